"""Scalar one-step updates of the internal variable z of the differential laws.

Each is written once here and used by the population drivers; they are plain
arithmetic so they port line by line to C (the FMU).  The input is the
displacement travel u = integral of v dt over the step [mm], with v linear
between samples; the rate-independent laws (6, 8, 9) are integrated exactly
for such an input, law 7 by the implicit trapezoidal rule.
"""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True)
def relax(x):
    """phi(x) = (1 - exp(-x)) / x, with phi(0) = 1 (exact integrating factor)."""
    if abs(x) < 1e-8:
        return 1.0 - 0.5 * x
    return -math.expm1(-x) / x


@njit(cache=True)
def split_travel(v0, v1, h):
    """Travel [mm] over a step of h [s] with v linear from v0 to v1 [mm/s],
    split where v changes sign: returns (u1, u2), each of one sign."""
    if v0 * v1 >= 0.0:
        return 0.5 * (v0 + v1) * h, 0.0
    tau = h * v0 / (v0 - v1)
    return 0.5 * v0 * tau, 0.5 * v1 * (h - tau)


@njit(cache=True)
def bouc_wen_step(z, u, A, beta, gamma):
    """Bouc-Wen with n = 1 over a travel u of one sign (exact).

    dz/dt = A v - beta |v| z - gamma v |z|  (Bouc-Wen, n = 1; the standard form
    of the paper's garbled eq. 9).  With w = sign(u) z and s = |u|:
    dw/ds = A - k w, k = beta + gamma while w >= 0 (loading) and
    k = beta - gamma while w < 0 (unloading).
    """
    if u == 0.0:
        return z
    sgn = 1.0 if u > 0.0 else -1.0
    w, s = sgn * z, abs(u)
    if w < 0.0:
        k = beta - gamma
        rate0 = A - k * w
        # travel to reach w = 0, if it is reached
        if k == 0.0:
            s0 = -w / A if A > 0.0 else 1e300
        elif rate0 > 0.0 and -k * w / A > -1.0:
            s0 = math.log1p(-k * w / A) / k
        else:
            s0 = 1e300
        if s0 >= s:
            return sgn * (w + rate0 * s * relax(k * s))
        w, s = 0.0, s - s0
    k = beta + gamma
    return sgn * (w + (A - k * w) * s * relax(k * s))


@njit(cache=True)
def lugre_step(z, u, a):
    """LuGre internal state (paper eq. 15, exact): dz/dt = v - a |v| z,
    i.e. dz/du = 1 - a sign(u) z, so z relaxes to sign(u)/a."""
    if u == 0.0:
        return z
    sgn = 1.0 if u > 0.0 else -1.0
    s = abs(u)
    return z + (sgn - a * z) * s * relax(a * s)


@njit(cache=True)
def slip_step(z, u, k):
    """Lu friction element (paper eq. 13, exact): dz/dt = k v while |z| < 1 or
    z v < 0, else 0; an elastic-perfectly-plastic element with z held in [-1, 1]."""
    z = z + k * u
    return 1.0 if z > 1.0 else (-1.0 if z < -1.0 else z)


@njit(cache=True)
def powsign(x, p):
    """sign(x) |x|^p."""
    if x == 0.0:
        return 0.0
    return math.copysign(abs(x) ** p, x)


@njit(cache=True)
def maxwell_step(z, u, h, q, p):
    """Lu visco-elastic spring deformation (paper eq. 11) over a step h [s].

    dz/dt = v - q sign(z)|z|^p with q = (K/C)^(1/alpha), p = beta/alpha.
    Implicit trapezoidal rule: x + c phi(x) = z + u - c phi(z), c = h q / 2,
    phi(x) = sign(x)|x|^p; the left side increases in x, so the root is
    unique and lies between 0 and the right side r (safeguarded Newton).
    """
    c = 0.5 * h * q
    r = z + u - c * powsign(z, p)
    if r == 0.0:
        return 0.0
    lo, hi = (0.0, r) if r > 0.0 else (r, 0.0)
    # start from the explicit Euler estimate, kept inside the bracket
    x = z + u - 2.0 * c * powsign(z, p)
    if not (lo < x < hi):
        x = 0.5 * (lo + hi)
    for _ in range(60):
        ax = abs(x)
        f = x + c * powsign(x, p) - r
        if f > 0.0:
            hi = x
        else:
            lo = x
        dfdx = 1.0 + (c * p * ax ** (p - 1.0) if ax > 0.0 else 0.0)
        xn = x - f / dfdx
        if not (lo < xn < hi):
            xn = 0.5 * (lo + hi)
        if abs(xn - x) <= 1e-12 * (1.0 + abs(xn)):
            return xn
        x = xn
    return x
