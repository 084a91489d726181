"""The damper's connection in series with the internal element, in step form:
a spring, a contact gap's dead zone, or both (the series stage of the
composition), solved per sample step by TR-BDF2 with one scalar root-find
per stage; the population driver runs it for every parameter row in
parallel (numba prange).  Mirrored in C by ``fmu/effects.c``.
Units: kN, mm, s.

The kernels take their values packed (read by the index names below):

- the members' constants, one float64 table (a row a member, columns
  SLOTS), packed once by the caller; inside, a member's row with the
  derived HALF and EXPONENT, a tuple (``series_population``);
- the state of ``series_sample``, a tuple (w, u, z, W0, pw, x_o, q, dq):
  the connection's stretch [mm], the law's velocity [mm/s], its state z,
  W0 [MJ], the law's power A law u [kN mm/s], its displacement [mm], and
  the solver's unknown q and its last change (``series_rest``);
- a sample step's motion, a tuple (y0, y1, v0, v1, a0, a1, dt): the pin's
  displacement [mm], velocity [mm/s] and acceleration [mm/s^2] at the two
  samples, and the step dt [s];
- a stage's knowns, a tuple (y, wb, hth, x0, z0, zb, hf): the pin's
  displacement at the stage's end y [mm], the stretch w = wb - hth u [mm]
  (u [mm/s], hth [s]), the law's displacement x0 [mm] and state z0 at the
  step's start, law 7's known part zb (``series_advance``) and the heat
  factor hf [-].

Inside the kernels these are tuples: numba keeps them on the stack, and an
array passed to every call of the solver costs reference counting (20% of
the connection's time, measured).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ..laws.fastmath import powsign
from ..laws.trbdf2 import TRBDF2_GAMMA
from .element import element_force, law7_rate, law_exponent, q_to_u
from .steps import J_TO_MJ, asymmetry_factor, heat_factor, parallel_spring

#: columns of ``series_population``'s table (the effects' slots, in this
#: order): Ks [kN/mm] (inf: a rigid contact), the gap's clearance g [mm]
#: (0: none), asymmetry r [-], heating theta [1/MJ], friction Ff [kN], and
#: behind a gap the parallel spring Kp [kN/mm] and preload F0 [kN]
SLOTS = ("Ks", "g", "r", "theta", "Ff", "Kp", "F0")
KS, GAP, ASYMMETRY, HEATING, FRICTION, KP, PRELOAD = range(len(SLOTS))
#: derived per member (``series_population``): the half clearance h = g/2
#: [mm] (``gap_half``) and the solver's exponent a (``law_exponent``)
HALF, EXPONENT = len(SLOTS), len(SLOTS) + 1
#: items of the state tuple (module docstring), as in ``fmu/effects.c``
SW, SU, SZ, SW0, SPW, SXL, SQ, SDQ = range(8)
#: the step dt [s], the last item of a sample step's motion tuple
DT = 6


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


# ------------------------------------------------------------------ contact gap
@njit(cache=True)
def gap_half(g):
    """Half clearance h = g/2 [mm] of a pin clearance g [mm] (total, both
    sides; none for g <= 0)."""
    return 0.5 * max(g, 0.0)


@njit(cache=True)
def dead_zone(w, half):
    """The contact gap's dead zone of half-width h = ``half`` [mm] on the
    connection's stretch w [mm] (pin relative to the law's displacement):

      dz(w, h) = w - h for w > h,  w + h for w < -h,  0 for |w| <= h;

    returns (dz, d dz/dw).  With h = 0 it is w itself (slope 1): a plain
    series spring."""
    if half == 0.0:
        return w, 1.0
    if w > half:
        return w - half, 1.0
    if w < -half:
        return w + half, 1.0
    return 0.0, 0.0


@njit(cache=True)
def gap_side(w, half):
    """Side of the clearance h = ``half`` [mm] at stretch w [mm]: +1 in
    contact on the tension side (w >= h), -1 on the compression side
    (w <= -h), 0 in the clearance (no force passes)."""
    if w >= half:
        return 1.0
    if w <= -half:
        return -1.0
    return 0.0


@njit(cache=True)
def linear_travel(f, dt, v0, v1):
    """Travel [mm] from the start of a sample step dt [s] to the fraction f
    of it, v linear from v0 to v1 [mm/s]."""
    return dt * f * (v0 + 0.5 * (v1 - v0) * f)


@njit(cache=True)
def series_residual(q, code, p, c, ks, stage):
    """R(q) = F_int(x(u), u) - ks dz(w(u), h), u = u(q) (exponent
    c[EXPONENT]), w(u) = wb - hth u, x = y - w (``dead_zone``,
    h = c[HALF]: w itself without a gap); F_int = ``element_force`` + Kp x
    + F0 (the parallel spring behind a gap; Kp = F0 = 0 otherwise); law 7's
    state over the stage: z + hth q phi(z) = zb + (x - x0) (the same stage
    coefficient hth as the spring's stretch).  c: the member's constants,
    ks [kN/mm] the spring in effect (c[KS], or 0: nothing passes), stage:
    the stage's knowns (module docstring).

    R increases with q; returns R, dR/dq (Newton; exact for laws 1-5,
    approximate for 6-9) and u, w, F_o, z."""
    y, wb, hth, x0, z0, zb, hf = stage
    Kp, F0 = c[KP], c[PRELOAD]
    u, dudq = q_to_u(q, c[EXPONENT])
    w = wb - hth * u
    x = y - w
    Fi, Fo, z, dfric, dFdx = element_force(code, p, x, x0, u, z0, zb, hth, c[ASYMMETRY], hf, c[FRICTION])
    if Kp != 0.0 or F0 != 0.0:
        Fi = Fi + parallel_spring(Kp, F0, x)
    s, ds = dead_zone(w, c[HALF])
    kd = ks * ds
    if code <= 5 and code != 1:
        dR = hf * asymmetry_factor(Fo, c[ASYMMETRY]) * p[0] + (dFdx * hth + dfric + (Kp + kd) * hth) * dudq
    elif code == 1:
        dR = (hf * asymmetry_factor(Fo, c[ASYMMETRY]) * p[0] + dfric + (Kp + kd) * hth) * dudq
    else:
        dR = 0.0  # estimated by the solver from a secant
    return Fi - ks * s, dR, u, w, Fo, z


@njit(cache=True)
def series_step(q_guess, code, p, c, ks, stage):
    """Solve R(q) = 0 (series_residual, R increasing) for one stage.

    Newton from ``q_guess`` (secant slopes for laws 6-9); until the signs of
    R bracket the root a step goes downhill by at most ``scale``, which grows
    geometrically; inside the bracket a step that leaves it is a bisection
    (so the kinks of a gap's dead zone cannot trap it).  Returns u, w, F_o, z
    at the root."""
    lo, hi = -math.inf, math.inf
    q = q_guess
    R, dR, u, w, Fo, z = series_residual(q, code, p, c, ks, stage)
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
                R2 = series_residual(q + dq, code, p, c, ks, stage)[0]
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
                R, dR, u, w, Fo, z = series_residual(q, code, p, c, ks, stage)
                break
        q_prev, R_prev = q, R
        q = qn
        R, dR, u, w, Fo, z = series_residual(q, code, p, c, ks, stage)
    return u, w, Fo, z


@njit(cache=True)
def series_stage(q_guess, code, p, c, ks, stage):
    """One stage of ``series_advance``: u, w, F_o, z and the force F [kN]
    through the connection at the stage's end.

    A spring (ks finite): the root of ``series_residual`` (``series_step``),
    F = ks dz(w, h).  A rigid contact (ks infinite: a gap without
    series_stiffness) is the limit of the same stage equation
    w = wb - hth u: contact on side s = +-1 holds where the element's force
    at w = s h, u_s = (wb - s h) / hth, has the sign s (F_int increases with
    u, so at most one side does, and the stiff spring's root would lie
    there); then u = u_s, w = s h, F = F_int(u_s).  Otherwise the connection
    is open: F_int(u) = 0 (``series_step`` with ks = 0), |w| <= h, F = 0."""
    half = c[HALF]
    if not math.isinf(ks):
        u, w, Fo, z = series_step(q_guess, code, p, c, ks, stage)
        return u, w, Fo, z, ks * dead_zone(w, half)[0]
    y, wb, hth, x0, z0, zb, hf = stage
    a = c[EXPONENT]
    first = 1.0 if wb >= 0.0 else -1.0  # the side the connection leans to first
    for side in (first, -first):
        u = (wb - side * half) / hth
        q = powsign(u, a) if a != 1.0 else u
        Fi, _, _, _, Fo, z = series_residual(q, code, p, c, 0.0, stage)
        if side * Fi > 0.0:
            return u, side * half, Fo, z, Fi
    u, w, Fo, z = series_step(q_guess, code, p, c, 0.0, stage)
    return u, min(max(w, -half), half), Fo, z, 0.0


@njit(cache=True)
def series_rest(x0, c):
    """State of ``series_sample`` at rest, the pin at x0 [mm]: a gap's pin
    centred in its clearance, the law at rest; a spring (Ks [kN/mm] finite,
    no gap) holds the accumulator behind it, Kp [kN/mm] and F0 [kN], in
    equilibrium: Ks w = Kp (x0 - w) + F0 (none where Ks + Kp <= 0 has no
    rest).  c: the member's constants."""
    Ks, Kp, F0 = c[KS], c[KP], c[PRELOAD]
    w = (Kp * x0 + F0) / (Ks + Kp) if c[HALF] == 0.0 and not math.isinf(Ks) and Ks + Kp > 0.0 else 0.0
    return (w, 0.0, 0.0, 0.0, 0.0, x0 - w, 0.0, 0.0)


@njit(cache=True)
def series_advance(code, p, c, ks, state, sample, fa, fb, h):
    """One TR-BDF2 step of ``series_sample`` from the fraction fa to fb of
    the sample step dt [s], h = (fb - fa) dt [s] (passed: dt / substeps for
    the regular sub-steps), with the spring ks [kN/mm] (c[KS], or 0 for the
    element's force-free motion).  The pin's travel psi: the cubic Hermite
    interpolant of v, a (``hermite_travel``), or the displacement increment
    y1 - y0 spread linearly in time in a step where v jumps to or from 0;
    with a gap (half > 0) the TR-BDF2 rule itself on v linear between the
    samples (the laws' own input), psi(0 -> g h) = g h/2 (v_0 + v_g),
    psi(0 -> h) = c_g psi(0 -> g h) + c_h v_1 (exact for linear v), so that
    the stage equations integrate w' = v - u and a rigid contact (w held at
    +-h) carries u = v at every stage end, also where the pin comes to rest
    or starts from it.  At the end of the sample step (fb = 1) the pin's
    displacement is y1.  Each stage by ``series_stage``.  Returns the
    state after the step, F_o [kN] and the force F [kN] through the
    connection at its end."""
    w, u, z, W0, pw, xl, q, dq = state
    y0, y1, v0, v1, a0, a1, dt = sample
    a, half, theta = c[EXPONENT], c[HALF], c[HEATING]
    jump = (v0 == 0.0) != (v1 == 0.0)
    g = TRBDF2_GAMMA  # trapezoidal rule to t + g h, then BDF2 (L-stable)
    c_g = 1.0 / (g * (2.0 - g))
    c_0 = (1.0 - g) ** 2 / (g * (2.0 - g))
    c_h = (1.0 - g) / (2.0 - g) * h
    fg = fa + g * (fb - fa)
    if half > 0.0:
        # with a gap the pin's travel by the law's own rule (TR-BDF2 on
        # w' = v - u, v linear): in rigid contact u is then the pin's v exactly
        ya = y0 + linear_travel(fa, dt, v0, v1)
        tr_g = 0.5 * g * h * ((v0 + (v1 - v0) * fa) + (v0 + (v1 - v0) * fg))
        tr_h = c_g * tr_g + c_h * (v0 + (v1 - v0) * fb)
    elif jump:
        ya = y0 + (y1 - y0) * fa
        tr_g = (y1 - y0) * (fg - fa)
        tr_h = (y1 - y0) * (fb - fa)
    else:
        base = hermite_travel(fa, dt, v0, v1, a0, a1)
        ya = y0 + base if fa > 0.0 else y0
        tr_g = hermite_travel(fg, dt, v0, v1, a0, a1) - base
        tr_h = hermite_travel(fb, dt, v0, v1, a0, a1) - base
    yg = ya + tr_g
    yb = y0 + (y1 - y0) * fb if ((jump and half == 0.0) or fb >= 1.0) else ya + tr_h
    hf = heat_factor(theta, W0 + h * pw * J_TO_MJ) if theta != 0.0 else 1.0
    # TR stage to t + g h
    wb = w + tr_g - 0.5 * g * h * u
    hth = 0.5 * g * h  # law 7's trapezoidal stage: z + hth q phi(z) = z - hth q phi(z0) + travel
    zb = z - hth * law7_rate(z, p) if code == 7 else 0.0
    ug, wg, fog, zg, _ = series_stage(q + g * dq, code, p, c, ks, (yg, wb, hth, xl, z, zb, hf))
    pwg = fog * ug / hf
    # BDF2 stage to t + h
    wb = c_g * wg - c_0 * w + tr_h - c_g * tr_g
    qg = powsign(ug, a) if a != 1.0 else ug
    # law 7's BDF2 stage: z1 - c_g z_g + c_0 z = travel terms - c_h q phi(z1)
    zb = c_g * zg - c_0 * z - c_0 * (yg - wg - xl) if code == 7 else 0.0
    u1, w1, fo, z1, F1 = series_stage(qg + (1.0 - g) * dq, code, p, c, ks, (yb, wb, c_h, yg - wg, zg, zb, hf))
    pw1 = fo * u1 / hf
    W0 += (0.5 * g * h * (pw + pwg) + 0.5 * (1.0 - g) * h * (pwg + pw1)) * J_TO_MJ
    q1 = powsign(u1, a) if a != 1.0 else u1
    # dq: linear extrapolation of the next step's guess
    return (w1, u1, z1, W0, pw1, yb - w1, q1, q1 - q), fo, F1


#: a contact that closes within this fraction of a step's ends is not split off
CONTACT_EDGE = 1e-6
#: locating one contact inside a step: at most this many re-computed steps
CONTACT_SPLITS = 4
#: pieces of one step at most (each but the last ends at a located contact)
CONTACT_PIECES = 4


@njit(cache=True)
def contact_fraction(code, p, c, state, w1, sample, fa, fb):
    """Where in a step of ``series_advance`` (from the fractions fa to fb of
    the sample step, from ``state``, ending at stretch w1 [mm]) the
    contact gap closes, as a fraction s of the step; 0 when nothing is to be
    split off.

    The step closes the contact when w1 is in contact on a side other than
    the start's (``gap_side``).  From the clearance, s is where the
    element's own force-free motion (the same step with ks = 0: nothing
    passes the connection) brings |w| to h = c[HALF]: regula falsi
    (Illinois) on the stretch at the end of the step cut at s.  A step that
    crosses the whole clearance (it starts in contact on the other side) is
    halved; one whose free motion reaches h only at its end (to rounding)
    is not split.  A contact within
    CONTACT_EDGE of either end is not split off: the step's own error is
    then of that size."""
    half, dt = c[HALF], sample[DT]
    w0 = state[SW]
    side = gap_side(w1, half)
    if side == 0.0 or side == gap_side(w0, half):
        return 0.0
    if gap_side(w0, half) != 0.0:
        return 0.5
    lo, f_lo = 0.0, side * w0 - half
    hi = 1.0
    f_hi = side * series_advance(code, p, c, 0.0, state, sample, fa, fb, (fb - fa) * dt)[0][SW] - half
    if not f_hi > 0.0:
        return 0.0  # the free motion reaches h only at the end (to rounding)
    s = 1.0
    last = 0
    for _ in range(40):
        s = (lo * f_hi - hi * f_lo) / (f_hi - f_lo)
        f = fa + (fb - fa) * s
        f_s = side * series_advance(code, p, c, 0.0, state, sample, fa, f, (f - fa) * dt)[0][SW] - half
        if f_s > 0.0:
            hi, f_hi = s, f_s
            if last == 1:
                f_lo *= 0.5  # Illinois: the end kept twice is halved
            last = 1
        else:
            lo, f_lo = s, f_s
            if last == -1:
                f_hi *= 0.5
            last = -1
        if abs(f_s) <= 1e-12 * (1.0 + half) or hi - lo <= 1e-12:
            break
    if s < CONTACT_EDGE or s > 1.0 - CONTACT_EDGE:
        return 0.0
    return s


@njit(cache=True)
def series_sample(code, p, c, state, sample, substeps):
    """One sample step of ``series_population`` for one member (law
    ``code``, parameters p, constants c (module docstring); Ks = inf a
    rigid contact, half clearance 0 no gap), cut in ``substeps`` TR-BDF2
    steps (``series_advance``); ``state`` and the motion ``sample`` as in the
    module docstring.

    With a gap, a step in which the contact closes is cut where it closes
    (``contact_fraction``): the law's velocity jumps there, and a step that
    starts at the contact integrates the jump exactly.  Returns the state
    at the sample, F [kN] through the connection (Ks dz(w, h), or the
    element's force in a rigid contact) and F_o [kN] of its last step."""
    ks, half, dt = c[KS], c[HALF], sample[DT]
    h = dt / substeps
    fo, F = 0.0, 0.0
    for j in range(substeps):
        f0, f1 = j / substeps, (j + 1) / substeps
        if half == 0.0:
            state, fo, F = series_advance(code, p, c, ks, state, sample, f0, f1, h)
            continue
        fa = f0
        pieces = 0
        while fa < f1:
            fb = f1
            new, fo, F = series_advance(code, p, c, ks, state, sample, fa, fb, (fb - fa) * dt)
            if pieces < CONTACT_PIECES:
                for _ in range(CONTACT_SPLITS):
                    s = contact_fraction(code, p, c, state, new[SW], sample, fa, fb)
                    if s == 0.0:
                        break
                    fb = fa + (fb - fa) * s
                    new, fo, F = series_advance(code, p, c, ks, state, sample, fa, fb, (fb - fa) * dt)
            state = new
            fa = fb
            pieces += 1
    return state, F, fo


@njit(parallel=True, cache=True)
def series_population(code, x, xv, xa, dt, P, table, substeps):
    """The damper's connection in series with the internal element, for each
    row i of P and ``table`` (columns SLOTS): a spring Ks [kN/mm] (inf: a
    rigid contact, ``series_stage``) whose force has a dead zone of
    half-width h = g/2 [mm] (a contact gap of clearance g; 0: a plain series
    spring; ``gap_half``), carrying
    the element (law ``code`` 1-9 with parameters P[i], asymmetry r [-],
    heating theta [1/MJ], friction Ff [kN], and behind a gap the parallel
    spring Kp [kN/mm], F0 [kN]; zeros when absent):

      F = Ks dz(w, h) = F_int(x_o, u),  w = x - x_o,  u = dx_o/dt,
      F_int = hf A law(x_o, u) + Ff tanh(u / v_f) + Kp x_o + F0,
      A = 1 +- r (sign of the law force),
      hf = 1 / (1 + theta W0),  W0 = 1e-6 integral A law u dt  [MJ]
      (hf = exp(-theta E), E the energy the law has dissipated, as in
      thermal_population); dz the dead zone (``dead_zone``).

    In the clearance (|w| <= h) F = 0 and the element moves force-free,
    F_int(x_o, u) = 0: a viscous law holds still, a hysteretic or friction
    element unloads through its own dashpot.  Contact holds while the force
    keeps its sign and opens when it would reverse.

    x, xv, xa (pop or 1, n_t): displacement [mm], velocity [mm/s] and
    acceleration [mm/s^2] of the pin (the record's d, v, a).  Each sample
    step is split into ``substeps`` steps h.  The stretch w = psi - W,
    psi = integral of xv (the pin's travel, exact for the cubic Hermite
    interpolant of xv and xa), and dW/dt = u by TR-BDF2 (Bank et al. 1985:
    the trapezoidal rule to t + g h, g = 2 - sqrt 2, then BDF2 to t + h;
    L-stable and second order, so a stiff spring neither rings nor lags):

      w_g = w_0 + psi(0 -> g h) - g h/2 (u_0 + u_g)
      w_1 = c_g w_g - c_0 w_0 + psi(0 -> h) - c_g psi(0 -> g h) - c_h u_1,
      c_g = 1/(g(2-g)), c_0 = (1-g)^2/(g(2-g)), c_h = (1-g)/(2-g) h.

    In a sample step where xv jumps to or from 0 the travel is the
    position increment, spread linearly in time; with a gap psi is always
    integrated from xv by the same TR-BDF2 rule (``series_advance``).  Each
    stage solves one scalar equation (series_stage); hf from W0 at the
    start of each step.
    The connection starts at rest (series_rest: a gap's pin centred, a
    spring holding the accumulator behind it) and the law at rest; each member goes sample by sample (series_sample;
    a gap's contact events split its steps).

    Returns F [kN] (through the connection), u [mm/s] (the law's velocity),
    F_o [kN] (the law force with asymmetry and heating) and x_o [mm] (the
    law's displacement), each (pop, n_t)."""
    pop, n = P.shape[0], x.shape[1]
    F = np.zeros((pop, n))
    U = np.zeros((pop, n))
    FO = np.zeros((pop, n))
    XO = np.empty((pop, n))
    rows = np.zeros(pop, np.int64) if x.shape[0] == 1 else np.arange(pop)
    for i in prange(pop):
        ri = rows[i]
        p = P[i]
        row = table[i]  # the member's constants: its row, then HALF and EXPONENT
        c = (row[KS], row[GAP], row[ASYMMETRY], row[HEATING], row[FRICTION], row[KP], row[PRELOAD],
             gap_half(row[GAP]), law_exponent(code, p))
        state = series_rest(x[ri, 0], c)
        XO[i, 0] = state[SXL]
        F[i, 0] = c[KS] * state[SW] if state[SW] != 0.0 else 0.0
        for k in range(1, n):
            sample = (x[ri, k - 1], x[ri, k], xv[ri, k - 1], xv[ri, k], xa[ri, k - 1], xa[ri, k], dt)
            state, F[i, k], FO[i, k] = series_sample(code, p, c, state, sample, substeps)
            U[i, k] = state[SU]
            XO[i, k] = state[SXL]
    return F, U, FO, XO
