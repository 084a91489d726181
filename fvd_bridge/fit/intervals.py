"""Parameter intervals: a parametric bootstrap that repeats the whole measurement chain.

A lab record's parameters carry two errors: the force noise, and the
displacement noise that reaches the model through the velocity the tool
derives from d.  Near a reversal a law with alpha ~ 0.3 turns a velocity
error of 0.2 mm/s into several kN, so the two noises together bias the fit
(on lab-like law-2 records C by about -0.4%, several times the scatter a
force-only bootstrap sees).  Each replicate therefore rebuilds the record
as the lab would have measured it had the calibrated model been the truth:

    d_s, v_s, a_s: d smoothed and its derivatives (Savitzky-Golay at the
                   velocity's median window)
    d* = d_s + sigma_d e_d,   v*, a* derived from d* as on reading
    F* = F_model(theta; d_s, v_s, a_s) + sigma_F e_F

(sigma_d, sigma_F the record's own noise estimates, e white Gaussian; a
measured velocity column is kept, with force noise only), and the fit is
repeated from theta on each replicate (``polish_model``: the local least
squares on eq. 18).  With
theta_b the replicates' estimates:

    bias = mean(theta_b) - theta,  stderr = sqrt(std(theta_b)^2 + (BIAS_SHARE bias)^2),
    95% interval = theta - bias -/+ 1.96 stderr

(the bias the chain adds is taken out of the interval, not hidden in it;
it grows with the squared noise estimates, known to 5-10%, so a quarter
of it is counted as uncertain).  An interval always holds its estimate
(where the bias exceeds 1.96 stderr it reaches to the estimate) and stays
inside the search bounds.
The intervals are those of the noise: a model that misses the record by
more than the noise floor has parameters that depend on what it misses
(``diagnose``).  The correlation matrix is that of theta_b; a parameter is
not identified when its interval reaches a bound of its search, when it
correlates with another beyond ``CORRELATED``, or when the law declares it
a factor of a derived quantity (law 8's mu and N: only mu*N acts; their
intervals are their search ranges, the product gets its own interval).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..records.cycles import force_noise
from ..records.device import as_device
from ..records.record import Record
from ..records.velocity import _savgol, rederive
from .api import evaluate_params, polish_model
from .layout import Layout

#: bootstrap replicates of a calibration
REPLICATES = 20
#: share of the bias counted as its own uncertainty: it scales with the
#: squared noise estimates, which the record gives to about 5-10%
BIAS_SHARE = 0.25
#: an OF beyond this multiple of the noise's marks a misfit the intervals do not count
MISFIT = 1.5
#: |correlation| beyond which two parameters are not identified separately
CORRELATED = 0.95
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
    the same polynomials (a measured velocity: the record as it is)."""
    vel = (record.provenance or {}).get("velocity") or {}
    if vel.get("method") != "savgol":
        return record
    window = int(vel.get("window_median") or vel.get("window") or 5)
    window = max(5, min(window if window % 2 else window + 1, record.n - (1 - record.n % 2)))
    d, v, a = (_savgol(record.d, window, 3, k, record.dt) for k in (0, 1, 2))
    return Record(record.t, d, record.F, v, a, record.name)


def replicate(record, F_clean: np.ndarray, d_smooth: np.ndarray, sigma_F: float, rng) -> Record:
    """One lab-like replicate of ``record`` (module docstring)."""
    F = F_clean + sigma_F * rng.standard_normal(record.n)
    d = d_smooth + (record.d_noise or 0.0) * rng.standard_normal(record.n)
    derived = rederive(record, d) if record.d_noise else None
    if derived is None:  # a measured velocity: force noise only
        return Record(record.t, record.d, F, record.v, record.a, record.name)
    return Record(record.t, d, F, *derived, record.name)


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
    parts = []
    for k, test in enumerate(device.tests):
        clean = smoothed(test)
        parts.append((test, model.force(clean, layout.for_test(params[None, :], k))[0], clean.d,
                      force_noise(test.F)))
    estimates, noise_ofs = [], []
    for b in range(int(replicates)):
        tests = [replicate(test, F_clean, d_s, sigma_F, rng) for test, F_clean, d_s, sigma_F in parts]
        rep = type(device)(device.name, tests, device.weights)
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
    centre = params - bias
    ci = np.column_stack([np.minimum(centre - Z95 * stderr, params), np.maximum(centre + Z95 * stderr, params)])
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
        s, b = float(values.std(ddof=1)), float(values.mean() - value)
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
        if bounds is not None and params[j] in (bounds[j][0], bounds[j][1]):
            out.not_identified.append(f"{name}: ended on its search bound [{bounds[j][0]:.4g}, {bounds[j][1]:.4g}]"
                                      f", so its interval is one-sided")
        elif bounds is not None and (lo <= bounds[j][0] < params[j] or hi >= bounds[j][1] > params[j]):
            out.not_identified.append(f"{name}: its 95% interval [{lo:.4g}, {hi:.4g}] reaches its search bound "
                                      f"[{bounds[j][0]:.4g}, {bounds[j][1]:.4g}]")
        partners = [names[k] for k in range(len(names)) if k != j and abs(corr[j, k]) > CORRELATED]
        if partners:
            combo = [f"{d.name} = {out.derived[d.name]['value']:.4g} {d.unit} "
                     f"[{out.derived[d.name]['ci95'][0]:.4g}, {out.derived[d.name]['ci95'][1]:.4g}]"
                     for d in model.law.derived if name in d.factors]
            out.not_identified.append(f"{name}: correlates with {', '.join(partners)} beyond {CORRELATED:g}"
                                      + (f"; identified: {combo[0]}" if combo else ""))
    return out
