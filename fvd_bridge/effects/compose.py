"""Composition of a law with effects, in one fixed order (the rig's physics):

    1. input     gap:                x, xv, xa = play(d), its velocity and acceleration
                                     (the damper body's motion; d, v, a without a gap)
    2. element   F_el(x_o, u) = law(x_o, u), then the output effects in order
                 (asymmetry: x (1 +- r), thermal_softening: x exp(-theta E)),
                 plus friction Ff tanh(u / v_f)
    3. series    series_stiffness:   Ks (x - x_o) = F_el(x_o, u), u = dx_o/dt
                                     (without it x_o = x, u = xv)
    4. parallel  + Kp x + F0 (parallel_stiffness), + m xa 1e-6 (inertia), user terms

With a series spring, the built-in element effects (asymmetry,
thermal_softening, friction) are solved inside the spring's implicit step
(steps.series_population); a user's output or parallel effect is then
applied outside the spring.  Within a stage effects apply in increasing
``Effect.order``.  Without any effect the model is the law itself.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError

STAGE_RANK = {"input": 0, "series": 1, "output": 2, "parallel": 3}


def ordered(effects) -> list:
    """Effects in composition order (stage, then ``order``, then name)."""
    return sorted(effects, key=lambda e: (STAGE_RANK[e.stage], e.order, e.name))


def _checked(e, F, pop: int, n: int) -> np.ndarray:
    try:
        out = np.broadcast_to(np.asarray(F, dtype=float), (pop, n))
    except ValueError:
        shape = getattr(F, "shape", type(F).__name__)
        raise InputError(f"effect '{e.name}' ({e.source}): returned shape {shape}, "
                         f"expected ({pop}, {n}) or broadcastable to it") from None
    return out


#: laws whose force depends on the velocity only and vanishes at v = 0
VELOCITY_LAWS = (1, 2)


def law_force(model, x, xv, dt, PL, substeps, record=None) -> np.ndarray:
    """The law on per-row (pop, n_t) or shared (1, n_t) kinematics [kN]."""
    if x.shape[0] == 1:
        return model.law.force(x[0], xv[0], dt, PL, substeps)
    if record is not None and model.law.number in VELOCITY_LAWS:
        moving = xv != 0.0
        if np.array_equal(xv[moving], np.broadcast_to(record.v, xv.shape)[moving]):
            # each row's velocity is the record's or 0 (a gap): mask the shared evaluation
            return model.law.force(record.d, record.v, dt, PL, substeps) * moving
    with _single_thread():  # one compiled call per row: no thread start-up each time
        return np.vstack([model.law.force(x[i], xv[i], dt, PL[i:i + 1], substeps)
                          for i in range(PL.shape[0])])


def _series(model, e, x, xv, xa, dt, PL, PE, pop, substeps):
    """The series stage (catalog.series_force) with the built-in element effects inside."""
    slots = {"r": np.zeros(pop), "theta": np.zeros(pop), "Ff": np.zeros(pop)}
    inside = set()
    for other in model.effects:
        if other.series_slot:
            slots[other.series_slot] = PE[other.name][:, 0]
            inside.add(other.name)
    shape = (pop if x.shape[0] > 1 else 1, x.shape[1])
    F, U, FO = e.function(PE[e.name], model.law.number, PL, np.broadcast_to(x, shape),
                          np.broadcast_to(xv, shape), np.broadcast_to(xa, shape), dt,
                          slots["r"], slots["theta"], slots["Ff"], substeps)
    return F, U, FO, inside


def _series_effect(model):
    return next((e for e in model.effects if e.stage == "series"), None)


def _rigid_rows(model, P):
    """Rows whose series stiffness is at least KS_RIGID (the upper end of its
    range): a rigid connection, computed without the spring (exactly the
    model without series_stiffness, so the models are nested)."""
    from .catalog import KS_RIGID_FROM

    e = _series_effect(model)
    if e is None:
        return None
    _, PE = model.split(P)
    return PE[e.name][:, 0] >= KS_RIGID_FROM


def _split_rigid(model, record, P, rigid, substeps, parts):
    series = _series_effect(model).name
    rigid_model = model.without_effect(series)
    cols = model.columns_without(series)
    pop, n = P.shape[0], record.n
    F = np.empty((pop, n))
    out_parts: dict = {}
    for rows, m, PP in ((np.flatnonzero(rigid), rigid_model, P[rigid][:, cols]),
                        (np.flatnonzero(~rigid), model, P[~rigid])):
        if rows.size == 0:
            continue
        if m.effects:
            res = composed_force(m, record, PP, substeps, parts)
        else:
            res = m.law.force(record.d, record.v, record.dt, PP, substeps)
            res = (res, {"law": res.copy()}) if parts else res
        Fi, pi = res if parts else (res, {})
        F[rows] = Fi
        for key, val in pi.items():
            out_parts.setdefault(key, np.zeros((pop, n)))[rows] = val
    return (F, out_parts) if parts else F


def composed_force(model, record, P: np.ndarray, substeps: int = 1, parts: bool = False):
    """Force [kN] of ``model`` (law + effects) for each row of P -> (pop, n_t).

    With ``parts=True`` returns (F, {term: contribution (pop, n_t)}): 'law'
    is the internal element's force before the output effects (with a series
    spring: the force the spring carries, less friction), each output effect
    contributes the change it makes and each parallel effect its term; the
    contributions sum to F.
    """
    P = np.atleast_2d(np.asarray(P, dtype=float))
    if P.shape[0] == 1 and not parts:
        with _single_thread():  # one row (a polish step): no thread start-up per kernel
            return _composed(model, record, P, substeps, parts)
    return _composed(model, record, P, substeps, parts)


class _single_thread:
    """Run numba kernels on one thread inside the block."""

    def __enter__(self):
        import numba

        self.threads = numba.get_num_threads()
        numba.set_num_threads(1)

    def __exit__(self, *exc):
        import numba

        numba.set_num_threads(self.threads)
        return False


def _composed(model, record, P, substeps, parts):
    pop, n = P.shape[0], record.n
    rigid = _rigid_rows(model, P)
    if rigid is not None and rigid.any():
        return _split_rigid(model, record, P, rigid, substeps, parts)
    PL, PE = model.split(P)
    dt = record.dt
    x, xv, xa = record.d[None, :], record.v[None, :], record.a[None, :]
    parts_out: dict = {}
    effects = ordered(model.effects)
    for e in (e for e in effects if e.stage == "input"):
        out = e.function(PE[e.name], x, xv, xa, dt)
        if not isinstance(out, tuple) or len(out) != 3:
            raise InputError(f"effect '{e.name}' ({e.source}): an input effect returns (x, xv, xa)")
        x, xv, xa = (_checked(e, o, pop, n) for o in out)
    series = [e for e in effects if e.stage == "series"]
    inside: set = set()
    if series:
        F, u, FO, inside = _series(model, series[0], x, xv, xa, dt, PL, PE, pop, substeps)
        if parts:
            friction = F - FO
            parts_out["law"] = FO
            for e in effects:
                if e.series_slot == "Ff":
                    parts_out[e.name] = friction
            if "Ff" not in {e.series_slot for e in effects}:
                parts_out["law"] = F.copy()
        # a user's output effect sees the law's own motion behind the spring
        Ks = np.asarray(PE[series[0].name][:, 0:1], dtype=float)
        xl, ul = np.asarray(x) - F / Ks, u
    else:
        F = law_force(model, np.asarray(x), np.asarray(xv), dt, PL, substeps, record)
        if parts:
            parts_out["law"] = F.copy()
        xl, ul = x, xv
    for e in (e for e in effects if e.stage == "output" and e.name not in inside):
        F_new = _checked(e, e.function(PE[e.name], F, xl, ul, dt), pop, n)
        if parts:
            parts_out[e.name] = F_new - F
        F = F_new
    F = np.array(F, dtype=float)
    for e in (e for e in effects if e.stage == "parallel" and e.name not in inside):
        term = _checked(e, e.function(PE[e.name], record.t, x, xv, xa), pop, n)
        if parts:
            parts_out[e.name] = np.array(term)
        F = F + term
    return (F, parts_out) if parts else F


def contributions(model, record, params) -> dict:
    """Per-term force contributions [kN] of one parameter vector (Pastas-style):
    {'law': ..., effect name: ...}, each (n_t,); they sum to the model force."""
    p = np.atleast_2d(np.asarray(params, dtype=float))
    if not model.effects:
        return {"law": model.force(record, p)[0]}
    _, parts = composed_force(model, record, p, parts=True)
    return {k: np.asarray(v)[0] for k, v in parts.items()}
