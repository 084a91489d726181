"""The nine laws' equations as scalar functions, each written once here.

The algebraic laws' force (1-5), the differential laws' constants from the
paper's parameters, their force and the one-step updates of their internal
variable z (6-9).  The population drivers (``algebraic.py``,
``differential.py``) apply them member by member, or lane by lane over a
SIMD block, and the effects' scalar kernels (a law behind a series spring)
call them directly; plain arithmetic, mostly without data-dependent branches
or C-library calls, which ports line by line to C (the FMU).  The input of
a step is the displacement travel u = integral of v dt over the step [mm],
with v linear between samples; the rate-independent laws (6, 8, 9) are
integrated exactly for such an input, law 7 (rate-dependent and stiff) by the
L-stable TR-BDF2 rule.

numba cannot vectorize calls to the C library's exp and log, so this module
carries its own (``vexp``, ``vlog``, ``log1p_ratio``, ``relax``): the textbook
range reductions and Taylor series, accurate to a few units in the last place.

numba's cache does not notice an edit here in the drivers that inline these
functions (``differential.py``, ``effects``): clear NUMBA_CACHE_DIR after one.
"""

from __future__ import annotations

import math

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

# fastmath without 'nnan'/'ninf' (comparisons stay exact) and without
# 'reassoc' (it would undo the exact range reductions below); inlined by numba
# itself, so that a lane loop is one straight body that LLVM can vectorize
FASTMATH = {"nsz", "arcp", "contract"}
kernel = njit(cache=True, fastmath=FASTMATH, error_model="numpy", inline="always")

LN2_HI = 6.93147180369123816490e-01  # ln 2 in two parts: n LN2_HI is exact for |n| < 2^20
LN2_LO = 1.90821492927058770002e-10
EXP_MAX = 709.0  # vexp saturates above EXP_MAX
EXP_MIN = -708.0  # and returns 0 below EXP_MIN (where e^x is no longer a normal number)
SQRT2 = math.sqrt(2.0)
# Taylor coefficients, highest degree first (Horner)
RELAX_SERIES = tuple((-1.0) ** j / math.factorial(j + 1) for j in range(11, -1, -1))  # |x| <= 1/4
ATANH_SERIES = tuple(1.0 / (2 * j + 1) for j in range(10, -1, -1))  # atanh(t)/t in t^2, |t| <= 0.172
# e^r for |r| <= ln2/2 to degree 12 (truncation < 2e-16), split in four
# interleaved Horner chains in r^4 (``poly4``): a quarter of the latency
EXP_SERIES4 = tuple(tuple(1.0 / math.factorial(j) for j in range(12, -1, -1) if j % 4 == k) for k in range(4))
LOG1P_COARSE = (-0.25, 1.0 / 3.0, -0.5, 1.0, 0.0)  # ln(1 + u) to u^4: error < 2.3e-3 for |u| <= 0.415
COARSE_LOG_ERROR = 0.01  # bound on |coarse_log(x) - ln x|, with margin


@intrinsic
def _float_bits(typingctx, x):
    """The IEEE-754 bits of a float64, as an int64 (C: memcpy)."""
    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.IntType(64))
    return types.int64(types.float64), codegen


@intrinsic
def _bits_float(typingctx, b):
    """The float64 with IEEE-754 bits b (C: memcpy)."""
    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.DoubleType())
    return types.float64(types.int64), codegen


@kernel
def horner(x, coeffs):
    """Polynomial with coefficients ``coeffs`` (highest degree first) at x."""
    p = 0.0
    for c in coeffs:
        p = p * x + c
    return p


@kernel
def poly4(x, parts):
    """Polynomial sum_k x^k P_k(x^4) (``parts`` = P_0..P_3, highest degree
    first): Horner's rule on four independent chains."""
    x2 = x * x
    x4 = x2 * x2
    p0, p1, p2, p3 = parts
    return (horner(x4, p0) + x * horner(x4, p1)) + x2 * (horner(x4, p2) + x * horner(x4, p3))


