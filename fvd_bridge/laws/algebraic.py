"""Algebraic laws 1-5 (paper sections 2.1-2.5): force from d [mm] and v [mm/s].

Compiled with numba and parallel over the population.  The power terms
C sign(x)|x|^e are evaluated as C sign(x) exp(e log|x|) with log|x| computed
once per sample for the whole population (the kernels' hot spot).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange


def _sign_log(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """sign(x) and log|x| (log 0 -> -1e300 so that 0^e = 0 for e > 0 and sign 0 kills e = 0)."""
    ax = np.abs(x)
    return np.sign(x), np.where(ax > 0.0, np.log(np.where(ax > 0.0, ax, 1.0)), -1e300)


@njit(cache=True, fastmath=True)
def power_term(c, sign_x, log_abs_x, e):
    """c sign(x) |x|^e  (the generalized viscous term of paper eq. 2, and eq. 7's spring)."""
    return c * sign_x * math.exp(e * log_abs_x)


@njit(parallel=True, cache=True, fastmath=True)
def _algebraic(d, sv, lv, sd, ld, C, alpha, K1, K2, K, beta):
    """F = K1 d + K2 d^2 + K sign(d)|d|^beta + C sign(v)|v|^alpha  (laws 2-5 are special cases)."""
    pop, n = C.size, d.size
    F = np.empty((pop, n))
    for i in prange(pop):
        for k in range(n):
            f = power_term(C[i], sv[k], lv[k], alpha[i]) + K1[i] * d[k] + K2[i] * d[k] * d[k]
            if K[i] != 0.0:
                f += power_term(K[i], sd[k], ld[k], beta[i])
            F[i, k] = f
    return F


def _general(d, v, C, alpha, K1=None, K2=None, K=None, beta=None):
    zero = np.zeros_like(C)
    sv, lv = _sign_log(v)
    sd, ld = _sign_log(d)
    pick = (lambda x: zero if x is None else np.ascontiguousarray(x))
    return _algebraic(d, sv, lv, sd, ld, np.ascontiguousarray(C), np.ascontiguousarray(alpha),
                      pick(K1), pick(K2), pick(K), pick(beta))


def law1(d, v, dt, P, substeps=1):
    """Linear viscous, F = C v (eq. 1)."""
    return P[:, 0:1] * v[None, :]


def law2(d, v, dt, P, substeps=1):
    """Generalized viscous, F = C sign(v)|v|^alpha (eq. 2)."""
    return _general(d, v, P[:, 0], P[:, 1])


def law3(d, v, dt, P, substeps=1):
    """Generalized viscous + linear spring, F = K1 d + C sign(v)|v|^alpha (eq. 5)."""
    return _general(d, v, P[:, 0], P[:, 1], K1=P[:, 2])


def law4(d, v, dt, P, substeps=1):
    """Generalized viscous + quadratic spring, F = K1 d + K2 d^2 + C sign(v)|v|^alpha (eq. 6).

    As printed: K2 d^2 is even in d (pushes the same way in tension and compression).
    """
    return _general(d, v, P[:, 0], P[:, 1], K1=P[:, 2], K2=P[:, 3])


def law5(d, v, dt, P, substeps=1):
    """Generalized Kelvin-Voigt, F = K sign(d)|d|^beta + C sign(v)|v|^alpha (eq. 7)."""
    return _general(d, v, P[:, 0], P[:, 1], K=P[:, 2], beta=P[:, 3])
