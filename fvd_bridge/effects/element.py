"""The internal element behind a connection, in step form: the law (any law
whose ``connection`` capability is set) at the law's own displacement and
velocity, with asymmetry, heating and friction, as the series connection's
stage equation needs it (``connection.py``).  Mirrored in C by
``fmu/effects.c``.  Units: kN, mm, s.
"""

from __future__ import annotations

import math

from numba import njit

from ..laws.fastmath import vlog
from ..laws.steps import (algebraic_force, algebraic_form, bouc_wen_constants, bouc_wen_step, law6_bouc_wen,
                          law8_constants, law9_constants, linear_force, lugre_step, maxwell_force, maxwell_log_rate,
                          power_term, sign_log, slip_step)
from ..laws.trbdf2 import LAM_MIN, maxwell_solve
from .steps import FRICTION_V_F, asymmetry_factor, friction_term

#: largest |u| [mm/s] the series solver considers (keeps |q|^(1/alpha) finite)
U_MAX = 1e12
#: smallest exponent used to map q = sign(u)|u|^alpha back to u
ALPHA_MIN = 1e-3


@njit(cache=True)
def algebraic_law(code, x, u, p):
    """Force [kN] of law ``code`` (1-5; ``steps.algebraic_force``) at law
    displacement x [mm] and velocity u [mm/s], and the slope dS/dx of its
    rate-independent part S = K1 x + K2 x^2 + K sign(x)|x|^beta."""
    C, alpha, K1, K2, K, beta = algebraic_form(code, p)
    sign_u, log_u = sign_log(u)
    sign_x, log_x = sign_log(x)
    F = algebraic_force(C, alpha, K1, K2, K, beta, x, sign_u, log_u, sign_x, log_x)
    dS = K1 + 2.0 * K2 * x + (beta * power_term(K, 1.0, log_x, beta - 1.0) if x != 0.0 else 0.0)
    return F, dS


@njit(cache=True)
def law6_constants(p):
    """Law 6's constants (``steps.bouc_wen_constants``) from its parameter row p."""
    C, K, alpha, A, beta, gamma = law6_bouc_wen(p[0], p[1], p[2], p[3])
    return bouc_wen_constants(C, K, alpha, A, beta, gamma)


@njit(cache=True, error_model="numpy")  # as the law kernels it inlines: x/0 = inf
def hysteretic_state(code, z0, u, p, zb, hz):
    """Internal variable z of laws 6-9 at the end of a stage in which the law
    travels u [mm]: the exact steps of laws 6, 8, 9 (fvd_bridge.laws.steps)
    from z0; law 7 by the series spring's own TR-BDF2 stage (the rule the plain
    law uses too): z + hz q phi(z) = zb + u, zb the stage's known part
    (``series_sample``), solved by ``trbdf2.maxwell_solve`` (inside a series
    spring the law's own dashpot may be arbitrarily stiff)."""
    if code == 6:
        A, beta, gamma = law6_constants(p)[3:]
        return bouc_wen_step(z0, u, A, beta, gamma)
    if code == 8:
        return slip_step(z0, u, law8_constants(p[0], p[1], p[2], p[3])[3])
    if code == 9:
        return lugre_step(z0, u, law9_constants(p[0], p[1], p[2])[3])
    return maxwell_solve(zb + u, math.log(hz) + maxwell_log_rate(p[0], p[1], p[2]), p[3] / p[1])


@njit(cache=True)
def law7_rate(z, p):
    """q phi(z) = q sign(z)|z|^(beta/alpha), q = (K/C)^(1/alpha) (paper eq. 11) [mm/s]."""
    if z == 0.0:
        return 0.0
    return math.copysign(math.exp(maxwell_log_rate(p[0], p[1], p[2]) + p[3] / p[1] * math.log(abs(z))), z)


@njit(cache=True, error_model="numpy")  # as the law kernels it inlines: x/0 = inf
def hysteretic_force(code, x, z, u, p):
    """Force [kN] of laws 6-9 at law displacement x [mm], state z, velocity u [mm/s]."""
    if code == 6:
        a, b, C = law6_constants(p)[:3]
    elif code == 8:
        a, b, C = law8_constants(p[0], p[1], p[2], p[3])[:3]
    elif code == 9:
        a, b, C = law9_constants(p[0], p[1], p[2])[:3]
    else:  # law 7
        return maxwell_force(z, vlog(abs(z)) if z != 0.0 else LAM_MIN, vlog(max(p[2], 1e-300)), p[3])
    return linear_force(a, b, C, x, z, u)


@njit(cache=True)
def law_exponent(code, p):
    """Exponent a of the map q = sign(u)|u|^a used as the solver's unknown:
    the damping exponent of laws 2-5 (so the power term is linear in q), 1
    otherwise."""
    if 2 <= code <= 5:
        return min(max(p[1], ALPHA_MIN), 1.0)
    return 1.0


@njit(cache=True)
def q_to_u(q, a):
    """u = sign(q)|q|^(1/a), and du/dq; |u| capped at U_MAX."""
    if q == 0.0:
        return 0.0, (1.0 if a == 1.0 else 0.0)
    if a == 1.0:
        return q, 1.0
    lq = math.log(abs(q))
    lu = lq / a
    if lu > math.log(U_MAX):
        return math.copysign(U_MAX, q), 0.0
    u = math.copysign(math.exp(lu), q)
    return u, abs(u) / (a * abs(q))


@njit(cache=True)
def element_force(code, p, x, x0, u, z0, zb, hz, r, hf, Ff):
    """Internal element at the end of a step: the law at displacement x [mm]
    (x0 at the step start) and velocity u [mm/s], with asymmetry r [-] and
    heat factor hf [-], plus friction Ff tanh(u / v_f) [kN].

    Returns (F_int, F_o, z, dF_int/du at fixed x, dF_law/dx): F_o the law's
    force with asymmetry and heating (the orifice force), z the law state."""
    z = z0
    if code <= 5:
        Fl, dFdx = algebraic_law(code, x, u, p)
    else:
        z = hysteretic_state(code, z0, x - x0, p, zb, hz)
        Fl = hysteretic_force(code, x, z, u, p)
        dFdx = 0.0
    A = asymmetry_factor(Fl, r)
    Fo = hf * A * Fl
    fr = friction_term(Ff, u) if Ff != 0.0 else 0.0
    th = fr / Ff if Ff != 0.0 else 0.0
    return Fo + fr, Fo, z, Ff / FRICTION_V_F * (1.0 - th * th), hf * A * dFdx
