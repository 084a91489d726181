"""The effects' equations as scalar functions, and their population drivers.

Each equation is written once, as a scalar function of plain arithmetic that
ports line by line to C (the FMU): the asymmetry factor, the friction term,
the heat factor and energy, the play's sample step, the series spring's
stage equation and sample step; the drivers run them for every parameter
row in parallel (numba prange over the population), ``catalog.py`` applies
the stateless ones to whole arrays (numba ufuncs of the same functions) and
``scalar.py`` composes them for one member, sample by sample.  Units: kN, mm, s.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange, vectorize

from ..laws.fastmath import powsign, vlog
from ..laws.steps import (algebraic_force, algebraic_form, bouc_wen_constants, bouc_wen_step, law6_bouc_wen,
                          law8_constants, law9_constants, linear_force, lugre_step, maxwell_force, maxwell_log_rate,
                          power_term, sign_log, slip_step, split_travel)
from ..laws.trbdf2 import LAM_MIN, TRBDF2_GAMMA, maxwell_solve

#: smoothing velocity of the friction term [mm/s] (fixed, not fitted)
FRICTION_V_F = 1.0
#: J (kN mm) -> MJ
J_TO_MJ = 1e-6


# ------------------------------------------------ stateless terms (scalar + ufunc)
@njit(cache=True)
def asymmetry_factor(F, r):
    """Tension/compression asymmetry: 1 + r where the law force F > 0 (tension),
    1 - r where F < 0 (compression), 1 at F = 0."""
    return 1.0 + r if F > 0.0 else (1.0 - r if F < 0.0 else 1.0)


@njit(cache=True)
def friction_term(Ff, u):
    """Seal friction Ff tanh(u / v_f) [kN], u [mm/s], v_f = FRICTION_V_F."""
    return Ff * math.tanh(u / FRICTION_V_F)


@njit(cache=True)
def heat_factor(theta, W0):
    """Heating hf = exp(-theta E) = 1 / (1 + theta W0), theta [1/MJ], W0 [MJ]
    the energy the unsoftened law would have dissipated (``thermal_population``)."""
    return 1.0 / (1.0 + theta * W0)


@njit(cache=True)
def parallel_spring(Kp, F0, x):
    """Accumulator (gas spring) and preload: Kp x + F0 [kN], Kp [kN/mm], F0 [kN], x [mm]."""
    return Kp * x + F0


@njit(cache=True)
def inertia_term(m, xa):
    """Moving mass: m xa 1e-6 [kN], m [kg], xa [mm/s^2] (1 kg mm/s^2 = 1e-6 kN)."""
    return m * 1e-6 * xa


asymmetry_factors = vectorize(["float64(float64, float64)"], cache=True)(asymmetry_factor)
friction_terms = vectorize(["float64(float64, float64)"], cache=True)(friction_term)
parallel_springs = vectorize(["float64(float64, float64, float64)"], cache=True)(parallel_spring)
inertia_terms = vectorize(["float64(float64, float64)"], cache=True)(inertia_term)


# ----------------------------------------------------------------- gap (play)
@njit(cache=True)
def play_step(rel, u, half):
    """Play (backlash) of half-width ``half`` [mm] over a pin travel u [mm]
    of one sign: rel = pin position relative to the damper body, held in
    [-half, half]; the body moves only when |rel| reaches half (contact)."""
    rel += u
    if rel > half:
        return half
    if rel < -half:
        return -half
    return rel


@njit(cache=True)
def play_half(g):
    """Half-width [mm] of the play for a clearance g [mm] (none for g < 0)."""
    return 0.5 * max(g, 0.0)


@njit(cache=True)
def play_advance(rel, half, v0, v1, dt):
    """rel [mm] after a sample step dt [s] with the pin's velocity linear from
    v0 to v1 [mm/s]: its travel split where v changes sign, each part by
    ``play_step``."""
    u1, u2 = split_travel(v0, v1, dt)
    return play_step(play_step(rel, u1, half), u2, half)


@njit(cache=True)
def play_motion(rel, half, d, v, acc):
    """The damper body's motion at a sample (x [mm], xv [mm/s], xa [mm/s^2])
    from the pin's d, v, acc and rel: x = d - rel; in contact (rel = +-half,
    v pushing on that side) xv = v, xa = acc; in free play xv = xa = 0."""
    contact = (v > 0.0 and rel >= half) or (v < 0.0 and rel <= -half)
    return d - rel, (v if contact else 0.0), (acc if contact else 0.0)


@njit(parallel=True, cache=True)
def play_population(d, v, acc, dt, g):
    """Play operator of the imposed motion for each clearance g [mm]
    (half-width g/2); d, v, acc (pop or 1, n_t) [mm, mm/s, mm/s^2].

    The pin's travel in each sample step is the integral of v (linear
    between samples), split where v changes sign, so a reversal between two
    samples is located as the rig does; the body position is anchored to the
    measured d: x = d - rel.  It starts centred (rel = 0, out of contact).
    In contact (rel = +-g/2, v pushing on that side) the body moves with d:
    xv = v, xa = acc; in free play xv = xa = 0.
    Returns x, xv, xa (pop, n_t) [mm, mm/s, mm/s^2]."""
    pop, n = g.size, d.shape[1]
    x = np.empty((pop, n))
    xv = np.empty((pop, n))
    xa = np.empty((pop, n))
    rows = np.zeros(pop, np.int64) if d.shape[0] == 1 else np.arange(pop)
    for i in prange(pop):
        r = rows[i]
        half = play_half(g[i])
        rel = 0.0
        for k in range(n):
            if k > 0:
                rel = play_advance(rel, half, v[r, k - 1], v[r, k], dt)
            x[i, k], xv[i, k], xa[i, k] = play_motion(rel, half, d[r, k], v[r, k], acc[r, k])
    return x, xv, xa


# ----------------------------------------------------------- thermal softening
@njit(cache=True)
def heat_energy(W0, p0, p1, dt):
    """W0 [MJ] after a sample step dt [s] in which the power F xv went from p0
    to p1 [kN mm/s]: the trapezoidal rule, 1 kN mm = 1e-6 MJ."""
    return W0 + 0.5 * dt * (p0 + p1) * J_TO_MJ


@njit(parallel=True, cache=True)
def thermal_population(F, xv, dt, theta):
    """Heating: F / (1 + theta W0(t)) for each row, W0 [MJ] = 1e-6 integral
    F xv dt (trapezoidal rule) with F [kN] the unsoftened force and xv [mm/s]
    the law's velocity; F (pop, n_t), xv (pop or 1, n_t), theta (pop,) [1/MJ].

    This is F exp(-theta E) with E = 1e-6 integral of the *softened* force
    times xv: dE/dt = exp(-theta E) dW0/dt integrates to
    exp(theta E) = 1 + theta W0."""
    pop, n = F.shape
    out = np.empty((pop, n))
    rows = np.zeros(pop, np.int64) if xv.shape[0] == 1 else np.arange(pop)
    for i in prange(pop):
        r = rows[i]
        W = 0.0
        out[i, 0] = F[i, 0]
        p_prev = F[i, 0] * xv[r, 0]
        for k in range(1, n):
            p = F[i, k] * xv[r, k]
            W = heat_energy(W, p_prev, p, dt)
            out[i, k] = F[i, k] * heat_factor(theta[i], W)
            p_prev = p
    return out


# --------------------------------------------------------- series stiffness
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


@njit(cache=True)
def series_residual(q, a, code, p, y, wb, hth, x0, z0, zb, Ks, r, hf, Ff):
    """R(q) = F_int(x(u), u) - Ks w(u), u = u(q), w(u) = wb - hth u, x = y - w;
    law 7's state over the stage: z + hth q phi(z) = zb + (x - x0) (the same
    stage coefficient hth as the spring's stretch).

    R increases with q; returns R, dR/dq (Newton; exact for laws 1-5,
    approximate for 6-9) and u, w, F_o, z."""
    u, dudq = q_to_u(q, a)
    w = wb - hth * u
    x = y - w
    Fi, Fo, z, dfric, dFdx = element_force(code, p, x, x0, u, z0, zb, hth, r, hf, Ff)
    if code <= 5 and code != 1:
        dR = hf * asymmetry_factor(Fo, r) * p[0] + (dFdx * hth + dfric + Ks * hth) * dudq
    elif code == 1:
        dR = (hf * asymmetry_factor(Fo, r) * p[0] + dfric + Ks * hth) * dudq
    else:
        dR = 0.0  # estimated by the solver from a secant
    return Fi - Ks * w, dR, u, w, Fo, z


@njit(cache=True)
def series_step(q_guess, a, code, p, y, wb, hth, x0, z0, zb, Ks, r, hf, Ff):
    """Solve R(q) = 0 (series_residual, R increasing) for one step.

    Newton from ``q_guess`` (secant slopes for laws 6-9); until the signs of
    R bracket the root a step goes downhill by at most ``scale``, which grows
    geometrically; inside the bracket a step that leaves it is a bisection.
    Returns u, w, F_o, z at the root."""
    lo, hi = -math.inf, math.inf
    q = q_guess
    R, dR, u, w, Fo, z = series_residual(q, a, code, p, y, wb, hth, x0, z0, zb, Ks, r, hf, Ff)
    q_prev, R_prev = math.nan, math.nan
    scale = 0.5 * abs(q) + 1e-3
    for _ in range(200):
        if R == 0.0 or not math.isfinite(R):
            break
        if R < 0.0:
            lo = q
        else:
            hi = q
        if code > 5:
            if q_prev == q_prev and q_prev != q and R != R_prev:
                dR = (R - R_prev) / (q - q_prev)
            else:
                dq = 1e-7 * (1.0 + abs(q))
                R2 = series_residual(q + dq, a, code, p, y, wb, hth, x0, z0, zb, Ks, r, hf, Ff)[0]
                dR = (R2 - R) / dq
        step = R / dR if dR > 0.0 else math.nan
        if abs(step) <= 1e-9 * (1.0 + abs(q)):
            break
        qn = q - step
        if math.isinf(lo) or math.isinf(hi):
            # open bracket: go downhill, at most ``scale`` (growing) at a time
            down = 1.0 if R < 0.0 else -1.0
            if not (qn == qn and (qn - q) * down > 0.0 and abs(qn - q) <= scale):
                qn = q + down * scale
                scale *= 4.0
        elif not (lo < qn < hi):
            qn = 0.5 * (lo + hi)
            if hi - lo <= 1e-14 * (1.0 + abs(qn)):
                q = qn
                R, dR, u, w, Fo, z = series_residual(q, a, code, p, y, wb, hth, x0, z0, zb, Ks, r, hf, Ff)
                break
        q_prev, R_prev = q, R
        q = qn
        R, dR, u, w, Fo, z = series_residual(q, a, code, p, y, wb, hth, x0, z0, zb, Ks, r, hf, Ff)
    return u, w, Fo, z


@njit(cache=True)
def hermite_travel(s, h, v0, v1, a0, a1):
    """Travel [mm] from the start of a sample step h [s] to the fraction s of
    it, with the velocity the cubic Hermite interpolant of v0, v1 [mm/s] and
    a0, a1 [mm/s^2] at the ends (exact for cubic v)."""
    s2 = s * s
    s3 = s2 * s
    s4 = s3 * s
    return h * ((0.5 * s4 - s3 + s) * v0 + (0.25 * s4 - 2.0 * s3 / 3.0 + 0.5 * s2) * h * a0
                + (-0.5 * s4 + s3) * v1 + (0.25 * s4 - s3 / 3.0) * h * a1)


@njit(cache=True)
def series_rest(x0):
    """State of ``series_sample`` at rest: the spring unstretched, the law at
    rest at the body's displacement x0 [mm]; (w, u, z, W0, pw, x_o, q, dq)."""
    return (0.0, 0.0, 0.0, 0.0, 0.0, x0, 0.0, 0.0)


