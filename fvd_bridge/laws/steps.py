"""The nine laws' equations as scalar functions, each written once here.

The algebraic laws' force (1-5), the differential laws' constants from the
paper's parameters, their force and the one-step updates of their internal
variable z (6-9).  The population drivers (``algebraic.py``,
``differential.py``) apply them member by member, or lane by lane over a
SIMD block, and the effects' series kernel (a law behind a series spring)
calls them directly; plain arithmetic, mostly without data-dependent
branches or C-library calls, which ports line by line to C (the FMU).  The
input of a step is the displacement travel u = integral of v dt over the
step [mm], with v linear between samples; the rate-independent laws (6, 8,
9) are integrated exactly for such an input, law 7 (rate-dependent and
stiff) by the L-stable TR-BDF2 rule (``trbdf2.py``).  The fast exp and log
are in ``fastmath.py``.

numba's cache does not notice an edit here in the drivers that inline these
functions (``differential.py``, ``effects``): clear NUMBA_CACHE_DIR after one.
"""

from __future__ import annotations

import math

from .fastmath import fmax, fmin, log1p_ratio, relax, scalar, vexp, vlog

@scalar
def split_travel(v0, v1, h):
    """Travel [mm] over a step of h [s] with v linear from v0 to v1 [mm/s],
    split where v changes sign: returns (u1, u2), each of one sign."""
    if v0 * v1 >= 0.0:
        return 0.5 * (v0 + v1) * h, 0.0
    tau = h * v0 / (v0 - v1)
    return 0.5 * v0 * tau, 0.5 * v1 * (h - tau)


@scalar
def bouc_wen_step(z, u, A, beta, gamma):
    """Bouc-Wen with n = 1 over a travel u [mm] of one sign (exact); A > 0.

    dz/dt = A v - beta |v| z - gamma v |z|  (Bouc-Wen, n = 1; the standard form
    of the paper's garbled eq. 9).  With w = sign(u) z and s = |u|:
    dw/ds = A - k w, k = beta - gamma while w < 0 (unloading, until w = 0
    after the travel s0 = ln(1 - k w/A)/k) and k = beta + gamma while w >= 0
    (loading); over a travel s, w -> w + (A - k w) s phi(k s).
    """
    sgn = 1.0 if u >= 0.0 else -1.0
    w, s = sgn * z, abs(u)
    k_un, k_lo = beta - gamma, beta + gamma
    unloading = w < 0.0
    y = -k_un * w / A
    s0 = -w / A * log1p_ratio(y)
    s0 = 0.0 if not unloading else (s0 if y > -1.0 else 1e300)  # 1e300: w = 0 is never reached
    w_un = w + (A - k_un * w) * s * relax(k_un * s)
    w1 = 0.0 if unloading else w
    s2 = fmax(s - s0, 0.0)
    w_lo = w1 + (A - k_lo * w1) * s2 * relax(k_lo * s2)
    return sgn * (w_un if unloading & (s < s0) else w_lo)


@scalar
def lugre_step(z, u, a):
    """LuGre internal state (paper eq. 15, exact): dz/dt = v - a |v| z, i.e.
    dz/du = sign(u) - a z over a travel u of one sign, so z relaxes to sign(u)/a."""
    sgn = 1.0 if u >= 0.0 else -1.0
    s = abs(u)
    return z + (sgn - a * z) * s * relax(a * s)


@scalar
def slip_step(z, u, k):
    """Lu friction element (paper eq. 13, exact): dz/dt = k v while |z| < 1 or
    z v < 0, else 0; an elastic-perfectly-plastic element with z held in [-1, 1]."""
    return fmin(fmax(z + k * u, -1.0), 1.0)


# --- the algebraic laws 1-5 ----------------------------------------------------

@scalar
def algebraic_form(code, p):
    """Law ``code`` (1-5) with parameters p as the general algebraic law's
    (C, alpha, K1, K2, K, beta) (``algebraic_force``; paper eqs. 1, 2, 5, 6, 7)."""
    if code == 1:
        return p[0], 1.0, 0.0, 0.0, 0.0, 1.0
    if code == 2:
        return p[0], p[1], 0.0, 0.0, 0.0, 1.0
    if code == 3:
        return p[0], p[1], p[2], 0.0, 0.0, 1.0
    if code == 4:
        return p[0], p[1], p[2], p[3], 0.0, 1.0
    return p[0], p[1], 0.0, 0.0, p[2], p[3]