@kernel
def vexp(x):
    """e^x: x = n ln2 + r with |r| <= ln2/2, e^r by its Taylor series to degree
    12 (truncation < 2e-16), 2^n from the exponent bits.  Saturates at
    x = 709; 0 for x < -708."""
    xc = min(max(x, EXP_MIN), EXP_MAX)
    n = math.floor(xc * 1.4426950408889634 + 0.5)
    r = (xc - n * LN2_HI) - n * LN2_LO
    e = poly4(r, EXP_SERIES4) * _bits_float((np.int64(n) + 1023) << 52)
    return e if x >= EXP_MIN else 0.0


@kernel
def _log_kernel(t):
    """ln((1 + t)/(1 - t)) = 2 atanh(t) for |t| <= 3 - 2 sqrt(2) (series to t^21)."""
    return 2.0 * t * horner(t * t, ATANH_SERIES)


@kernel
def _log_reduce(x):
    """(e, m) with x = 2^e m, m in [1/sqrt2, sqrt2], for a normal x > 0."""
    b = _float_bits(x)
    e = ((b >> 52) & 0x7FF) - 1023
    m = _bits_float((b & 0x000FFFFFFFFFFFFF) | 0x3FF0000000000000)  # in [1, 2)
    big = m > SQRT2
    return (e + 1 if big else e), (0.5 * m if big else m)


@kernel
def vlog(x):
    """ln x for a normal x > 0: x = 2^e m, ln m = 2 atanh((m - 1)/(m + 1))."""
    e, m = _log_reduce(x)
    return e * LN2_HI + (_log_kernel((m - 1.0) / (m + 1.0)) + e * LN2_LO)


@kernel
def coarse_log(x):
    """ln x to within COARSE_LOG_ERROR, for a normal x > 0 (no division):
    x = 2^e m, ln m = ln(1 + u) by its series to u^4."""
    e, m = _log_reduce(x)
    return e * LN2_HI + horner(m - 1.0, LOG1P_COARSE)


@kernel
def log1p_ratio(y):
    """ln(1 + y)/y for y > -1 (1 at y = 0), without cancellation near 0:
    ln(1 + y) = 2 atanh(y/(2 + y)) where 1 + y is in [1/sqrt2, sqrt2]."""
    near = (y > SQRT2 / 2.0 - 1.0) & (y < SQRT2 - 1.0)
    yn = y if near else 0.0
    yf = 1.0 if near else y
    series = 2.0 / (2.0 + yn) * horner((yn / (2.0 + yn)) ** 2, ATANH_SERIES)
    direct = vlog(1.0 + yf) / yf
    return series if near else direct


@kernel
def relax(x):
    """phi(x) = (1 - e^-x)/x, phi(0) = 1 (the exact integrating factor);
    Taylor series for |x| < 1/4, the closed form elsewhere."""
    near = abs(x) < 0.25
    xf = 1.0 if near else x
    series = horner(x, RELAX_SERIES)
    direct = (1.0 - vexp(-xf)) / xf
    return series if near else direct


@kernel
def powsign(x, p):
    """sign(x) |x|^p (0 at x = 0), by the C library's pow: for scalar code."""
    return math.copysign(abs(x) ** p, x) if x != 0.0 else 0.0


@kernel
def split_travel(v0, v1, h):
    """Travel [mm] over a step of h [s] with v linear from v0 to v1 [mm/s],
    split where v changes sign: returns (u1, u2), each of one sign."""
    if v0 * v1 >= 0.0:
        return 0.5 * (v0 + v1) * h, 0.0
    tau = h * v0 / (v0 - v1)
    return 0.5 * v0 * tau, 0.5 * v1 * (h - tau)


@kernel
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
    s2 = max(s - s0, 0.0)
    w_lo = w1 + (A - k_lo * w1) * s2 * relax(k_lo * s2)
    return sgn * (w_un if unloading & (s < s0) else w_lo)