@njit(cache=True)
def series_sample(code, p, a, ks, r, theta, Ff, state, y0, y1, v0, v1, a0, a1, dt, substeps):
    """One sample step dt [s] of ``series_population`` for one member (law
    ``code``, parameters p, solver exponent a = ``law_exponent``, Ks [kN/mm],
    r [-], theta [1/MJ], Ff [kN]), cut in ``substeps`` TR-BDF2 steps.

    y, v, a at the two samples: the body's displacement [mm], velocity
    [mm/s] and acceleration [mm/s^2].  state = (w, u, z, W0, pw, x_o, q, dq):
    the spring's stretch [mm], the law's velocity [mm/s], its state z, W0
    [MJ], the law's power A law u [kN mm/s], its displacement [mm], and the
    solver's unknown q and its last change (``series_rest``).  Returns the
    state at the sample, F = Ks w [kN] and F_o [kN] of its last step."""
    w, u, z, W0, pw, xl, q, dq = state
    h = dt / substeps
    g = TRBDF2_GAMMA  # trapezoidal rule to t + g h, then BDF2 (L-stable)
    c_g = 1.0 / (g * (2.0 - g))
    c_0 = (1.0 - g) ** 2 / (g * (2.0 - g))
    c_h = (1.0 - g) / (2.0 - g) * h
    fo = 0.0
    jump = (v0 == 0.0) != (v1 == 0.0)
    for j in range(substeps):
        f0, f1 = j / substeps, (j + 1) / substeps
        fg = f0 + g * (f1 - f0)
        if jump:
            ya = y0 + (y1 - y0) * f0
            tr_g = (y1 - y0) * (fg - f0)
            tr_h = (y1 - y0) * (f1 - f0)
        else:
            base = hermite_travel(f0, dt, v0, v1, a0, a1)
            ya = y0 + base if j > 0 else y0
            tr_g = hermite_travel(fg, dt, v0, v1, a0, a1) - base
            tr_h = hermite_travel(f1, dt, v0, v1, a0, a1) - base
        yg = ya + tr_g
        yb = y0 + (y1 - y0) * f1 if (jump or j == substeps - 1) else ya + tr_h
        hf = heat_factor(theta, W0 + h * pw * J_TO_MJ) if theta != 0.0 else 1.0
        # TR stage to t + g h
        wb = w + tr_g - 0.5 * g * h * u
        hth = 0.5 * g * h  # law 7's trapezoidal stage: z + hth q phi(z) = z - hth q phi(z0) + travel
        zb = z - hth * law7_rate(z, p) if code == 7 else 0.0
        ug, wg, fog, zg = series_step(q + g * dq, a, code, p, yg, wb, hth, xl, z, zb, ks, r, hf, Ff)
        pwg = fog * ug / hf
        # BDF2 stage to t + h
        wb = c_g * wg - c_0 * w + tr_h - c_g * tr_g
        qg = powsign(ug, a) if a != 1.0 else ug
        # law 7's BDF2 stage: z1 - c_g z_g + c_0 z = travel terms - c_h q phi(z1)
        zb = c_g * zg - c_0 * z - c_0 * (yg - wg - xl) if code == 7 else 0.0
        u1, w1, fo, z1 = series_step(qg + (1.0 - g) * dq, a, code, p, yb, wb, c_h, yg - wg, zg, zb, ks, r, hf, Ff)
        pw1 = fo * u1 / hf
        W0 += (0.5 * g * h * (pw + pwg) + 0.5 * (1.0 - g) * h * (pwg + pw1)) * J_TO_MJ
        pw = pw1
        xl = yb - w1
        u, w, z = u1, w1, z1
        q1 = powsign(u, a) if a != 1.0 else u
        dq = q1 - q  # linear extrapolation of the next step's guess
        q = q1
    return (w, u, z, W0, pw, xl, q, dq), ks * w, fo


