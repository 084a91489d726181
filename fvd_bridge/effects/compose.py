"""Composition of a law with effects, in one fixed order (the rig's physics):

    1. input     a user's input effects: x, xv, xa (the pin's motion: the
                 record's d, v, a without them)
    2. element   F_el(x_o, u) = law(x_o, u), then the output effects in order
                 (asymmetry: x (1 +- r), thermal_softening: x exp(-theta E)),
                 plus friction Ff tanh(u / v_f); behind a gap also the
                 parallel spring Kp x_o + F0
    3. series    the connection, series_stiffness and/or gap:
                 F = Ks dz(x - x_o, g/2) = F_el(x_o, u), u = dx_o/dt
                 (dz the gap's dead zone, w itself without a gap; a gap
                 without series_stiffness is a rigid contact, Ks = inf);
                 without either x_o = x, u = xv
    4. parallel  + Kp x + F0 (parallel_stiffness, without a gap),
                 + m xa 1e-6 (inertia, on the measured motion also with a
                 gap), user terms

With a connection (a series spring, a gap, or both) the built-in element
effects (asymmetry, thermal_softening, friction, and with a gap
parallel_stiffness: no force at all passes the clearance) are solved
inside its implicit step (steps.series_population); a user's output or
parallel effect is then applied outside it.  A row whose gap is closed
(g <= 0) or whose spring is rigid (Ks >= KS_RIGID) is computed exactly as
the model without that effect, so every model is nested in the one with
one more effect.  Within a stage effects apply in increasing
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
#: the connection effects, solved together (catalog.gap_force, catalog.series_force)
CONNECTION = ("gap", "series_stiffness")
#: effects solved inside the connection only when it has a gap (their slots):
#: the accumulator sits behind the clearance
BEHIND_GAP = {"parallel_stiffness": ("Kp", "F0")}


def law_force(model, x, xv, dt, PL, substeps, record=None) -> np.ndarray:
    """The law on per-row (pop, n_t) or shared (1, n_t) kinematics [kN]."""
    if x.shape[0] == 1:
        return model.law.force(x[0], xv[0], dt, PL, substeps)
    if record is not None and model.law.number in VELOCITY_LAWS:
        moving = xv != 0.0
        if np.array_equal(xv[moving], np.broadcast_to(record.v, xv.shape)[moving]):
            # each row's velocity is the record's or 0 (a user's input effect): mask the shared evaluation
            return model.law.force(record.d, record.v, dt, PL, substeps) * moving
    with _single_thread():  # one compiled call per row: no thread start-up each time
        return np.vstack([model.law.force(x[i], xv[i], dt, PL[i:i + 1], substeps)
                          for i in range(PL.shape[0])])


def _effect(model, name):
    return next(e for e in model.effects if e.name == name)


def _connection(model, x, xv, xa, dt, PL, PE, pop, substeps):
    """The connection (catalog.gap_force with a gap, else catalog.series_force)
    with the built-in element effects inside: (F, u, F_o, x_o, the effects inside)."""
    zeros = np.zeros(pop)
    slots = {"r": zeros, "theta": zeros, "Ff": zeros, "Kp": zeros, "F0": zeros}
    inside = set()
    gap = model.has("gap")
    for other in model.effects:
        if other.series_slot:
            slots[other.series_slot] = PE[other.name][:, 0]
            inside.add(other.name)
        elif gap and other.name in BEHIND_GAP:
            for j, slot in enumerate(BEHIND_GAP[other.name]):
                slots[slot] = PE[other.name][:, j]
            inside.add(other.name)
    shape = (pop if x.shape[0] > 1 else 1, x.shape[1])
    motion = (model.law.number, PL, np.broadcast_to(x, shape), np.broadcast_to(xv, shape),
              np.broadcast_to(xa, shape), dt)
    if gap:
        Ks = PE["series_stiffness"][:, 0] if model.has("series_stiffness") else np.full(pop, np.inf)  # rigid
        out = _effect(model, "gap").function(PE["gap"], *motion, Ks, slots["r"], slots["theta"], slots["Ff"],
                                             slots["Kp"], slots["F0"], substeps)
    else:
        out = _effect(model, "series_stiffness").function(PE["series_stiffness"], *motion, slots["r"],
                                                          slots["theta"], slots["Ff"], substeps)
    return (*out, inside)


def _open_rows(model, P):
    """[(effect name, row mask)] of the connection effects switched off in
    some rows: a gap with g <= 0 (closed), a series spring with Ks >=
    KS_RIGID (rigid, the upper end of its range); None when no row has one."""
    from .catalog import KS_RIGID_FROM

    _, PE = model.split(P)
    off = []
    if model.has("gap"):
        off.append(("gap", PE["gap"][:, 0] <= 0.0))
    if model.has("series_stiffness"):
        off.append(("series_stiffness", PE["series_stiffness"][:, 0] >= KS_RIGID_FROM))
    return off if any(mask.any() for _, mask in off) else None


def _split_rows(model, record, P, off, substeps, parts):
    """Each group of rows with the same connection effects switched off,
    computed with the model without them (exactly that model: nesting)."""
    pop, n = P.shape[0], record.n
    group = np.zeros(pop, dtype=np.int64)
    for k, (_, mask) in enumerate(off):
        group |= mask.astype(np.int64) << k
    F = np.empty((pop, n))
    out_parts: dict = {}
    for g in np.unique(group):
        rows = np.flatnonzero(group == g)
        m, cols = model, list(range(P.shape[1]))
        for k, (name, _) in enumerate(off):
            if g >> k & 1:
                cols = [cols[j] for j in m.columns_without(name)]
                m = m.without_effect(name)
        PP = P[rows][:, cols]
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
    off = _open_rows(model, P)
    if off is not None:
        return _split_rows(model, record, P, off, substeps, parts)
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
    inside: set = set()
    if any(model.has(name) for name in CONNECTION):
        F, u, FO, xo, inside = _connection(model, x, xv, xa, dt, PL, PE, pop, substeps)
        if parts:
            rest = F
            for e in effects:
                if e.name in inside and e.name in BEHIND_GAP:
                    parts_out[e.name] = e.function(PE[e.name], record.t, xo, u, xa)
                    rest = rest - parts_out[e.name]
            friction = [e.name for e in effects if e.series_slot == "Ff"]
            parts_out["law"] = FO if friction else rest.copy()
            for name in friction:
                parts_out[name] = rest - FO
        # a user's output effect sees the law's own motion behind the connection
        xl, ul = xo, u
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
