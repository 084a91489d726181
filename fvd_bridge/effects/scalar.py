"""A model (a built-in law with built-in effects) for one member, sample by
sample: the reference for the FMU's C code.

The FMU's C code mirrors ``model_history``'s loop body, its doStep.  Per
sample k, in the order of ``compose.py`` (d, v, a the record's: the pin's
motion x, xv, xa):

  1. connection  a gap (g > 0) and/or a series spring (Ks < KS_RIGID):
               F = Ks dz(w, g/2) of one sample step of the connection
               (``connection.series_sample``; Ks = inf, a rigid contact, for a
               gap alone; dz = w without a gap) with asymmetry,
               heating, friction and, behind a gap, Kp x_o + F0 inside it;
               F = 0 at k = 0 (the pin centred);
     or law    the law's sub-steps with xv linear between samples
               (``laws.scalar.advance``), F = ``laws.scalar.force``(x, xv);
  2. output    (without a connection) F *= ``steps.asymmetry_factor``(F, r);
               heating: W0 = ``steps.heat_energy`` of the power F xv (F with
               asymmetry, before heating), F *= ``steps.heat_factor``(theta, W0);
  3. parallel  + ``steps.friction_term``(Ff, xv) (without a connection),
               + Kp x + F0 (``catalog.parallel_force``; without a gap),
               + m 1e-6 xa (``catalog.inertia_force``), added in this order.

An effect is on where ``flags[effect]`` is set (the model has it), with its
parameters in the fixed layout ``PARAMETERS``; g <= 0 is no gap and
Ks >= KS_RIGID a rigid connection (the model without the effect, as
``compose.py``).  Every equation is a call to ``steps.py`` or
``laws/scalar.py``, except the two parallel terms, which ``catalog.py``
writes as array expressions only.
Compiled without fastmath, so the sums round as numpy's (no fused
multiply-adds); the law's sub-step velocities with ``laws.scalar``'s flags
(``law_sample``).  tests/test_scalar_models.py checks it against
``Model.force``: bit for bit on laws 2, 5-9 and behind a connection;
laws 1, 3, 4 without one to rounding (their drivers: F = C v, and
fastmath=True).  Units: kN, mm, s, mass kg.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..errors import InputError
from ..laws.differential import _sub_velocities
from ..laws.scalar import advance, force, law_constants, new_state, one_member
from .catalog import BUILTIN, EFFECTS, KS_RIGID_FROM
from .connection import gap_half, series_rest, series_sample
from .element import law_exponent
from .steps import asymmetry_factor, friction_term, heat_energy, heat_factor, inertia_term, parallel_spring

#: the effects, in ``flags`` order (the catalog's)
EFFECT_NAMES = tuple(e.name for e in BUILTIN)
GAP, SERIES, ASYMMETRY, THERMAL, FRICTION, PARALLEL, INERTIA = range(7)
#: the effects' parameters, in ``p_eff`` order, and the values that switch each off
PARAMETERS = tuple(n for e in BUILTIN for n in e.names)
OFF = tuple(x for e in BUILTIN for x in e.none)
G, KS, R, THETA, FF, KP, F0, M = range(8)


# compiled with laws.scalar's fastmath flags, as its history and the drivers:
# there 'arcp' turns j/m into j*(1/m); without it members differ by up to
# 3e-16 of the peak force at substeps=3 (bit for bit with it)
@one_member
def law_sample(code, k, s, v0, v1, h, substeps):
    """The law's sub-steps of h [s] over one sample step, v linear from v0 to
    v1 [mm/s] (``laws.scalar.advance``, as ``laws.scalar.history``): update
    its state s in place."""
    for j in range(substeps):
        va, vb = _sub_velocities(v0, v1, j, substeps)
        advance(code, k, s, va, vb, h)


@njit(cache=True, error_model="numpy")
def model_history(code, flags, p_law, p_eff, d, v, a, dt, substeps=1):
    """Force history [kN] (n_t,) of one member: law ``code`` (1-9) with
    parameters p_law (law order) and the effects on in ``flags`` (bool
    (7,), EFFECT_NAMES order) with parameters p_eff (8,) (PARAMETERS order:
    g [mm], Ks [kN/mm], r [-], theta [1/MJ], Ff [kN], Kp [kN/mm], F0 [kN],
    m [kg]), for d [mm], v [mm/s], a [mm/s^2] sampled every dt [s], from
    rest; each sample step in ``substeps`` sub-steps (module docstring)."""
    n = d.size
    F = np.empty(n)
    # compose._open_rows: a closed gap or a rigid spring is the model without it
    gap = flags[GAP] and p_eff[G] > 0.0
    series = flags[SERIES] and not p_eff[KS] >= KS_RIGID_FROM
    connected = gap or series
    ks = p_eff[KS] if series else math.inf  # a gap alone: a rigid contact
    half = gap_half(p_eff[G]) if gap else 0.0
    # inside the connection an absent effect is its 'off' value (as compose._connection)
    r = p_eff[R] if flags[ASYMMETRY] else 0.0
    theta = p_eff[THETA] if flags[THERMAL] else 0.0
    Ff = p_eff[FF] if flags[FRICTION] else 0.0
    behind = gap and flags[PARALLEL]  # the accumulator behind the clearance (compose.BEHIND_GAP)
    kp = p_eff[KP] if behind else 0.0
    f0 = p_eff[F0] if behind else 0.0
    h = dt / substeps
    k_law, s_law = law_constants(code, p_law, h), new_state(code)
    q_exp = law_exponent(code, p_law)
    spring = series_rest(0.0)  # the connection's state, set at sample 0
    W0, power = 0.0, 0.0
    x0, xv0, xa0 = 0.0, 0.0, 0.0
    for k in range(n):
        x, xv, xa = d[k], v[k], a[k]
        if connected:
            # 1. the connection, with the law and the element effects inside
            if k == 0:
                spring = series_rest(x)
                f = 0.0
            else:
                spring, f, _ = series_sample(code, p_law, q_exp, ks, half, r, theta, Ff, kp, f0, spring,
                                             x0, x, xv0, xv, xa0, xa, dt, substeps)
        else:
            # 1. the law
            if k > 0:
                law_sample(code, k_law, s_law, xv0, xv, h, substeps)
            f = force(code, k_law, s_law, x, xv)
            # 2. output
            if flags[ASYMMETRY]:
                f = f * asymmetry_factor(f, r)
            if flags[THERMAL]:
                p1 = f * xv
                if k > 0:
                    W0 = heat_energy(W0, power, p1, dt)
                    f = f * heat_factor(theta, W0)
                power = p1
            # 3. parallel: friction on the law's velocity (inside the connection with one)
            if flags[FRICTION]:
                f = f + friction_term(Ff, xv)
        # 3. parallel
        if flags[PARALLEL] and not behind:
            f = f + parallel_spring(p_eff[KP], p_eff[F0], x)
        if flags[INERTIA]:
            f = f + inertia_term(p_eff[M], xa)
        F[k] = f
        x0, xv0, xa0 = x, xv, xa
    return F


def scalar_arguments(model, params) -> tuple:
    """(code, flags, p_law, p_eff) of ``model_history`` for a Model and one
    parameter vector (``model.names`` order); an effect that is not built
    in (a plugin's) has no scalar form: InputError naming it."""
    for e in model.effects:
        if EFFECTS.get(e.name) is not e:
            raise InputError(f"model '{model.spec}': effect '{e.name}' ({e.source}) has no scalar form "
                             f"(built-in effects only: {', '.join(EFFECT_NAMES)})")
    p = np.asarray(params, dtype=float).ravel()
    if p.size != len(model.names):
        raise InputError(f"model {model.spec}: expected {len(model.names)} parameters "
                         f"({', '.join(model.names)}), got {p.size}")
    p_law, by_effect = model.split(p[None, :])
    flags = np.zeros(len(EFFECT_NAMES), dtype=np.bool_)
    p_eff = np.array(OFF, dtype=float)
    for name, values in by_effect.items():
        flags[EFFECT_NAMES.index(name)] = True
        for pname, x in zip(EFFECTS[name].names, values[0]):
            p_eff[PARAMETERS.index(pname)] = x
    return model.law.number, flags, np.ascontiguousarray(p_law[0]), p_eff


def scalar_force(model, params, record, substeps: int = 1) -> np.ndarray:
    """Force [kN] (n_t,) of ``model`` with one parameter vector for the
    record's d [mm], v [mm/s], a [mm/s^2] (``model_history``); the same as
    ``model.force(record, params[None])[0]`` to rounding."""
    code, flags, p_law, p_eff = scalar_arguments(model, params)
    c = np.ascontiguousarray
    return model_history(code, flags, p_law, p_eff, c(record.d, dtype=float), c(record.v, dtype=float),
                         c(record.a, dtype=float), float(record.dt), int(substeps))
