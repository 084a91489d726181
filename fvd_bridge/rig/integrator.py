"""Numerical core of the rig: the internal element and the Maxwell integrator.

Internal element (orifice with asymmetry and heating, plus seal friction):
  F_int(v_o) = hf C A(v_o) sign(v_o)|v_o|^alpha + Ff tanh(v_o / v_f),
  A = 1 + r when v_o > 0 (tension), 1 - r when v_o < 0;  hf = exp(-theta E).
It increases strictly with v_o, so it has a unique inverse.

Series spring (Maxwell): S = Ks (y - x_o) = F_int(v_o) + Kp x_o + F0
(the accumulator behind the spring, Kp = F0 = 0 beside it), v_o = dx_o/dt,
x_o = y - S / Ks, so
  dS/dt = Ks (v_y(t) - v_o(S, y, E)),   dE/dt = F_o(v_o) v_o 1e-6  [MJ/s],
F_o the orifice part of F_int (kN mm/s = J/s). The S equation is stiff near
the force peaks (rate Ks dv_o/dS) and not smooth at S = 0 (v_o ~ S^(1/alpha)).

Integrator: Alexander's 3-stage SDIRK of order 3 (L-stable, stiffly accurate;
Hairer & Wanner, Solving ODEs II, table IV.6.5), on a node grid that the
caller aligns with every discontinuity of v_y (contact events of the gap).
Each stage is one scalar equation (S = S_base + h gamma Ks (v_y - u),
k = 1 + Kp / Ks)
  F_int(u) + k h gamma Ks u = k (S_base + h gamma Ks v_y(t_stage)) - Kp y(t_stage) - F0,
whose left side increases in u: a bracketed Newton iteration always converges.
E enters through hf, updated by fixed-point iteration (coupling ~ theta dE).

The device's constants reach the kernels as one float64 array
(``device_constants``), read by the index names below.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

GAMMA = 0.43586652150845899941601945
C2 = 0.5 * (1.0 + GAMMA)
A21 = C2 - GAMMA
B1 = -(6.0 * GAMMA * GAMMA - 16.0 * GAMMA + 1.0) / 4.0
B2 = (6.0 * GAMMA * GAMMA - 20.0 * GAMMA + 5.0) / 4.0
#: stage abscissae c_i of the SDIRK scheme (fractions of a step)
STAGE_C = np.array([GAMMA, C2, 1.0])

#: the device's constants (``device_constants``): C [kN/(mm/s)^alpha],
#: alpha [-], asymmetry r [-], heating theta [1/MJ], friction Ff [kN] and
#: its smoothing velocity v_f [mm/s], the series spring Ks [kN/mm], and
#: behind it the accumulator Kp [kN/mm] and preload F0 [kN]
DAMPING, ALPHA, ASYMMETRY, HEATING, FRICTION, V_FRICTION, KS, KP, PRELOAD = range(9)


def device_constants(*, C, alpha, r, theta, Ff, vf, Ks, Kp, F0) -> np.ndarray:
    """The device's constants as ``integrate_maxwell`` reads them (units above)."""
    c = np.empty(PRELOAD + 1)
    c[DAMPING], c[ALPHA], c[ASYMMETRY], c[HEATING], c[FRICTION] = C, alpha, r, theta, Ff
    c[V_FRICTION], c[KS], c[KP], c[PRELOAD] = vf, Ks, Kp, F0
    return c


