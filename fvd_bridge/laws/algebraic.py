"""Algebraic laws 1-5 (paper sections 2.1-2.5): force from d [mm] and v [mm/s].

Compiled with numba and parallel over the population.  The power terms
C sign(x)|x|^e are evaluated as C sign(x) exp(e log|x|) with log|x| computed
once per sample for the whole population (the kernels' hot spot).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ..kernel_cache import kernel_array
from .steps import algebraic_form, algebraic_force, sign_log


@njit(cache=True)
def _sign_log(x):
    """sign(x) and ln|x| of each sample (``steps.sign_log``)."""
    signs, logs = np.empty_like(x), np.empty_like(x)
    for k in range(x.size):
        signs[k], logs[k] = sign_log(x[k])
    return signs, logs


@njit(parallel=True, cache=True, fastmath=True)
def _algebraic(d, sv, lv, sd, ld, C, alpha, K1, K2, K, beta):
    """``steps.algebraic_force`` for each member (laws 2-5 are special cases)."""
    pop, n = C.size, d.size
    F = np.empty((pop, n))
    for i in prange(pop):
        for k in range(n):
            F[i, k] = algebraic_force(C[i], alpha[i], K1[i], K2[i], K[i], beta[i], d[k], sv[k], lv[k], sd[k], ld[k])
    return F


def _general(code, d, v, P):
    """Law ``code`` as the general algebraic law (``steps.algebraic_form``)."""
    columns = algebraic_form.py_func(code, P.T)
    sv, lv = _sign_log(v)
    sd, ld = _sign_log(d)
    return _algebraic(d, sv, lv, sd, ld, *(kernel_array(np.broadcast_to(c, P.shape[:1])) for c in columns))


def law1(d, v, dt, P, substeps=1):
    """Linear viscous, F = C v (eq. 1)."""
    return P[:, 0:1] * v[None, :]


def law2(d, v, dt, P, substeps=1):
    """Generalized viscous, F = C sign(v)|v|^alpha (eq. 2)."""
    return _general(2, d, v, P)


def law3(d, v, dt, P, substeps=1):
    """Generalized viscous + linear spring, F = K1 d + C sign(v)|v|^alpha (eq. 5)."""
    return _general(3, d, v, P)


def law4(d, v, dt, P, substeps=1):
    """Generalized viscous + quadratic spring, F = K1 d + K2 d^2 + C sign(v)|v|^alpha (eq. 6).

    As printed: K2 d^2 is even in d (pushes the same way in tension and compression).
    """
    return _general(4, d, v, P)


def law5(d, v, dt, P, substeps=1):
    """Generalized Kelvin-Voigt, F = K sign(d)|d|^beta + C sign(v)|v|^alpha (eq. 7)."""
    return _general(5, d, v, P)