@kernel
def lugre_step(z, u, a):
    """LuGre internal state (paper eq. 15, exact): dz/dt = v - a |v| z, i.e.
    dz/du = sign(u) - a z over a travel u of one sign, so z relaxes to sign(u)/a."""
    sgn = 1.0 if u >= 0.0 else -1.0
    s = abs(u)
    return z + (sgn - a * z) * s * relax(a * s)


@kernel
def slip_step(z, u, k):
    """Lu friction element (paper eq. 13, exact): dz/dt = k v while |z| < 1 or
    z v < 0, else 0; an elastic-perfectly-plastic element with z held in [-1, 1]."""
    return min(max(z + k * u, -1.0), 1.0)


# --- the algebraic laws 1-5 ----------------------------------------------------

@kernel
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


@kernel
def power_term(c, sign_x, log_abs_x, e):
    """c sign(x)|x|^e from sign(x) and ln|x| (ln 0 = -1e300, so 0^e = 0 for
    e > 0 and sign 0 makes e = 0 vanish): the generalized viscous term
    (eq. 2) and law 5's spring (eq. 7)."""
    return c * sign_x * math.exp(e * log_abs_x)


@kernel
def algebraic_force(C, alpha, K1, K2, K, beta, d, sign_v, log_v, sign_d, log_d):
    """F = C sign(v)|v|^alpha + K1 d + K2 d^2 + K sign(d)|d|^beta [kN], d [mm],
    v [mm/s] given by their signs and logs (``power_term``)."""
    f = power_term(C, sign_v, log_v, alpha) + K1 * d + K2 * d * d
    return f + power_term(K, sign_d, log_d, beta) if K != 0.0 else f


@kernel
def sign_log(x):
    """(sign x, ln|x|), ln 0 = -1e300 (``power_term``)."""
    ax = abs(x)
    return (1.0 if x > 0.0 else (-1.0 if x < 0.0 else 0.0)), (math.log(ax) if ax > 0.0 else -1e300)


# --- the differential laws' constants and force from the paper's parameters -
# Used by the population drivers (differential.py) and by the effects' scalar
# kernels, so that each law's equations are written here only.

@kernel
def bouc_wen_constants(C, K, alpha, A, beta, gamma):
    """Bouc-Wen element + viscous (paper eq. 8): F = a d + b z + C v with
    a = alpha K, b = (1 - alpha) K [kN/mm]; returns (a, b, C, A, beta, gamma),
    the last three for ``bouc_wen_step``."""
    return alpha * K, (1.0 - alpha) * K, C, A, beta, gamma


@kernel
def law6_bouc_wen(C, K, alpha, beta):
    """Law 6 (section 2.6) as the Bouc-Wen element's parameters
    (C, K, alpha, A, beta, gamma): A = n = 1 and gamma = beta."""
    return C, K, alpha, 1.0, beta, beta


@kernel
def law8_constants(C, K, mu, N):
    """Law 8 (eqs. 12-13): F = mu N z + C v; returns (0, mu N, C, k), k = K/(mu N)
    [1/mm] the slip element's stiffness for ``slip_step`` (0 where mu N = 0)."""
    mu_N = mu * N
    return 0.0, mu_N, C, (K / mu_N if mu_N > 0.0 else 0.0)


@kernel
def law9_constants(C, alpha, beta):
    """Law 9 (eqs. 14-15, eps = K = F0 = 0): F = beta z + C v; returns
    (0, beta, C, alpha), alpha [1/mm] the LuGre rate for ``lugre_step``."""
    return 0.0, beta, C, alpha


@kernel
def linear_force(a, b, C, d, z, v):
    """F = a d + b z + C v [kN]: laws 6, 8 and 9 with their constants."""
    return a * d + b * z + C * v


@kernel
def maxwell_log_rate(C, alpha, K):
    """ln q of law 7, q = (K/C)^(1/alpha) (paper eq. 11), clipped to +-700
    (C = 0: a rigid dashpot, K = 0: no spring)."""
    ln_ratio = vlog(max(K, 1e-300)) - vlog(max(C, 1e-300))
    return min(max(ln_ratio / alpha, -700.0), 700.0)


