"""Composition of a law with effects, in one fixed order.

    1. input     (gap):               x, xv = play(d), its velocity   [the law sees x, xv]
    2. series    (series_stiffness):  F = Ks (x - x_law) = law(x_law, dx_law/dt)
    3. law       F_law = law(x, xv)   (when there is no series spring)
    4. output    (asymmetry, then thermal_softening): F_law transformed
    5. parallel  (friction, parallel_stiffness, inertia, user terms): added

Within a stage effects apply in increasing ``Effect.order``.  Without any
effect the model is the law itself.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from . import kernels

STAGE_RANK = {"input": 0, "series": 1, "output": 2, "parallel": 3}


def ordered(effects) -> list:
    """Effects in composition order (stage, then ``order``, then name)."""
    return sorted(effects, key=lambda e: (STAGE_RANK[e.stage], e.order, e.name))


def split_params(model, P: np.ndarray) -> tuple[np.ndarray, dict]:
    """(pop, n_par) -> law parameters (pop, n_law) and {effect name: (pop, n_e)}."""
    j = len(model.law.parameters)
    out = {}
    for e in model.effects:
        k = len(e.parameters)
        out[e.name] = P[:, j:j + k]
        j += k
    return P[:, :len(model.law.parameters)], out


def _checked(e, F, pop: int, n: int) -> np.ndarray:
    try:
        out = np.broadcast_to(np.asarray(F, dtype=float), (pop, n))
    except ValueError:
        shape = getattr(F, "shape", type(F).__name__)
        raise InputError(f"effect '{e.name}' ({e.source}): returned shape {shape}, "
                         f"expected ({pop}, {n}) or broadcastable to it") from None
    return out


def law_force(model, x, xv, dt, PL, substeps) -> np.ndarray:
    """The law on per-row (pop, n_t) or shared (1, n_t) kinematics."""
    if x.shape[0] == 1:
        return model.law.force(x[0], xv[0], dt, PL, substeps)
    return np.vstack([model.law.force(x[i], xv[i], dt, PL[i:i + 1], substeps) for i in range(PL.shape[0])])


def composed_force(model, record, P: np.ndarray, substeps: int = 1, parts: bool = False):
    """Force [kN] of ``model`` (law + effects) for each row of P -> (pop, n_t).

    With ``parts=True`` returns (F, {term: contribution (pop, n_t)}), where
    'law' is the law's force after the input and series stages, each output
    effect contributes the change it makes and each parallel effect its term.
    """
    P = np.atleast_2d(np.asarray(P, dtype=float))
    pop, n = P.shape[0], record.n
    PL, PE = split_params(model, P)
    dt = record.dt
    x, xv = record.d[None, :], record.v[None, :]
    contributions = {}
    effects = ordered(model.effects)
    for e in (e for e in effects if e.stage == "input"):
        x, xv = e.function(PE[e.name], x, xv, dt)
        x, xv = _checked(e, x, pop, n), _checked(e, xv, pop, n)
    series = [e for e in effects if e.stage == "series"]
    if series:
        e = series[0]
        Ks = np.ascontiguousarray(PE[e.name][:, 0], dtype=float)
        xx = np.ascontiguousarray(x, dtype=float)
        vv = np.ascontiguousarray(xv, dtype=float)
        F, xv = kernels.series_population(model.law.number, xx, vv, dt, Ks,
                                          np.ascontiguousarray(PL), int(substeps))
    else:
        F = law_force(model, np.asarray(x), np.asarray(xv), dt, PL, substeps)
    if parts:
        contributions["law"] = F.copy()
    for e in (e for e in effects if e.stage == "output"):
        F_new = _checked(e, e.function(PE[e.name], F, x, xv, dt), pop, n)
        if parts:
            contributions[e.name] = F_new - F
        F = F_new
    F = np.array(F, dtype=float, copy=True) if not F.flags.writeable else F
    for e in (e for e in effects if e.stage == "parallel"):
        term = _checked(e, e.function(PE[e.name], record.t, record.d, record.v, record.a), pop, n)
        if parts:
            contributions[e.name] = np.array(term)
        F = F + term
    return (F, contributions) if parts else F


def contributions(model, record, params) -> dict:
    """Per-term force contributions [kN] of one parameter vector (Pastas-style):
    {'law': ..., effect name: ...}, each (n_t,); they sum to the model force."""
    from ..model import Model  # noqa: F401  (documentation link)

    p = np.atleast_2d(np.asarray(params, dtype=float))
    if not model.effects:
        return {"law": model.force(record, p)[0]}
    _, parts = composed_force(model, record, p, parts=True)
    return {k: v[0] for k, v in parts.items()}
