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

With a connection (a series spring, a gap, or both) the element effects
that declare it (``Effect.inside_with``: asymmetry, thermal_softening,
friction, and with a gap parallel_stiffness: no force at all passes the
clearance) are solved inside its implicit step
(catalog.connection_force); a user's output or parallel effect is then
applied outside it.  A row in which a connection effect is switched off
(``Effect.off``: a gap closed, g <= 0, or a spring rigid, Ks >= KS_RIGID)
is computed exactly as the model without that effect, so every model is
nested in the one with one more effect.  Within a stage effects apply in increasing
``Effect.order``.  Without any effect the model is the law itself.
"""

from __future__ import annotations

import numba
import numpy as np

from ..errors import InputError
from .catalog import SLOT_OFF, connection_force

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


def law_force(model, x, xv, dt, PL, substeps, record=None) -> np.ndarray:
    """The law on per-row (pop, n_t) or shared (1, n_t) kinematics [kN]."""
    if x.shape[0] == 1:
        return model.law.force(x[0], xv[0], dt, PL, substeps)
    if record is not None and model.law.velocity_only:
        moving = xv != 0.0
        if np.array_equal(xv[moving], np.broadcast_to(record.v, xv.shape)[moving]):
            # each row's velocity is the record's or 0 (a user's input effect): mask the shared evaluation
            return model.law.force(record.d, record.v, dt, PL, substeps) * moving
    with _single_thread():  # one compiled call per row: no thread start-up each time
        return np.vstack([model.law.force(x[i], xv[i], dt, PL[i:i + 1], substeps)
                          for i in range(PL.shape[0])])


def inside_connection(model) -> set:
    """Names of the model's effects solved inside its connection: the
    connection effects (stage 'series') and those whose ``inside_with`` names
    one of them."""
    connections = {e.name for e in model.effects if e.stage == "series"}
    return connections | {e.name for e in model.effects if connections & set(e.inside_with)}


def _connection(model, x, xv, xa, dt, *, PL, PE, pop, substeps):
    """The connection (catalog.connection_force) with the element effects
    inside: (F, u, F_o, x_o, the names of the effects inside)."""
    inside = inside_connection(model)
    slots = {slot: np.full(pop, off) for slot, off in SLOT_OFF.items()}
    for e in model.effects:
        if e.name in inside:
            values = e.function(PE[e.name]) if e.stage == "series" and e.function else PE[e.name].T
            for slot, value in zip(e.slots, values):
                slots[slot] = np.broadcast_to(np.asarray(value, dtype=float), (pop,))
    shape = (pop if x.shape[0] > 1 else 1, x.shape[1])
    out = connection_force(model.law.number, PL, np.broadcast_to(x, shape), np.broadcast_to(xv, shape),
                           np.broadcast_to(xa, shape), dt, slots, substeps)
    return (*out, inside)


def _open_rows(model, P):
    """[(effect name, row mask)] of the connection effects switched off in
    some rows (``Effect.off``); None when no row has one."""
    _, PE = model.split(P)
    off = [(e.name, e.off(PE[e.name])) for e in model.effects if e.stage == "series"]
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
        self.threads = numba.get_num_threads()
        numba.set_num_threads(1)

    def __exit__(self, *exc):
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
    if any(e.stage == "series" for e in model.effects):
        F, u, FO, xo, inside = _connection(model, x, xv, xa, dt, PL=PL, PE=PE, pop=pop, substeps=substeps)
        if parts:
            rest = F
            for e in effects:  # the parallel terms inside act on the law's own motion
                if e.name in inside and e.stage == "parallel":
                    parts_out[e.name] = e.function(PE[e.name], record.t, xo, u, xa)
                    rest = rest - parts_out[e.name]
            parts_out["law"] = rest.copy()
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
