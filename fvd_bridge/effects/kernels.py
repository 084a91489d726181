"""Scalar step functions of the stateful effects and their population drivers.

Each equation is written once, as a scalar function of plain arithmetic that
ports line by line to C (the FMU); the drivers run it for every parameter row
in parallel (numba prange over the population).  Units: kN, mm, s.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ..laws.steps import bouc_wen_step, lugre_step, maxwell_step, powsign, slip_step

#: J (kN mm) -> MJ
J_TO_MJ = 1e-6


# ----------------------------------------------------------------- gap (play)
@njit(cache=True)
def play_step(y, d, half):
    """Play (backlash) operator with half-width ``half`` [mm]: y stays until
    |d - y| reaches half, then follows d at that distance."""
    if d - y > half:
        return d - half
    if y - d > half:
        return d + half
    return y


@njit(cache=True)
def play_velocity(y, d, v, half):
    """Velocity [mm/s] of the play output: v while the pin is in contact and
    pushing (d at the edge of the clearance, moving outward), else 0."""
    if v > 0.0 and d - y >= half:
        return v
    if v < 0.0 and y - d >= half:
        return v
    return 0.0


@njit(parallel=True, cache=True)
def play_population(d, v, g):
    """Play operator of d [mm] for each clearance g [mm] (half-width g/2),
    starting centred (x = d at t = 0); d, v (pop or 1, n_t) [mm, mm/s].
    Returns x, xv (pop, n_t) [mm, mm/s]."""
    pop, n = g.size, d.shape[1]
    x = np.empty((pop, n))
    xv = np.empty((pop, n))
    rows = np.zeros(pop, np.int64) if d.shape[0] == 1 else np.arange(pop)
    for i in prange(pop):
        r = rows[i]
        half = 0.5 * max(g[i], 0.0)
        y = d[r, 0]
        for k in range(n):
            y = play_step(y, d[r, k], half)
            x[i, k] = y
            xv[i, k] = play_velocity(y, d[r, k], v[r, k], half)
    return x, xv


# ----------------------------------------------------------- thermal softening
@njit(cache=True)
def heat_step(E, p0, p1, h):
    """Dissipated energy [MJ] after a step h [s] with power p0 -> p1 [kN mm/s]
    (trapezoidal rule)."""
    return E + 0.5 * h * (p0 + p1) * J_TO_MJ


@njit(parallel=True, cache=True)
def thermal_population(F, xv, dt, theta):
    """F exp(-theta E(t)), E [MJ] = integral of F xv dt so far (the law's
    dissipated energy, from the unsoftened force F [kN] and the law's velocity
    xv [mm/s]); F (pop, n_t), xv (pop or 1, n_t), theta (pop,) [1/MJ]."""
    pop, n = F.shape
    out = np.empty((pop, n))
    rows = np.zeros(pop, np.int64) if xv.shape[0] == 1 else np.arange(pop)
    for i in prange(pop):
        r = rows[i]
        E = 0.0
        out[i, 0] = F[i, 0]
        p_prev = F[i, 0] * xv[r, 0]
        for k in range(1, n):
            p = F[i, k] * xv[r, k]
            E = heat_step(E, p_prev, p, dt)
            out[i, k] = F[i, k] * math.exp(-theta[i] * E)
            p_prev = p
    return out


# --------------------------------------------------------- series stiffness
#: largest exponent of the dashpot rate exp(log(|u|/C)/alpha) (keeps it finite)
RATE_LOG_MAX = 690.0
#: smallest damping exponent used by the series solver (alpha -> 0 is a slider)
ALPHA_MIN = 1e-3


@njit(cache=True)
def dashpot_rate(u, C, alpha):
    """Velocity [mm/s] of a dashpot C sign(xd)|xd|^alpha carrying force u [kN]:
    xd = sign(u) (|u|/C)^(1/alpha), and d xd / du (for Newton)."""
    if u == 0.0:
        return 0.0, (1.0 / C if alpha == 1.0 and C > 0.0 else 0.0)
    a = max(alpha, ALPHA_MIN)
    c = max(C, 1e-300)
    lr = math.log(abs(u) / c) / a
    if lr > RATE_LOG_MAX:
        r = math.exp(RATE_LOG_MAX)
        return math.copysign(r, u), 0.0
    r = math.exp(lr)
    return math.copysign(r, u), r / (a * abs(u))


@njit(cache=True)
def static_force(code, x, p):
    """Rate-independent spring part S(x) [kN] of laws 3-5 and its slope dS/dx."""
    if code == 3:
        return p[2] * x, p[2]
    if code == 4:
        return p[2] * x + p[3] * x * x, p[2] + 2.0 * p[3] * x
    if code == 5:
        ax = abs(x)
        if ax == 0.0:
            return 0.0, 0.0
        s = p[2] * math.copysign(ax ** p[3], x)
        return s, p[3] * abs(s) / ax
    return 0.0, 0.0


@njit(cache=True)
def viscous_residual(w, w0, travel, xd0, h, y, Ks, code, p):
    """Series spring Ks [kN/mm] + law 1-5, trapezoidal rule on the spring
    stretch w [mm] (F = Ks w):

      dw/dt = xv - xd,  xd = dashpot velocity carrying Ks w - S(y - w),
      g(w) = w - w0 - travel + h/2 (xd0 + xd(w)) = 0,

    with travel = integral of xv over the step.  Returns g, dg/dw, xd."""
    if code == 1:
        C, alpha = p[0], 1.0
    else:
        C, alpha = p[0], p[1]
    S, dS = static_force(code, y - w, p)
    xd, dxd = dashpot_rate(Ks * w - S, C, alpha)
    g = w - w0 - travel + 0.5 * h * (xd0 + xd)
    dg = 1.0 + 0.5 * h * dxd * (Ks + dS)
    return g, dg, xd


@njit(cache=True)
def hysteretic_state(code, z0, u, p, h):
    """Internal variable z of laws 6-9 after a law travel u [mm] over h [s]
    (the exact/implicit steps of fvd_bridge.laws.steps)."""
    if code == 6:
        return bouc_wen_step(z0, u, 1.0, p[3], p[3])
    if code == 8:
        muN = p[2] * p[3]
        return slip_step(z0, u, p[1] / muN if muN > 0.0 else 0.0)
    if code == 9:
        return lugre_step(z0, u, p[1])
    # law 7: spring deformation of the Lu visco-elastic element
    C, alpha, K, beta = p[0], p[1], p[2], p[3]
    if C > 0.0 and K > 0.0:
        q = min(math.exp(math.log(K / C) / alpha), 1e150)
    else:
        q = 1e150 if C <= 0.0 else 0.0
    return maxwell_step(z0, u, h, q, beta / alpha)


@njit(cache=True)
def hysteretic_force(code, x, z, xd, p):
    """Force [kN] of laws 6-9 at law displacement x, state z, law velocity xd."""
    if code == 6:
        return p[2] * p[1] * x + (1.0 - p[2]) * p[1] * z + p[0] * xd
    if code == 8:
        return z * p[2] * p[3] + p[0] * xd
    if code == 9:
        return p[2] * z + p[0] * xd
    return p[2] * powsign(z, p[3])


@njit(cache=True)
def hysteretic_residual(w, x0, z0, y, h, Ks, code, p):
    """Series spring + law 6-9: force balance Ks w = law(x, z, xd) at the end
    of the step, x = y - w, law travel u = x - x0, z = z(z0, u), xd = u / h
    (backward Euler on the law's viscous term; first order, use substeps).
    Returns the residual (increasing in w) and z."""
    x = y - w
    u = x - x0
    z = hysteretic_state(code, z0, u, p, h)
    return Ks * w - hysteretic_force(code, x, z, u / h, p), z


@njit(cache=True)
def _bracket_root(gl, gh, wl, wh):
    """Illinois false-position step, kept inside the bracket."""
    w = wh - gh * (wh - wl) / (gh - gl) if gh != gl else 0.5 * (wl + wh)
    if not (min(wl, wh) < w < max(wl, wh)):
        w = 0.5 * (wl + wh)
    return w


@njit(cache=True)
def series_viscous_step(w0, xd0, y, travel, h, Ks, code, p, w_guess):
    """One step of Ks in series with a law 1-5: returns (w, xd).

    Newton on g(w) (viscous_residual) from ``w_guess``, safeguarded by the
    bracket that the signs of g build up (g increases with w; the dashpot
    rate is convex on the side of the root, so Newton lands on the far side
    and then converges monotonically)."""
    lo, hi = -math.inf, math.inf
    w = w_guess
    g, dg, xd = viscous_residual(w, w0, travel, xd0, h, y, Ks, code, p)
    scale = abs(travel) + abs(h * xd0) + 1e-9 * (1.0 + abs(w))
    for _ in range(100):
        if g == 0.0:
            return w, xd
        if g < 0.0:
            lo = w
        else:
            hi = w
        dx = g / dg if dg > 0.0 else math.nan
        if abs(dx) <= 1e-12 * (1.0 + abs(w)):
            return w, xd  # converged (Newton step below round-off)
        wn = w - dx
        if not (lo < wn < hi):
            if math.isinf(lo) or math.isinf(hi):
                # no bracket yet on one side: step out geometrically
                scale *= 2.0
                wn = w + scale if g < 0.0 else w - scale
            else:
                wn = 0.5 * (lo + hi)
                if hi - lo <= 1e-12 * (1.0 + abs(wn)):
                    w = wn
                    g, dg, xd = viscous_residual(w, w0, travel, xd0, h, y, Ks, code, p)
                    return w, xd
        w = wn
        g, dg, xd = viscous_residual(w, w0, travel, xd0, h, y, Ks, code, p)
    return w, xd


@njit(cache=True)
def series_hysteretic_step(w0, x0, z0, y, h, Ks, code, p):
    """One step of Ks in series with a law 6-9: returns (w, z).

    Illinois false position on the increasing residual hysteretic_residual(w)
    inside a bracket found by expanding from w0."""
    a = w0
    ga, za = hysteretic_residual(a, x0, z0, y, h, Ks, code, p)
    if ga == 0.0:
        return a, za
    step = abs(y - x0 - w0) + 1e-9 * (1.0 + abs(a))
    direction = -1.0 if ga > 0.0 else 1.0
    b = a + direction * step
    gb, zb = hysteretic_residual(b, x0, z0, y, h, Ks, code, p)
    it = 0
    while gb * ga > 0.0 and it < 200:
        a, ga = b, gb
        step *= 2.0
        b = a + direction * step
        gb, zb = hysteretic_residual(b, x0, z0, y, h, Ks, code, p)
        it += 1
    side = 0
    w, z = b, zb
    for _ in range(200):
        w = _bracket_root(ga, gb, a, b)
        g, z = hysteretic_residual(w, x0, z0, y, h, Ks, code, p)
        if g == 0.0 or abs(b - a) <= 1e-13 * (1.0 + abs(w)):
            break
        if g * gb < 0.0:
            a, ga = b, gb
            b, gb = w, g
            side = 0
        else:
            b, gb = w, g
            if side == 1:
                ga *= 0.5  # Illinois: halve the stale end
            side = 1
    return w, z


@njit(parallel=True, cache=True)
def series_population(code, x, xv, dt, Ks, P, substeps):
    """Law ``code`` (1-9) in series with a spring Ks [kN/mm] for each row of
    P (the law's parameters): returns the force F = Ks w [kN] and the law
    element's velocity xd [mm/s], (pop, n_t) each.

    x, xv (pop or 1, n_t): displacement [mm] and velocity [mm/s] of the
    spring-plus-law pair (the record's d, v, or the gap's output).  The
    spring starts unstretched and the law at rest.  Between samples x and xv
    are linear in time; each sample step is split into ``substeps``."""
    pop, n = P.shape[0], x.shape[1]
    F = np.zeros((pop, n))
    XD = np.zeros((pop, n))
    rows = np.zeros(pop, np.int64) if x.shape[0] == 1 else np.arange(pop)
    h = dt / substeps
    for i in prange(pop):
        r = rows[i]
        p = P[i]
        ks = Ks[i]
        w, xd, z, dw = 0.0, 0.0, 0.0, 0.0
        xl = x[r, 0]  # law displacement
        XD[i, 0] = xd
        for k in range(1, n):
            for j in range(substeps):
                f0, f1 = j / substeps, (j + 1) / substeps
                va = xv[r, k - 1] + (xv[r, k] - xv[r, k - 1]) * f0
                vb = xv[r, k - 1] + (xv[r, k] - xv[r, k - 1]) * f1
                yb = x[r, k - 1] + (x[r, k] - x[r, k - 1]) * f1
                if code <= 5:
                    w1, xd = series_viscous_step(w, xd, yb, 0.5 * (va + vb) * h, h, ks, code, p, w + dw)
                    dw = w1 - w
                    w = w1
                else:
                    w1, z = series_hysteretic_step(w, xl, z, yb, h, ks, code, p)
                    xd = (yb - w1 - xl) / h
                    xl = yb - w1
                    w = w1
            F[i, k] = ks * w
            XD[i, k] = xd
    return F, XD
