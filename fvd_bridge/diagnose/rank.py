"""Candidate effects: add each to the model, refit, and judge the gain against noise.

An effect counts ("helps beyond noise") only if both hold:

1. the OF falls by more than ``MARGIN`` noise-floor uncertainties:
   OF_base - OF_with > MARGIN u,  u = floor max(1.7 / sqrt(N), 0.02)
   (1.7 / sqrt(N): the relative scatter of the floor estimated from the
   force noise (median of N fourth differences) combined with the scatter
   of the exact model's OF under the same noise);
2. the Bayesian information criterion agrees (Laplace errors, whose
   maximum likelihood is set by the mean absolute residual, so the OF):
   dBIC = 2 N_eff ln(OF_with / OF_base) + dk ln(N_eff) < 0,
   N_eff = N (1 - rho) / (1 + rho) with rho the lag-1 autocorrelation of the
   refitted model's residual: a residual that is still a smooth misfit is
   worth few independent samples, so a small gain does not pass.

And none counts when the model is already at the noise floor
(OF_base <= floor + MARGIN u): "nothing left to explain".

Each refit is a real fit (fit_model, seeded) of the model with the effect;
should it end above the nested start (the base parameters with the effect
switched off, which reproduces the base model exactly), the nested start is
kept, so that adding an effect never makes the fit worse.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..fit import fit_model, objective
from .where import effective_samples

#: an effect must lower the OF by more than this many noise-floor uncertainties
MARGIN = 3.0


def floor_uncertainty(floor: float, n: int) -> float:
    """Uncertainty of the noise-floor OF estimated from N samples (see module doc)."""
    return float(floor * max(1.7 / math.sqrt(max(n, 1)), 0.02))


def nested_start(model, base_model, base_params, scales) -> np.ndarray:
    """Parameters of ``model`` that reproduce ``base_model`` at ``base_params``:
    the shared parameters copied, each added effect at its 'no effect' values
    (clipped into its bounds: an infinite stiffness is the upper bound)."""
    known = dict(zip(base_model.names, base_params))
    out = []
    for e in [None] + list(model.effects):
        if e is None:
            out.extend(known[n] for n in model.law.names)
            continue
        b = e.bounds(scales)
        for name, none, (lo, hi) in zip(e.names, e.none, b):
            out.append(known[name] if name in known else float(np.clip(none, lo, hi)))
    return np.asarray(out, dtype=float)


def refit(model, record, seed: int, settings, start: np.ndarray | None = None):
    """fit_model (DE + polish, seeded); when it ends above the OF of ``start``
    (the nested start: the model without the effect), ``start`` is the
    result, so that adding an effect never makes the fit worse."""
    fit = fit_model(model, record, bounds="auto", optimizer="de", seed=seed, settings=settings)
    if start is None:
        return fit
    start = np.clip(start, fit.bounds[:, 0], fit.bounds[:, 1])
    of0 = float(objective(record.F, model.force(record, start[None, :]), record.t)[0])
    if np.isfinite(of0) and of0 < fit.of:
        fit.params, fit.of = start, of0
        fit.evaluations += 1
    return fit


@dataclass
class Candidate:
    """One effect added to the model and refitted."""

    effect: str
    model: object  # the base model with the effect (fvd_bridge.model.Model)
    fit: object
    of: float
    improvement: float  # (OF_base - OF) / OF_base
    delta_bic: float
    n_eff: float
    significant: bool
    reason: str
    explanation: str
    wall_s: float = 0.0

    @property
    def spec(self) -> str:
        return self.model.spec

    def as_dict(self) -> dict:
        return {"effect": self.effect, "spec": self.spec, "of": self.of, "improvement": self.improvement,
                "delta_bic": self.delta_bic, "significant": self.significant, "reason": self.reason,
                "explanation": self.explanation,
                "params": {n: float(v) for n, v in zip(self.fit.names, self.fit.params)}}


@dataclass
class Judge:
    """The noise-based yardstick of one record: floor OF, its uncertainty, N."""

    floor: float
    n: int
    margin: float = field(init=False)

    def __post_init__(self):
        self.margin = MARGIN * floor_uncertainty(self.floor, self.n)

    def at_floor(self, of: float) -> bool:
        return of <= self.floor + self.margin

    def verdict(self, of_base: float, of_new: float, dk: int, residual) -> tuple[bool, str, float, float]:
        """(significant, reason, dBIC, N_eff) of going from of_base to of_new with dk more parameters."""
        n_eff = effective_samples(residual)
        dbic = (2.0 * n_eff * math.log(max(of_new, 1e-300) / max(of_base, 1e-300))
                + dk * math.log(n_eff))
        drop = of_base - of_new
        if self.at_floor(of_base):
            return False, "model already at the noise floor", dbic, n_eff
        if drop <= self.margin:
            return (False, f"within noise (OF falls {max(drop, 0.0):.3g}, needs > {self.margin:.3g})",
                    dbic, n_eff)
        if dbic >= 0.0:
            return False, f"not worth its parameters (dBIC {dbic:+.1f}, N_eff {n_eff:.0f})", dbic, n_eff
        return True, "helps beyond noise", dbic, n_eff


def rank(base_model, base_fit, record, effects: dict, judge: Judge, seed: int, settings,
         progress=None) -> list[Candidate]:
    """Refit ``base_model`` + each effect of ``effects`` ({name: Effect}) not
    already in it; candidates best (lowest OF) first."""
    scales = record.scales()
    out = []
    for name, e in effects.items():
        if base_model.has(name):
            continue
        model = base_model.with_effect(e)
        start = nested_start(model, base_model, base_fit.params, scales)
        t0 = time.perf_counter()
        fit = refit(model, record, seed, settings, start)
        wall = time.perf_counter() - t0
        F = model.force(record, fit.params[None, :])[0]
        ok, reason, dbic, n_eff = judge.verdict(base_fit.of, fit.of, len(e.parameters), record.F - F)
        imp = (base_fit.of - fit.of) / base_fit.of if base_fit.of > 0 else 0.0
        cand = Candidate(name, model, fit, float(fit.of), float(imp), float(dbic), float(n_eff), ok,
                         reason, e.explanation(), wall)
        out.append(cand)
        if progress:
            progress(cand)
    out.sort(key=lambda c: (c.of, c.effect))
    return out