@njit(parallel=True, cache=True)
def series_population(code, x, xv, xa, dt, Ks, P, r, theta, Ff, substeps):
    """A spring Ks [kN/mm] in series with the internal element (law ``code``
    1-9 with parameters P[i], asymmetry r [-], heating theta [1/MJ], friction
    Ff [kN]), for each row i:

      F = Ks w = F_int(x_o, u),  w = x - x_o,  u = dx_o/dt,
      F_int = hf A law(x_o, u) + Ff tanh(u / v_f),  A = 1 +- r (sign of the law force),
      hf = 1 / (1 + theta W0),  W0 = 1e-6 integral A law u dt  [MJ]
      (hf = exp(-theta E), E the energy the law has dissipated, as in
      thermal_population).

    x, xv, xa (pop or 1, n_t): displacement [mm], velocity [mm/s] and
    acceleration [mm/s^2] of the damper body (the record's d, v, a or the
    gap's output).  Each sample step is split into ``substeps`` steps h.
    The spring's stretch w = psi - W, psi = integral of xv (the body's
    travel, exact for the cubic Hermite interpolant of xv and xa), and
    dW/dt = u by TR-BDF2 (Bank et al. 1985: the trapezoidal rule to t + g h,
    g = 2 - sqrt 2, then BDF2 to t + h; L-stable and second order, so a
    stiff spring (Ks large: rigid) neither rings nor lags):

      w_g = w_0 + psi(0 -> g h) - g h/2 (u_0 + u_g)
      w_1 = c_g w_g - c_0 w_0 + psi(0 -> h) - c_g psi(0 -> g h) - c_h u_1,
      c_g = 1/(g(2-g)), c_0 = (1-g)^2/(g(2-g)), c_h = (1-g)/(2-g) h.

    In a sample step where xv jumps to or from 0 (a gap's contact event) the
    travel is the body's position increment, spread linearly in time.  Each
    stage solves one scalar equation (series_step); hf from W0 at the start
    of each step.  The spring starts unstretched and the law at rest
    (series_rest); each member goes sample by sample (series_sample).

    Returns F [kN] (through the spring), u [mm/s] (the law's velocity) and
    F_o [kN] (the law force with asymmetry and heating), each (pop, n_t)."""
    pop, n = P.shape[0], x.shape[1]
    F = np.zeros((pop, n))
    U = np.zeros((pop, n))
    FO = np.zeros((pop, n))
    rows = np.zeros(pop, np.int64) if x.shape[0] == 1 else np.arange(pop)
    for i in prange(pop):
        ri = rows[i]
        p = P[i]
        a = law_exponent(code, p)
        state = series_rest(x[ri, 0])
        for k in range(1, n):
            state, F[i, k], FO[i, k] = series_sample(code, p, a, Ks[i], r[i], theta[i], Ff[i], state,
                                                     x[ri, k - 1], x[ri, k], xv[ri, k - 1], xv[ri, k],
                                                     xa[ri, k - 1], xa[ri, k], dt, substeps)
            U[i, k] = state[1]
    return F, U, FO
