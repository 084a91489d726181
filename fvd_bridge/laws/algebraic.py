"""Algebraic laws 1-5 (paper sections 2.1-2.5): force from d [mm] and v [mm/s].

Compiled with numba and parallel over the population.  The power terms
C sign(x)|x|^e are evaluated as C sign(x) exp(e log|x|) with log|x| computed
once per sample for the whole population (the kernels' hot spot).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from .steps import algebraic_form, algebraic_force, sign_log


#: below this many members, ``_algebraic`` splits the samples among the threads, not the members
FEW_MEMBERS = 4


@njit(parallel=True, cache=True, fastmath=True)
def _algebraic(code, d, v, P):
    """``steps.algebraic_force`` of law ``code`` (1-5, ``steps.algebraic_form``)
    for each parameter row of P (pop, n_par), with sign and log of v (and
    of d for law 5, the one power of d) once per sample for all members.
    The members are split among the threads; fewer than FEW_MEMBERS (a
    Jacobian's batch) split the samples instead, in one parallel region
    (at 2,865 samples, one member 55 -> 40 us, three 75 -> 65 us)."""
    pop, n = P.shape[0], d.size
    form = np.empty((pop, 6))
    for i in range(pop):
        form[i] = algebraic_form(code, P[i])
    F = np.empty((pop, n))
    if pop < FEW_MEMBERS:
        for k in prange(n):
            sv, lv = sign_log(v[k])
            sd, ld = sign_log(d[k]) if code == 5 else (0.0, 0.0)
            for i in range(pop):
                F[i, k] = algebraic_force(form[i, 0], form[i, 1], form[i, 2], form[i, 3], form[i, 4], form[i, 5],
                                          d[k], sv, lv, sd, ld)
        return F
    sv, lv, sd, ld = np.empty(n), np.empty(n), np.zeros(n), np.zeros(n)
    for k in prange(n):
        sv[k], lv[k] = sign_log(v[k])
        if code == 5:
            sd[k], ld[k] = sign_log(d[k])
    for i in prange(pop):
        for k in range(n):
            F[i, k] = algebraic_force(form[i, 0], form[i, 1], form[i, 2], form[i, 3], form[i, 4], form[i, 5],
                                      d[k], sv[k], lv[k], sd[k], ld[k])
    return F


def law1(d, v, dt, P, substeps=1):
    """Linear viscous, F = C v (eq. 1)."""
    return P[:, 0:1] * v[None, :]


def law2(d, v, dt, P, substeps=1):
    """Generalized viscous, F = C sign(v)|v|^alpha (eq. 2)."""
    return _algebraic(2, d, v, P)


def law3(d, v, dt, P, substeps=1):
    """Generalized viscous + linear spring, F = K1 d + C sign(v)|v|^alpha (eq. 5)."""
    return _algebraic(3, d, v, P)


def law4(d, v, dt, P, substeps=1):
    """Generalized viscous + quadratic spring, F = K1 d + K2 d^2 + C sign(v)|v|^alpha (eq. 6).

    As printed: K2 d^2 is even in d (pushes the same way in tension and compression).
    """
    return _algebraic(4, d, v, P)


def law5(d, v, dt, P, substeps=1):
    """Generalized Kelvin-Voigt, F = K sign(d)|d|^beta + C sign(v)|v|^alpha (eq. 7)."""
    return _algebraic(5, d, v, P)