@scalar
def power_term(c, sign_x, log_abs_x, e):
    """c sign(x)|x|^e from sign(x) and ln|x| (ln 0 = -1e300, so 0^e = 0 for
    e > 0 and sign 0 makes e = 0 vanish): the generalized viscous term
    (eq. 2) and law 5's spring (eq. 7)."""
    return c * sign_x * math.exp(e * log_abs_x)


@scalar
def algebraic_force(C, alpha, K1, K2, K, beta, d, sign_v, log_v, sign_d, log_d):
    """F = C sign(v)|v|^alpha + K1 d + K2 d^2 + K sign(d)|d|^beta [kN], d [mm],
    v [mm/s] given by their signs and logs (``power_term``)."""
    f = power_term(C, sign_v, log_v, alpha) + K1 * d + K2 * d * d
    return f + power_term(K, sign_d, log_d, beta) if K != 0.0 else f


@scalar
def sign_log(x):
    """(sign x, ln|x|), ln 0 = -1e300 (``power_term``)."""
    ax = abs(x)
    return (1.0 if x > 0.0 else (-1.0 if x < 0.0 else 0.0)), (math.log(ax) if ax > 0.0 else -1e300)


# --- the differential laws' constants and force from the paper's parameters -
# Used by the population drivers (differential.py) and by the effects' scalar
# kernels, so that each law's equations are written here only.

@scalar
def bouc_wen_constants(C, K, alpha, A, beta, gamma):
    """Bouc-Wen element + viscous (paper eq. 8): F = a d + b z + C v with
    a = alpha K, b = (1 - alpha) K [kN/mm]; returns (a, b, C, A, beta, gamma),
    the last three for ``bouc_wen_step``."""
    return alpha * K, (1.0 - alpha) * K, C, A, beta, gamma


@scalar
def law6_bouc_wen(C, K, alpha, beta):
    """Law 6 (section 2.6) as the Bouc-Wen element's parameters
    (C, K, alpha, A, beta, gamma): A = n = 1 and gamma = beta."""
    return C, K, alpha, 1.0, beta, beta


@scalar
def law8_constants(C, K, mu, N):
    """Law 8 (eqs. 12-13): F = mu N z + C v; returns (0, mu N, C, k), k = K/(mu N)
    [1/mm] the slip element's stiffness for ``slip_step`` (0 where mu N = 0)."""
    mu_N = mu * N
    return 0.0, mu_N, C, (K / mu_N if mu_N > 0.0 else 0.0)


@scalar
def law9_constants(C, alpha, beta):
    """Law 9 (eqs. 14-15, eps = K = F0 = 0): F = beta z + C v; returns
    (0, beta, C, alpha), alpha [1/mm] the LuGre rate for ``lugre_step``."""
    return 0.0, beta, C, alpha


@scalar
def linear_force(a, b, C, d, z, v):
    """F = a d + b z + C v [kN]: laws 6, 8 and 9 with their constants."""
    return a * d + b * z + C * v


@scalar
def maxwell_log_rate(C, alpha, K):
    """ln q of law 7, q = (K/C)^(1/alpha) (paper eq. 11), clipped to +-700
    (C = 0: a rigid dashpot, K = 0: no spring)."""
    ln_ratio = vlog(fmax(K, 1e-300)) - vlog(fmax(C, 1e-300))
    return fmin(fmax(ln_ratio / alpha, -700.0), 700.0)


@scalar
def maxwell_force(sign_z, lam, ln_K, beta):
    """Spring force K sign(z)|z|^beta [kN] (paper eq. 10), lam = ln|z|;
    sign_z is any number of the sign of z (0 for z = 0)."""
    f = math.copysign(vexp(ln_K + beta * lam), sign_z)
    return f if sign_z != 0.0 else 0.0
