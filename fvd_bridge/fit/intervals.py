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
repeated from theta on each replicate (``polish_model``: the local least
squares on eq. 18).  With theta_b the replicates' estimates:

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
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..records.cycles import force_noise
from ..records.device import as_device
from ..records.record import Record
from ..records.velocity import _savgol, derive_with_windows, rederive, rest_mask, runs
from .api import evaluate_params, polish_model
from .layout import Layout

#: bootstrap replicates of a calibration
REPLICATES = 20
#: share of the bias counted as its own uncertainty: the bootstrap's truth
#: is the record smoothed, not the device's motion, and on lab-like law-2
#: records with rests it put the bias at up to twice the true one
#: (benchmarks/bench_coverage.py): the bias is known to its own size
BIAS_SHARE = 1.0
#: an OF beyond this multiple of the noise's marks a misfit the intervals do not count
MISFIT = 1.5
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

    def as_dict(self) -> dict:
        return {"replicates": self.replicates, "method": "bootstrap of the measurement chain (fit.intervals)",
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


def _replicates(record, F_clean: np.ndarray, d_smooth: np.ndarray, sigma_F: float, count: int, rng) -> list:
    """``count`` lab-like replicates of ``record`` (module docstring), one batch."""
    F = F_clean + sigma_F * rng.standard_normal((count, record.n))
    if not record.d_noise or str((record.provenance.get("velocity") or {}).get("method")) != "savgol":
        return [Record(record.t, record.d, f, record.v, record.a, record.name) for f in F]  # force noise only
    D = d_smooth + record.d_noise * rng.standard_normal((count, record.n))
    if record.windows is None:  # a record built in code: its differentiator chooses again
        return [Record(record.t, d, f, *rederive(record, d), record.name) for d, f in zip(D, F)]
    V, A = derive_with_windows(D, record.dt, record.windows, record.provenance["velocity"].get("polyorder", 3),
                               record.v_noise)
    return [Record(record.t, d, f, v, a, record.name) for d, f, v, a in zip(D, F, V, A)]


def intervals(model, record, params, per_test=(), bounds=None, replicates: int = REPLICATES, seed=0,
              progress=None, of: float | None = None) -> Intervals:
    """Bootstrap intervals of a calibration: ``params`` (the fit's columns) of
    ``model`` on ``record`` (a Record or a Device); ``bounds`` (n, 2): the
    fit's search bounds (an interval reaching one is not identified);
    ``of``: the fit's OF, compared with what noise alone gives (``note``)."""
    device = as_device(record)
    layout = Layout(model, tuple(device.test_names), tuple(per_test))
    params = np.asarray(params, dtype=float)
    rng = np.random.default_rng(seed)
    count = int(replicates)
    per_test_reps = []
    for k, test in enumerate(device.tests):
        clean = smoothed(test)
        F_clean = model.force(clean, layout.for_test(params[None, :], k))[0]
        per_test_reps.append(_replicates(test, F_clean, clean.d, force_noise(test.F), count, rng))
    estimates, noise_ofs = [], []
    for b in range(count):
        rep = type(device)(device.name, [reps[b] for reps in per_test_reps], device.weights)
        est, _ = polish_model(model, rep, params, per_test=per_test)
        estimates.append(est)
        noise_ofs.append(evaluate_params(model, rep, params, per_test=per_test))
        if progress:
            progress(b + 1)
    out = summarize(model, layout, params, np.array(estimates), bounds)
    out.noise_of = float(np.mean(noise_ofs))
    if of is not None and of > MISFIT * out.noise_of:
        out.note = (f"OF {of:.4g} is {of / out.noise_of:.1f}x what the noise alone gives ({out.noise_of:.4g}): "
                    f"the model misses the record, and these intervals count the noise only, not the misfit "
                    f"(fvd-bridge diagnose shows what is missing)")
    return out


def summarize(model, layout, params: np.ndarray, estimates: np.ndarray, bounds=None) -> Intervals:
    """Intervals from the replicates' estimates (B, n) around ``params``."""
    names = layout.names
    bias = estimates.mean(axis=0) - params
    stderr = np.hypot(estimates.std(axis=0, ddof=1), BIAS_SHARE * bias)
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
        if bounds is not None and np.isclose(params[j], bounds[j], rtol=1e-6, atol=0.0).any():  # ended on it
            out.not_identified.append(f"{name}: ended on its search bound [{bounds[j][0]:.4g}, {bounds[j][1]:.4g}]"
                                      f", so its interval is one-sided")
        elif bounds is not None and (lo <= bounds[j][0] < params[j] or hi >= bounds[j][1] > params[j]):
            out.not_identified.append(f"{name}: its 95% interval [{lo:.4g}, {hi:.4g}] reaches its search bound "
                                      f"[{bounds[j][0]:.4g}, {bounds[j][1]:.4g}]")
    return out
