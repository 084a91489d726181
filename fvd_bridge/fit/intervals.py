"""Parameter intervals: a parametric bootstrap that repeats the whole measurement chain.

A lab record's parameters carry two errors: the force noise, and the
displacement noise that reaches the model through the velocity the tool
derives from d.  Near a reversal a law with alpha ~ 0.3 turns a velocity
error of 0.2 mm/s into several kN, so the two noises together bias the fit
(the rests, where it was largest, are taken out at the source: the velocity
is 0 there, ``records.velocity``).  Each replicate therefore rebuilds the
record as the lab would have measured it had the calibrated model been the
truth:

    d_s, v_s, a_s: d smoothed and its derivatives (Savitzky-Golay at the
                   velocity's median window; v_s and a_s 0 in the
                   record's rests)
    d* = d_s + sigma_d e_d,   v*, a* derived from d* with the windows the
                   record's own derivation chose at each sample, its rests
                   found again (``velocity.derive_with_windows``: one batch)
    F* = F_model(theta; d_s, v_s, a_s) + sigma_F e_F

(sigma_d, sigma_F the record's own noise estimates, e white Gaussian; a
measured velocity column is kept, with force noise only), and the fit is
repeated from theta on each replicate by Newton steps on its M-estimator
(the k-step bootstrap: Davidson & MacKinnon 1999, Andrews 2002): with e_i
the replicate's weighted residuals of eq. 18 at theta_b (from theta), g_i
their parameter gradients (forward differences on the replicate's own
motion), psi the soft-L1 derivative at the scale s_i = SOFT_SHARE of the
force noise (eq. 18's L1 but within the noise's smallest 5%),

    theta_b <- theta_b - H^-1 sum psi(e_i/s_i) g_i,   H = sum psi'(e_i/s_i)/s_i g_i g_i^T

each step halved until the cost falls, until a step (taken, the last)
moves no parameter by more than STEP_TOL of its standard error (the
sandwich H^-1 B H^-1; at most NEWTON_STEPS).  On lab-like law-2 and law-9
records (1,757 and 9,439 samples) 3-4.5 evaluations a replicate reach the
replicates' own full refits (``polish_model``) to 0.04 of their spread,
at a third of their cost (``tests/fit/test_intervals.py``); a replicate whose
steps do not settle (a singular H, a force that is not finite) is
refitted by ``polish_model``.  A parameter on which the OF moves in steps
(a gap's clearance, ``Effect.stepped``) has no gradient: the Newton steps
hold it, and it is searched along its line on the replica's OF
(``fit.local.line_search``), the Newton steps repeated from there, until
the line search moves it no more (STEPPED_ROUNDS at most).  A replica
refitted by ``polish_model`` (after NEWTON_MISSES such replicates in a
row, the rest of the batch at once: a cost that is not smooth, a gap's
dead zone).  With theta_b the replicates' estimates:

    bias = mean(theta_b) - theta,  stderr = sqrt(std(theta_b)^2 + (BIAS_SHARE bias)^2),
    95% interval = theta - bias -/+ 1.96 stderr

The bias the chain adds is taken out of the interval, not hidden in it,
and counted in full as uncertain (the bootstrap's truth is the smoothed
record, not the device's motion), so the interval holds its estimate by
construction (1.96 stderr > |bias|), with no clipping; it stays inside the
search bounds.  The intervals are those of the noise: a model that misses
the record by more than the noise floor has parameters that depend on what
it misses (``note``, and ``diagnose``).  The correlation matrix is that of
theta_b, reported as correlations (a law whose C scales |v|^alpha has C and
alpha correlated at -0.98 and both well determined).  A parameter is not
identified when its interval reaches a bound of its search, or when the
law declares it a factor of a derived quantity (law 8's mu and N: only
mu*N acts; their intervals are their search ranges, the product gets its
own interval).

With the tests' force zero fitted beside the model (``Layout.zero``,
``fit.zero``), the replicas carry the calibration's zero, every refit
profiles it out as the calibration did, and each replica's zero at its
estimate gives the zero's own intervals (``Intervals.zero``): the
parameters' intervals count the zero's uncertainty.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError, command, option
from ..records.cycles import force_noise
from ..records.device import as_device
from ..records.record import Record
from ..records.velocity import _savgol, derive_with_windows, rederive, rest_mask, runs
from .api import evaluate_params, joint_objective, joint_residuals, polish_model, residual_weights
from .layout import Layout
from .local import line_search
from .search import Evaluations
from . import zero as zero_mod

#: bootstrap replicates of a calibration
REPLICATES = 20


def replicates(n) -> int:
    """``n`` bootstrap replicates, checked: 0 (none) or at least 2 (one has no spread)."""
    if int(n) != n or n < 0 or n == 1:
        raise InputError(f"{option('--intervals', n)}: 0 (none) or at least 2 replicates")
    return int(n)
#: share of the bias counted as its own uncertainty: the bootstrap's truth
#: is the record smoothed, not the device's motion, and on lab-like law-2
#: records with rests it put the bias at up to twice the true one
#: (benchmarks/bench_coverage.py): the bias is known to its own size
BIAS_SHARE = 1.0
#: an OF beyond this multiple of the noise's marks a misfit the intervals do not count
MISFIT = 1.5
#: the soft-L1 scale of the replicates' Newton steps, a share of the force noise
SOFT_SHARE = 0.05
#: the Newton steps settle when no parameter moves by more than this share of its standard error
STEP_TOL = 0.05
#: at most this many Newton steps per replicate (and as many halvings), then its full refit
NEWTON_STEPS = 8
#: after this many replicas in a row whose steps did not settle, the others are refitted at once
NEWTON_MISSES = 2
#: rounds of a stepped parameter's line search and the Newton steps at most
STEPPED_ROUNDS = 3
#: a replica's line search starts on this share of the search range around
#: the calibration's value (a replica's optimum lies a few standard errors
#: from it: the gap's 1% on the earthquake test is 30 of them; a best on
#: the span's edge walks on)
STEPPED_SPAN = 0.01
#: forward-difference step of the replicates' gradients, a share of each parameter
FD_SHARE = 1e-6
#: two-sided 95% normal quantile
Z95 = 1.959964


@dataclass
class Intervals:
    """Per parameter (the fit's columns): stderr, bias and the 95% interval;
    the correlation matrix; derived quantities' intervals; what is not identified."""

    names: list
    stderr: np.ndarray
    bias: np.ndarray
    ci95: np.ndarray  # (n, 2)
    correlation: np.ndarray
    derived: dict = field(default_factory=dict)  # {name: {value, stderr, ci95}}
    not_identified: list = field(default_factory=list)  # one line each
    replicates: int = 0
    noise_of: float = float("nan")  # mean OF of the calibrated model on the replicates: what noise alone gives
    note: str = ""  # the fit misses the record beyond the noise: the intervals count the noise only
    zero: dict = field(default_factory=dict)  # {test: {F0: {value, stderr, ci95}, F1: ...}}: the tests' force zero

    def as_dict(self) -> dict:
        return {"replicates": self.replicates, "method": "bootstrap of the measurement chain (fit.intervals)",
                **({"zero": self.zero} if self.zero else {}),
                "noise_of": float(self.noise_of), "note": self.note,
                "parameters": {n: {"stderr": float(s), "bias": float(b), "ci95": [float(lo), float(hi)]}
                               for n, s, b, (lo, hi) in zip(self.names, self.stderr, self.bias, self.ci95)},
                "correlation": {"names": list(self.names),
                                "matrix": [[round(float(x), 4) for x in row] for row in self.correlation]},
                "derived": self.derived, "not_identified": list(self.not_identified)}


def smoothed(record) -> Record:
    """The record's motion, smoothed: d [mm] by Savitzky-Golay at the window
    its velocity used (median), v [mm/s] and a [mm/s^2] the derivatives of
    the same polynomials, 0 in its rests (a measured velocity: the record
    as it is)."""
    vel = (record.provenance or {}).get("velocity") or {}
    if vel.get("method") != "savgol":
        return record
    window = int(vel.get("window_median") or vel.get("window") or 5)
    window = max(5, min(window if window % 2 else window + 1, record.n - (1 - record.n % 2)))
    d, v, a = (_savgol(record.d, window, 3, k, record.dt) for k in (0, 1, 2))
    for start, end in runs(rest_mask(record)):  # the record's rests: the motion holds still there
        d[start:end], v[start:end], a[start:end] = np.mean(d[start:end]), 0.0, 0.0
    return Record(record.t, d, record.F, v, a, record.name)


def _replicates(record, F_clean: np.ndarray, clean: Record, sigma_F: float, count: int, rng,
                acceleration: bool = True) -> list:
    """``count`` lab-like replicates of ``record`` (module docstring), one
    batch; without ``acceleration`` (a model that does not read it: a bare
    law) each keeps ``clean``'s (the smoothed record's)."""
    d_smooth = clean.d
    F = F_clean + sigma_F * rng.standard_normal((count, record.n))
    if not record.d_noise or str((record.provenance.get("velocity") or {}).get("method")) != "savgol":
        return [Record(record.t, record.d, f, record.v, record.a, record.name) for f in F]  # force noise only
    D = d_smooth + record.d_noise * rng.standard_normal((count, record.n))
    if record.windows is None:  # a record built in code: its differentiator chooses again
        return [Record(record.t, d, f, *rederive(record, d), record.name) for d, f in zip(D, F)]
    V, A = derive_with_windows(D, record.dt, record.windows, record.provenance["velocity"].get("polyorder", 3),
                               record.v_noise, acceleration=acceleration)
    A = [clean.a] * count if A is None else A
    return [Record(record.t, d, f, v, a, record.name) for d, f, v, a in zip(D, F, V, A)]


def intervals(model, record, params, *, per_test=(), bounds=None, replicates: int = REPLICATES, seed=0,
              progress=None, of: float | None = None, force_zero: bool = False,
              floor: float | None = None) -> Intervals:
    """Bootstrap intervals of a calibration: ``params`` (the fit's columns) of
    ``model`` on ``record`` (a Record or a Device); ``bounds`` (n, 2): the
    fit's search bounds (an interval reaching one is not identified);
    ``of``: the fit's OF, compared with what noise alone gives (``note``:
    with ``floor``, the records' noise floor; ``from_estimates``).
    ``force_zero``: the tests' force zero fitted beside the model (module
    docstring).  The three steps (``bootstrap_replicas``, ``newton_refits``,
    ``from_estimates``) may run apart: a campaign spreads the refits over
    its processes."""
    layout, replicas, noise = bootstrap_replicas(model, record, params, per_test, replicates, seed,
                                                 force_zero=force_zero)
    estimates, ofs = newton_refits(model, layout, replicas, params, noise, bounds, progress)
    return from_estimates(model, layout, params, estimates, float(np.mean(ofs)), bounds, of,
                          zero=fitted_zero(model, record, layout, params), floor=floor)


def fitted_zero(model, record, layout, params) -> dict | None:
    """{test: (F0 [kN], F1 [kN/s])} of ``params`` on ``record`` when the
    layout fits the tests' force zero (None: it does not)."""
    if not layout.zero:
        return None
    device = as_device(record)
    return zero_mod.values(model, device, layout, params, residual_weights(device))


def bootstrap_replicas(model, record, params, per_test=(), replicates: int = REPLICATES, seed=0, *,
                       force_zero: bool = False):
    """(layout, replicas, noise): ``replicates`` lab-like replicas of
    ``record`` (Devices of one replicate per test) had ``params`` been the
    truth (with ``force_zero``, and each test's fitted force zero), and
    each test's force noise [kN]."""
    device = as_device(record)
    layout = Layout(model, tuple(device.test_names), tuple(per_test), force_zero)
    params = np.asarray(params, dtype=float)
    rng = np.random.default_rng(seed)
    count = int(replicates)
    zero = fitted_zero(model, device, layout, params) or {}
    per_test_reps = []
    for k, test in enumerate(device.tests):
        clean = smoothed(test)
        F_clean = model.force(clean, layout.for_test(params[None, :], k))[0]
        if test.name in zero:
            F_clean = F_clean + zero_mod.zero_force(*zero[test.name], test.t)
        per_test_reps.append(_replicates(test, F_clean, clean, force_noise(test.F), count, rng,
                                         acceleration=bool(model.effects)))
    noise = [force_noise(test.F) for test in device.tests]
    replicas = [type(device)(device.name, [reps[b] for reps in per_test_reps], device.weights)
                for b in range(count)]
    return layout, replicas, noise


def from_estimates(model, layout, params, estimates: np.ndarray, noise_of: float, bounds=None,
                   of: float | None = None, zero: dict | None = None, *, floor: float | None = None) -> Intervals:
    """The Intervals of the replicas' estimates (B, n; with the tests' force
    zero, (B, n + 2 n_tests): each test's F0, F1 after the parameters);
    ``noise_of``: the mean OF of ``params`` on them; ``of``: the fit's
    (``note``); ``zero``: the fitted zero {test: (F0, F1)} (``fitted_zero``);
    ``floor``: the records' noise floor the search was judged by
    (``fit.floor``), which the note then reads the OF against, as the
    calibration's warnings do (None: ``noise_of``)."""
    params = np.asarray(params, dtype=float)
    estimates = np.asarray(estimates, dtype=float)
    out = summarize(model, layout, params, estimates[:, :params.size], bounds)
    if zero:
        out.zero = zero_intervals(zero, estimates[:, params.size:])
    out.noise_of = noise_of
    against = floor or out.noise_of
    if of is not None and of > MISFIT * against:
        out.note = (f"OF {of:.4g} is {of / against:.1f}x what the noise alone gives ({against:.4g}): "
                    f"the model misses the record, and these intervals count the noise only, not the misfit "
                    f"({command('diagnose')} shows what is missing)")
    return out


def zero_intervals(zero: dict, estimates: np.ndarray) -> dict:
    """{test: {F0: {value, unit, stderr, ci95}, F1: ...}} of the fitted zero
    {test: (F0, F1)} from the replicas' zeros (B, 2 n_tests), as
    ``summarize`` does the parameters' (a drift held at 0: its value)."""
    out = {}
    for j, (test, fitted) in enumerate(zero.items()):
        out[test] = {}
        for i, (name, unit) in enumerate((("F0", "kN"), ("F1", "kN/s"))):
            value, b = float(fitted[i]), estimates[:, 2 * j + i]
            bias = float(b.mean() - value)
            stderr = float(np.hypot(b.std(ddof=1), BIAS_SHARE * bias)) if len(b) > 1 else 0.0
            out[test][name] = {"value": value, "unit": unit, "stderr": stderr,
                               "ci95": [value - bias - Z95 * stderr, value - bias + Z95 * stderr]}
    return out


def newton_refits(model, layout, replicas: list, params: np.ndarray, noise: list, bounds=None,
                  progress=None) -> tuple[np.ndarray, np.ndarray]:
    """Each replica's (a Record or Device) estimate (B, n) by Newton steps
    from ``params`` (module docstring), and the OF of ``params`` on each
    replica (B,): what the noise alone gives.  ``noise``: per test, its
    force noise [kN].  With the tests' force zero (``layout.zero``) each
    row goes on with the replica's zero at its estimate (F0, F1 per test)."""
    replicas = [as_device(r) for r in replicas]
    estimates = np.repeat(np.asarray(params, dtype=float)[None, :], len(replicas), axis=0)
    zeros = []
    ofs = np.zeros(len(replicas))
    stepped = layout.stepped
    misses = 0  # replicas in a row whose steps did not settle
    for b, replica in enumerate(replicas):
        if misses < NEWTON_MISSES:
            settled, ofs[b] = _newton(model, layout, replica, params, noise, bounds, stepped)
            if settled is not None and stepped:
                settled = _along_steps(model, layout, replica, settled, noise, bounds, stepped)
        else:  # the steps would not settle here either (a cost that is not smooth: a gap's dead zone)
            settled, ofs[b] = None, evaluate_params(model, replica, params, per_test=layout.per_test,
                                                    force_zero=layout.zero)
        misses = 0 if settled is not None else misses + 1
        estimates[b] = (settled if settled is not None
                        else polish_model(model, replica, params, per_test=layout.per_test,
                                          overrides=_fixed(layout.names, bounds), force_zero=layout.zero)[0])
        if layout.zero:
            zeros.append(np.ravel(list(fitted_zero(model, replica, layout, estimates[b]).values())))
        if progress:
            progress(b + 1)
    return np.hstack([estimates, np.reshape(zeros, (len(replicas), -1))]), ofs


def _fixed(names: list, bounds) -> dict:
    """{name: (value, value)} of the parameters the caller fixed (bounds of one value)."""
    if bounds is None:
        return {}
    return {n: (float(lo), float(hi)) for n, (lo, hi) in zip(names, np.asarray(bounds, dtype=float)) if lo == hi}


def _along_steps(model, layout, replica, x: np.ndarray, noise: list, bounds, stepped: list):
    """A replica's estimate from the Newton steps' ``x`` (the ``stepped``
    columns held): each stepped column searched along its line on the
    replica's OF (within ``bounds``; without, 0 to twice its value), the
    Newton steps again from there, until the line search moves it no more
    (STEPPED_ROUNDS at most)."""
    weights = residual_weights(replica)
    pins = zero_mod.pins(replica, weights) if layout.zero else None

    def evaluate(P):
        of = joint_objective(model, replica, layout, P, weights=weights, pins=pins)
        return np.where(np.isfinite(of), of, np.inf)

    for _ in range(STEPPED_ROUNDS):
        start, f = x, float(evaluate(x[None, :])[0])
        for j in stepped:
            lo, hi = ((float(bounds[j][0]), float(bounds[j][1])) if bounds is not None
                      else (min(0.0, 2.0 * x[j]), max(0.0, 2.0 * x[j])))
            x, f = line_search(evaluate, x, f, j, Evaluations(), lo, hi, STEPPED_SPAN)
        if np.array_equal(x, start):
            break
        x = _newton(model, layout, replica, x, noise, bounds, stepped)[0]
        if x is None:
            return None
    return x


def _newton(model, layout, replica, params: np.ndarray, noise: list, bounds=None, held=()):
    """(estimate or None, OF of ``params``) of one replica: Newton steps on
    the soft-L1 cost from ``params`` (the columns ``held`` kept), each step
    halved until the cost falls, settled when a step moves each parameter
    by at most STEP_TOL of its standard error (the sandwich H^-1 B H^-1 at
    that point); None when the steps do not settle or the force is not
    finite there."""
    n = params.size
    lower, upper = (np.asarray(bounds, dtype=float).T if bounds is not None
                    else (np.full(n, -np.inf), np.full(n, np.inf)))
    free = upper > lower  # a parameter fixed by the caller (lower == upper) does not move
    free[list(held)] = False
    h = np.where(free, FD_SHARE * np.maximum(np.abs(params), 1e-9), 0.0)
    nudges = np.diag(h)[free]
    weights = residual_weights(replica)
    pins = zero_mod.pins(replica, weights) if layout.zero else None
    scale = np.concatenate([SOFT_SHARE * s * np.abs(c) for s, c in zip(noise, weights) if c is not None])
    x, of0 = np.asarray(params, dtype=float), None
    last_x, last_cost, step = x, np.inf, np.zeros(n)
    for _ in range(2 * NEWTON_STEPS):
        R = joint_residuals(model, replica, layout, np.vstack([x, x + nudges]), weights=weights, pins=pins)
        if not np.isfinite(R).all():
            return None, of0 if of0 is not None else np.inf
        if of0 is None:
            of0 = float(np.abs(R[0]).sum())
        cost = float((scale * (np.sqrt(1.0 + (R[0] / scale) ** 2) - 1.0)).sum())
        if cost > last_cost:  # overshot: half the step back
            step = 0.5 * step
            x = np.clip(last_x + step, lower, upper)
            continue
        last_x, last_cost = x, cost
        newton = _newton_step(R[0], (R[1:] - R[0]) / h[free][:, None], scale)
        if newton is None:
            return None, of0
        step, stderr = np.zeros(n), np.ones(n)
        step[free], stderr[free] = newton
        if np.all(np.abs(step) <= STEP_TOL * stderr):
            return np.clip(x + step, lower, upper), of0
        x = np.clip(x + step, lower, upper)
    return None, of0


def _newton_step(e: np.ndarray, G: np.ndarray, scale: np.ndarray):
    """(step (n,), standard errors (n,)) of the soft-L1 cost sum s (sqrt(1 +
    (e/s)^2) - 1) of residuals e (m,) with gradients G (n, m) at scales s
    (m,): the Newton step -H^-1 g and the sandwich H^-1 B H^-1's diagonal;
    None where H is singular."""
    u = e / scale
    root = np.sqrt(1.0 + u * u)
    slope = u / root  # the cost's derivative in e: sign(e) beyond the scale
    H = (G * (1.0 / (root ** 3 * scale))) @ G.T
    B = (G * slope ** 2) @ G.T
    try:
        Hinv = np.linalg.inv(H)
    except np.linalg.LinAlgError:
        return None
    step = -Hinv @ (G @ slope)
    stderr = np.sqrt(np.abs(np.diag(Hinv @ B @ Hinv)))
    return (step, stderr) if np.isfinite(step).all() and np.isfinite(stderr).all() else None


def summarize(model, layout, params: np.ndarray, estimates: np.ndarray, bounds=None) -> Intervals:
    """Intervals from the replicates' estimates (B, n) around ``params``."""
    names = layout.names
    fixed = (np.asarray(bounds, dtype=float)[:, 0] == np.asarray(bounds, dtype=float)[:, 1]
             if bounds is not None else np.zeros(len(names), bool))  # held by the caller: no spread, no bias
    bias = np.where(fixed, 0.0, estimates.mean(axis=0) - params)
    stderr = np.where(fixed, 0.0, np.hypot(estimates.std(axis=0, ddof=1), BIAS_SHARE * bias))
    ci = np.column_stack([params - bias - Z95 * stderr, params - bias + Z95 * stderr])
    if bounds is not None:  # no value beyond the search: the model is not defined there
        ci = np.clip(ci, np.asarray(bounds, dtype=float)[:, :1], np.asarray(bounds, dtype=float)[:, 1:])
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = np.corrcoef(estimates, rowvar=False) if len(names) > 1 else np.ones((1, 1))
    corr = np.where(np.isfinite(corr), corr, 0.0)
    out = Intervals(names, stderr, bias, ci, np.atleast_2d(corr), replicates=len(estimates))
    law_n = len(model.law.parameters)
    for d in model.law.derived:
        values = np.array([d.value(e[:law_n]) for e in estimates])
        value = float(d.value(params[:law_n]))
        b = float(values.mean() - value)
        s = float(np.hypot(values.std(ddof=1), BIAS_SHARE * b))
        out.derived[d.name] = {"value": value, "unit": d.unit, "stderr": s,
                               "ci95": [value - b - Z95 * s, value - b + Z95 * s]}
    declared = {}  # factors the registry declares unidentifiable alone (law 8: mu, N)
    for d in model.law.derived:
        for factor in d.factors:
            declared[factor] = d
    for j, name in enumerate(names):
        d = declared.get(name)
        if d is not None:
            if bounds is not None:
                ci[j] = bounds[j]
            p = out.derived[d.name]
            out.not_identified.append(f"{name}: only {d.name} acts on the force, so its interval is its whole "
                                      f"search range; identified: {d.name} = {p['value']:.4g} {d.unit} "
                                      f"[{p['ci95'][0]:.4g}, {p['ci95'][1]:.4g}]")
            continue
        lo, hi = ci[j]
        if bounds is not None and bounds[j][0] == bounds[j][1]:  # fixed by the caller: its interval is its value
            continue
        if bounds is not None and np.isclose(params[j], bounds[j], rtol=1e-6, atol=0.0).any():  # ended on it
            out.not_identified.append(f"{name}: ended on its search bound [{bounds[j][0]:.4g}, {bounds[j][1]:.4g}]"
                                      f", so its interval is one-sided")
        elif bounds is not None and (lo <= bounds[j][0] < params[j] or hi >= bounds[j][1] > params[j]):
            out.not_identified.append(f"{name}: its 95% interval [{lo:.4g}, {hi:.4g}] reaches its search bound "
                                      f"[{bounds[j][0]:.4g}, {bounds[j][1]:.4g}]")
    return out
