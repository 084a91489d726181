"""Fast scalar math for the compiled kernels: exp, log and friends that
numba can vectorize (it cannot vectorize calls to the C library's exp and
log), and the ``scalar`` decorator every scalar step function uses.

A step function avoids Python's ``max``/``min`` (``fmax``/``fmin``) and
``x ** 2`` (``x * x``) too: numba compiles those as calls to functions of
their own, which LLVM inlines only after it has tried to vectorize a
kernel's lane loops, so one such call leaves a loop scalar (law 7's
drivers were 3-4x slower, ``differential.py``).

The textbook range reductions and Taylor series, accurate to a few units in
the last place; plain arithmetic and bit operations that port to C (the
FMU's C code uses the C library's exp and log instead).
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
scalar = njit(cache=True, fastmath=FASTMATH, error_model="numpy", inline="always")

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


@scalar
def fmax(a, b):
    """max(a, b) as Python's and numba's (b if b > a, else a), inlined."""
    return b if b > a else a


@scalar
def fmin(a, b):
    """min(a, b) as Python's and numba's (b if b < a, else a), inlined."""
    return b if b < a else a


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


@scalar
def horner(x, coeffs):
    """Polynomial with coefficients ``coeffs`` (highest degree first) at x."""
    p = 0.0
    for c in coeffs:
        p = p * x + c
    return p


@scalar
def poly4(x, parts):
    """Polynomial sum_k x^k P_k(x^4) (``parts`` = P_0..P_3, highest degree
    first): Horner's rule on four independent chains."""
    x2 = x * x
    x4 = x2 * x2
    p0, p1, p2, p3 = parts
    return (horner(x4, p0) + x * horner(x4, p1)) + x2 * (horner(x4, p2) + x * horner(x4, p3))


@scalar
def vexp(x):
    """e^x: x = n ln2 + r with |r| <= ln2/2, e^r by its Taylor series to degree
    12 (truncation < 2e-16), 2^n from the exponent bits.  Saturates at
    x = 709; 0 for x < -708."""
    xc = fmin(fmax(x, EXP_MIN), EXP_MAX)
    n = math.floor(xc * 1.4426950408889634 + 0.5)
    r = (xc - n * LN2_HI) - n * LN2_LO
    e = poly4(r, EXP_SERIES4) * _bits_float((np.int64(n) + 1023) << 52)
    return e if x >= EXP_MIN else 0.0


@scalar
def _log_kernel(t):
    """ln((1 + t)/(1 - t)) = 2 atanh(t) for |t| <= 3 - 2 sqrt(2) (series to t^21)."""
    return 2.0 * t * horner(t * t, ATANH_SERIES)


@scalar
def _log_reduce(x):
    """(e, m) with x = 2^e m, m in [1/sqrt2, sqrt2], for a normal x > 0."""
    b = _float_bits(x)
    e = ((b >> 52) & 0x7FF) - 1023
    m = _bits_float((b & 0x000FFFFFFFFFFFFF) | 0x3FF0000000000000)  # in [1, 2)
    big = m > SQRT2
    return (e + 1 if big else e), (0.5 * m if big else m)


@scalar
def vlog(x):
    """ln x for a normal x > 0: x = 2^e m, ln m = 2 atanh((m - 1)/(m + 1))."""
    e, m = _log_reduce(x)
    return e * LN2_HI + (_log_kernel((m - 1.0) / (m + 1.0)) + e * LN2_LO)


@scalar
def coarse_log(x):
    """ln x to within COARSE_LOG_ERROR, for a normal x > 0 (no division):
    x = 2^e m, ln m = ln(1 + u) by its series to u^4."""
    e, m = _log_reduce(x)
    return e * LN2_HI + horner(m - 1.0, LOG1P_COARSE)


@scalar
def log1p_ratio(y):
    """ln(1 + y)/y for y > -1 (1 at y = 0), without cancellation near 0:
    ln(1 + y) = 2 atanh(y/(2 + y)) where 1 + y is in [1/sqrt2, sqrt2]."""
    near = (y > SQRT2 / 2.0 - 1.0) & (y < SQRT2 - 1.0)
    yn = y if near else 0.0
    yf = 1.0 if near else y
    t = yn / (2.0 + yn)
    series = 2.0 / (2.0 + yn) * horner(t * t, ATANH_SERIES)
    direct = vlog(1.0 + yf) / yf
    return series if near else direct


@scalar
def relax(x):
    """phi(x) = (1 - e^-x)/x, phi(0) = 1 (the exact integrating factor);
    Taylor series for |x| < 1/4, the closed form elsewhere."""
    near = abs(x) < 0.25
    xf = 1.0 if near else x
    series = horner(x, RELAX_SERIES)
    direct = (1.0 - vexp(-xf)) / xf
    return series if near else direct


@scalar
def powsign(x, p):
    """sign(x) |x|^p (0 at x = 0), by the C library's pow: for scalar code."""
    return math.copysign(abs(x) ** p, x) if x != 0.0 else 0.0


