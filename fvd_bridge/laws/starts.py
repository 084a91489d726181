"""Data-driven starts: a law's parameters estimated from a record's samples in closed form.

A start is the local search's first point (``fit.local``), not a result: it
only has to lie in the optimum's basin.  Each estimate reads one feature of
a sinusoidal loop: d [mm], v [mm/s], F [kN] of all tests together.

- the viscous term C sign(v)|v|^alpha: a log-log regression of |F| on |v|
  over the fastest half of the samples, where a spring or friction term
  is smallest against it;
- a parallel spring K1: the slope of F against d over the slowest tenth,
  where the viscous term vanishes;
- a friction or bristle force Ff, read twice: the median |F| over the
  slowest tenth (at a reversal the hysteretic variable is still
  saturated), and the intercept of |F| against |v| at speed; the
  saturation travel a tenth of the stroke.

A law returns a list of candidate parameter sets (one, or for the
hysteretic laws one per reading of Ff); the local search solves from each.
"""

from __future__ import annotations

import numpy as np

#: the hysteretic laws' saturation travel, as a share of the stroke amplitude
SATURATION_SHARE = 0.1


def _slow(v: np.ndarray) -> np.ndarray:
    return np.abs(v) <= np.quantile(np.abs(v), 0.1)


def _fast(v: np.ndarray) -> np.ndarray:
    return np.abs(v) >= np.median(np.abs(v))


def _line(x: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """(slope, intercept) of the least-squares line y = slope x + intercept
    (closed form; np.polyfit's SVD costs 4x more at these sizes)."""
    dx = x - x.mean()
    slope = float(np.dot(dx, y - y.mean()) / max(np.dot(dx, dx), 1e-300))
    return slope, float(y.mean() - slope * x.mean())


def power_term(v: np.ndarray, F: np.ndarray) -> tuple[float, float]:
    """(C, alpha) of F = C sign(v)|v|^alpha from the fastest half of the samples."""
    fast = _fast(v) & (np.abs(v) > 0)
    if fast.sum() < 2:
        return float(np.mean(np.abs(F))), 1.0
    alpha = _line(np.log(np.abs(v[fast])), np.log(np.maximum(np.abs(F[fast]), 1e-9)))[0]
    alpha = float(np.clip(alpha, 0.05, 1.0))
    return float(np.median(np.abs(F[fast]) / np.abs(v[fast]) ** alpha)), alpha


def spring(d: np.ndarray, v: np.ndarray, F: np.ndarray) -> float:
    """K1 [kN/mm] >= 0: the slope of F against d where the velocity is slowest."""
    slow = _slow(v)
    if np.ptp(d[slow]) <= 0:
        return 0.0
    return max(_line(d[slow], F[slow])[0], 0.0)


def speed_line(v: np.ndarray, F: np.ndarray) -> tuple[float, float]:
    """(a [kN], b [kN/(mm/s)]) of the line |F| = a + b |v| over the fastest half of the samples."""
    fast = _fast(v)
    b, a = _line(np.abs(v[fast]), np.abs(F[fast]))
    return a, b


def hysteretic(d: np.ndarray, v: np.ndarray, F: np.ndarray) -> list[tuple[float, float, float]]:
    """Two readings of (Ff [kN], y [mm], C [kN/(mm/s)]): the friction force,
    its saturation travel and the linear viscous term.  At the reversals:
    Ff the median |F| there, C from the remainder at speed; at speed: the
    line |F| = Ff + C |v| over the fastest half.  The first misses the
    friction of a device whose connection has play (the force drops while
    the play closes at each reversal), the second a concave viscous term's
    share; the local search solves from both."""
    y = SATURATION_SHARE * max(float(np.ptp(d)) / 2.0, 1e-9)
    fast = _fast(v)
    Ff = float(np.median(np.abs(F[_slow(v)])))
    rest = F[fast] - Ff * np.sign(v[fast])
    C = max(float(np.sum(rest * v[fast]) / max(np.sum(v[fast] ** 2), 1e-30)), 0.0)
    icept, slope = speed_line(v, F) if fast.sum() >= 2 else (Ff, C)
    return [(Ff, y, C), (max(icept, 1e-9), y, max(slope, 0.0))]


def law1(d, v, F):
    """C = sum(F v) / sum(v^2) (least squares of eq. 1)."""
    return [(max(float(np.sum(F * v) / max(np.sum(v * v), 1e-30)), 0.0),)]


def law2(d, v, F):
    return [power_term(v, F)]


def law3(d, v, F):
    K1 = spring(d, v, F)
    return [(*power_term(v, F - K1 * d), K1)]


def law4(d, v, F):
    return [(*p, 0.0) for p in law3(d, v, F)]


def law5(d, v, F):
    """The spring as law 3's with beta = 1 (one amplitude does not fix beta)."""
    return [(*p, 1.0) for p in law3(d, v, F)]


def law6(d, v, F):
    """alpha 0.05; z saturates at 1/(2 beta) = y, the hysteretic force (1-alpha) K y = Ff."""
    return [(C, Ff / (0.95 * y), 0.05, 1.0 / (2.0 * y)) for Ff, y, C in hysteretic(d, v, F)]


def law8(d, v, F):
    """mu N = Ff (mu 0.5), slipping after a travel y: K = Ff / y."""
    return [(C, Ff / y, 0.5, 2.0 * Ff) for Ff, y, C in hysteretic(d, v, F)]


def law9(d, v, F):
    """z saturates at 1/alpha = y, the bristle force beta / alpha = Ff."""
    return [(C, 1.0 / y, Ff / y) for Ff, y, C in hysteretic(d, v, F)]


#: law 10's relief knee, as a share of the peak velocity
KNEE_SHARE = 0.1
#: a series spring's start deflects 1/RIGID_SHARE of the stroke amplitude at the peak force
RIGID_SHARE = 30.0


def law10(d, v, F):
    """Beyond the relief force the force is a line in |v|: |F| = a + b |v|
    with b = p C (a regression over the fastest half), which meets F = C v
    at the knee v_k: Fr = a + b v_k, C = Fr / v_k, p = b / C."""
    a, b = speed_line(v, F)
    v_k = KNEE_SHARE * float(np.max(np.abs(v)))
    Fr = max(float(a + b * v_k), 1e-9)
    C = Fr / v_k
    amplitude = max(float(np.ptp(d)) / 2.0, 1e-9)
    return [(RIGID_SHARE * float(np.max(np.abs(F))) / amplitude, C, Fr, float(np.clip(b / C, 1e-3, 1.0)))]