# --- law 7: Lu visco-elastic spring deformation, TR-BDF2 ------------------
#
# dz/dt = v - q sign(z)|z|^p,  q = (K/C)^(1/alpha), p = beta/alpha (paper eq. 11).
# TR-BDF2 (Bank et al. 1985) with gamma = 2 - sqrt(2): a trapezoidal stage to
# t + gamma h, then a BDF2 stage to t + h; second order and L-stable, so the
# stiff members of a population (q h >> 1) neither ring nor blow up.  For
# this gamma both stages solve
#     x + c sign(x)|x|^p = r,   c = gamma h q / 2,
# which has one root, of the sign of r.  It is solved for lam = ln|x| by
# Newton's method on f(lam) = ln(e^lam + c e^(p lam)) - ln|r|, convex with a
# slope between min(1, p) and max(1, p); c enters only as ln c, so no
# stiffness overflows.  Each solve starts from a second-order Taylor
# prediction off the previous solve (lam as a function of ln|r|), clipped to
# the bracket of the root: one Newton step then usually meets the tolerance.

TRBDF2_GAMMA = 2.0 - math.sqrt(2.0)
LAM_MIN = -700.0  # ln|x| floor: |x| < 1e-304 mm counts as 0
R_MIN = 1e-300  # |r| floor [mm]
NEWTON_TOL = 1e-10  # a solve stops once the error estimate of ln|x| is below
NEWTON_MAXIT = 50


@kernel
def law7_constants(C, alpha, K, beta, h):
    """Constants of the TR-BDF2 solves over a step h [s]: (ln c, p, 1/p, ln K,
    beta), c = gamma h q/2, p = beta/alpha."""
    p = beta / alpha
    return (math.log(0.5 * TRBDF2_GAMMA * h) + maxwell_log_rate(C, alpha, K), p, 1.0 / p,
            vlog(max(K, 1e-300)), beta)


@kernel
def maxwell_tr_rhs(z, c_phi, v0, v1, h):
    """Right side r of the trapezoidal stage: z + (gamma h/2)(v0 + v_gamma) - c phi(z),
    v_gamma = v0 + gamma (v1 - v0) (v linear over the step h [s] from v0 to v1
    [mm/s]); c phi(z) is carried from the previous solve (c phi(x) = r - x)."""
    g = TRBDF2_GAMMA
    return z + 0.5 * g * h * (2.0 * v0 + g * (v1 - v0)) - c_phi


@kernel
def maxwell_bdf2_rhs(z_gamma, z, v1, h):
    """Right side r of the BDF2 stage: (z_gamma - (1-gamma)^2 z)/(gamma (2-gamma))
    + (gamma h/2) v1, v1 the velocity at the end of the step [mm/s]."""
    g = TRBDF2_GAMMA
    return (z_gamma - (1.0 - g) ** 2 * z) / (g * (2.0 - g)) + 0.5 * g * h * v1


@kernel
def maxwell_start(r, R_prev, lam, lam1, lam2, ln_r_prev, ln_c, inv_p):
    """Start of the solve of x + c sign(x)|x|^p = r: lam + lam1 dl + lam2 dl^2,
    dl = ln(R/R_prev) the change of R = |r| since the previous solve (lam,
    lam1, lam2: its root and the derivatives of lam(ln R) there), clipped to
    the bracket [min(ln(R/2), (ln(R/2) - ln c)/p), min(ln R, (ln R - ln c)/p)]
    of the root, widened by COARSE_LOG_ERROR.  dl = 2 atanh(t),
    t = (R - R_prev)/(R + R_prev), by its series to t^7 where |t| < 0.1 (error
    < 3e-10), else the difference of coarse logs (the bracket then decides).
    Returns (lam0, coarse ln R, R); R is floored at R_MIN."""
    R = max(abs(r), R_MIN)
    ln_r = coarse_log(R)
    t = (R - R_prev) / (R + R_prev)
    near = abs(t) < 0.1
    tn = t if near else 0.0
    dl = 2.0 * tn * horner(tn * tn, (1.0 / 7.0, 0.2, 1.0 / 3.0, 1.0)) if near else ln_r - ln_r_prev
    upper = min(ln_r, (ln_r - ln_c) * inv_p) + COARSE_LOG_ERROR
    lower = min(ln_r - LN2_HI, (ln_r - LN2_HI - ln_c) * inv_p) - COARSE_LOG_ERROR
    return max(min(max(lam + dl * (lam1 + lam2 * dl), lower), upper), LAM_MIN), ln_r, R