@njit(cache=True)
def solve_internal(rhs, K, hf, C, alpha, r, Ff, vf, u_guess):
    """u [mm/s] with hf C A(u) sign(u)|u|^alpha + Ff tanh(u/vf) + K u = rhs [kN].

    The left side increases strictly from 0 at u = 0, so u has the sign of
    rhs. Safeguarded Newton on x = |u|^alpha (alpha <= 1, where the left side
    is smooth in x) or x = |u| (alpha > 1), inside a shrinking bracket.
    """
    if rhs == 0.0:
        return 0.0
    sgn = 1.0 if rhs > 0.0 else -1.0
    b = abs(rhs)
    ca = hf * C * (1.0 + sgn * r)
    inv = 1.0 / alpha
    qmode = alpha <= 1.0
    uhi = (b / ca) ** inv
    if K > 0.0 and b / K < uhi:
        uhi = b / K
    if Ff > 0.0 and b < Ff:
        uf = vf * math.atanh(b / Ff)
        if uf < uhi:
            uhi = uf
    lo = 0.0
    hi = uhi ** alpha if qmode else uhi
    ug = u_guess * sgn
    if ug > 0.0 and ug < uhi:
        x = ug ** alpha if qmode else ug
    else:
        x = 0.5 * hi
    for _ in range(200):
        if qmode:
            u = x ** inv
            q = x
            dq = 1.0
            du = inv * x ** (inv - 1.0) if x > 0.0 else (1.0 if alpha == 1.0 else 0.0)
        else:
            u = x
            q = x ** alpha
            dq = alpha * x ** (alpha - 1.0) if x > 0.0 else 0.0
            du = 1.0
        th = math.tanh(u / vf) if Ff > 0.0 else 0.0
        R = ca * q + Ff * th + K * u - b
        if R > 0.0:
            hi = x
        elif R < 0.0:
            lo = x
        else:
            return sgn * u
        if abs(R) <= 1e-15 * b or hi - lo <= 4e-16 * hi:
            return sgn * u
        dR = ca * dq + (Ff / vf * (1.0 - th * th) + K) * du
        xn = x - R / dR if dR > 0.0 else -1.0
        if not (lo < xn < hi):
            xn = 0.5 * (lo + hi)
        x = xn
    return sgn * (x ** inv if qmode else x)


@njit(cache=True)
def _stage(base_S, base_E, vy, y, K, hg, e_guess, u_guess, c):
    """One implicit stage (K = hg Ks, hg = h gamma [s], c the device's
    constants): returns (u, S, E, kS, kE)."""
    C, alpha, r, theta, Ff, vf = c[DAMPING], c[ALPHA], c[ASYMMETRY], c[HEATING], c[FRICTION], c[V_FRICTION]
    Ks, Kp, F0 = c[KS], c[KP], c[PRELOAD]
    rhs = base_S + K * vy
    k = 1.0 + Kp / Ks
    e = e_guess
    u = u_guess
    p = 0.0
    for _ in range(30):
        hf = math.exp(-theta * e) if theta > 0.0 else 1.0
        u = solve_internal(k * rhs - Kp * y - F0, k * K, hf, C, alpha, r, Ff, vf, u)
        au = abs(u)
        asym = 1.0 + r if u > 0.0 else 1.0 - r
        p = hf * C * asym * au ** alpha * au * 1e-6
        en = base_E + hg * p
        converged = theta == 0.0 or abs(en - e) <= 1e-15 * (1.0 + abs(en))
        e = en
        if converged:
            break
    return u, rhs - K * u, e, Ks * (vy - u), p


@njit(cache=True)
def integrate_maxwell(H, VY, Y, c, S0, E0):
    """SDIRK3 over the nodes: H[n] step [s], VY[n, i] and Y[n, i] the damper
    body's velocity v_y [mm/s] and displacement y [mm] at the stage times
    t_n + c_i H[n]; c the device's constants (``device_constants``); S0 [kN]
    the spring's force at the start (its stretch S0 / Ks), E0 [MJ] the
    energy. Returns S [kN], E [MJ] and v_o [mm/s] at every node (M + 1
    values)."""
    Ks = c[KS]
    M = H.size
    S = np.empty(M + 1)
    E = np.empty(M + 1)
    U = np.empty(M + 1)
    S[0] = S0
    E[0] = E0
    U[0] = 0.0  # at rest
    u = U[0]
    kE_last = 0.0
    for n in range(M):
        h = H[n]
        hg = h * GAMMA
        K = hg * Ks
        s0 = S[n]
        e0 = E[n]
        u1, S1, E1, k1, q1 = _stage(s0, e0, VY[n, 0], Y[n, 0], K, hg, e0 + hg * kE_last, u, c)
        bS = s0 + h * A21 * k1
        bE = e0 + h * A21 * q1
        u2, S2, E2, k2, q2 = _stage(bS, bE, VY[n, 1], Y[n, 1], K, hg, bE + hg * q1, u1, c)
        bS = s0 + h * (B1 * k1 + B2 * k2)
        bE = e0 + h * (B1 * q1 + B2 * q2)
        u3, S3, E3, k3, q3 = _stage(bS, bE, VY[n, 2], Y[n, 2], K, hg, bE + hg * q2, u2, c)
        S[n + 1] = S3
        E[n + 1] = E3
        U[n + 1] = u3
        u = u3
        kE_last = q3
    return S, E, U