@kernel
def maxwell_newton(lam, R, ln_c, p):
    """One Newton step on f(lam) = ln(S/R), S = e1 + e2, e1 = e^lam,
    e2 = c e^(p lam), f' = (e1 + p e2)/S, with ln(S/R) replaced by
    2 (S - R)/(S + R) (same root and slope there, and a shorter step, so the
    iterates stay on the convex side).  The error left after a step d is
    about (f''/2f') d^2 + |d|^3/12 (the second term from the replacement),
    f'' = e1 e2 (p - 1)^2/S^2.  Returns (new lam, e1, e2, 1/(e1 + p e2),
    converged): whether that error is below NEWTON_TOL (or the step was
    stopped at LAM_MIN)."""
    e1 = vexp(lam)
    e2 = vexp(ln_c + p * lam)
    s = e1 + e2
    g1 = e1 + p * e2
    inv = 1.0 / ((s + R) * g1)
    new = max(lam - 2.0 * s * (s - R) * inv, LAM_MIN)
    d = abs(new - lam)
    converged = e1 * e2 * (p - 1.0) ** 2 * d * d <= (2.0 * NEWTON_TOL - d * d * d / 6.0) * s * g1
    return new, e1, e2, (s + R) * inv, converged


@kernel
def maxwell_end(r, e1, e2, inv_g1, dlam, p):
    """Root x = sign(r) e^lam from the last Newton evaluation (e1 = e^(lam - dlam),
    e2, inv_g1 = 1/(e1 + p e2)) and the step dlam taken from it (e^dlam to
    second order); and the derivatives of lam(ln R) there, lam1 = 1/f' and
    lam2 = -f''/(2 f'^3), f'' = e1 e2 (p - 1)^2/S^2.  Returns (x, lam1, lam2)."""
    s = e1 + e2
    lam1 = s * inv_g1
    lam2 = -0.5 * e1 * e2 * (p - 1.0) ** 2 * s * inv_g1 * inv_g1 * inv_g1
    return math.copysign(e1 * (1.0 + dlam * (1.0 + 0.5 * dlam)), r), lam1, lam2


@kernel
def maxwell_solve(r, ln_c, p):
    """Root x of x + c sign(x)|x|^p = r without a previous solve to start from
    (scalar code): Newton (``maxwell_newton``) from the upper end of the
    bracket, where the iterates approach the root from one side."""
    R = max(abs(r), R_MIN)
    ln_r = vlog(R)
    lam = max(min(ln_r, (ln_r - ln_c) / p), LAM_MIN)
    e1, e2, inv_g1, dlam = 0.0, 0.0, 1.0, 0.0
    for _ in range(NEWTON_MAXIT):
        new, e1, e2, inv_g1, done = maxwell_newton(lam, R, ln_c, p)
        dlam, lam = new - lam, new
        if done:
            break
    return maxwell_end(r, e1, e2, inv_g1, dlam, p)[0] if r != 0.0 else 0.0


@kernel
def maxwell_force(sign_z, lam, ln_K, beta):
    """Spring force K sign(z)|z|^beta [kN] (paper eq. 10), lam = ln|z|;
    sign_z is any number of the sign of z (0 for z = 0)."""
    f = math.copysign(vexp(ln_K + beta * lam), sign_z)
    return f if sign_z != 0.0 else 0.0
