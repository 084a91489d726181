"""Differential laws 6-9 (paper sections 2.6-2.9): population drivers.

Each driver integrates z(t) from z = 0 with a fixed step equal to the
sampling step dt (optionally split in ``substeps``), v linear between
samples, for every parameter row in parallel (numba prange over the
population): P (pop, n_par) -> F (pop, n_t) [kN].
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from .steps import bouc_wen_step, lugre_step, maxwell_step, powsign, slip_step, split_travel

Q_MAX = 1e150  # largest dashpot rate factor q of law 7 [1/s per mm^p]


@njit(cache=True)
def _sub_velocities(v0, v1, j, m):
    """Velocities at the ends of sub-step j of m within one sample step."""
    return v0 + (v1 - v0) * j / m, v0 + (v1 - v0) * (j + 1) / m


@njit(parallel=True, cache=True)
def bouc_wen_force(d, v, dt, C, K, alpha, A, beta, gamma, substeps):
    """F = alpha K d + (1 - alpha) K z + C v (paper eq. 8) with the Bouc-Wen z
    of ``bouc_wen_step``; parameters are arrays of length pop."""
    pop, n = C.size, d.size
    F = np.empty((pop, n))
    h = dt / substeps
    for i in prange(pop):
        z = 0.0
        F[i, 0] = alpha[i] * K[i] * d[0] + C[i] * v[0]
        for k in range(1, n):
            for j in range(substeps):
                va, vb = _sub_velocities(v[k - 1], v[k], j, substeps)
                u1, u2 = split_travel(va, vb, h)
                z = bouc_wen_step(z, u1, A[i], beta[i], gamma[i])
                z = bouc_wen_step(z, u2, A[i], beta[i], gamma[i])
            F[i, k] = alpha[i] * K[i] * d[k] + (1.0 - alpha[i]) * K[i] * z + C[i] * v[k]
    return F


def law6(d, v, dt, P, substeps=1):
    """Bouc-Wen + viscous with A = n = 1, beta = gamma (paper section 2.6)."""
    ones = np.ones(P.shape[0])
    return bouc_wen_force(d, v, dt, P[:, 0].copy(), P[:, 1].copy(), P[:, 2].copy(),
                          ones, P[:, 3].copy(), P[:, 3].copy(), substeps)


@njit(parallel=True, cache=True)
def _law7(d, v, dt, P, substeps):
    pop, n = P.shape[0], d.size
    F = np.zeros((pop, n))
    h = dt / substeps
    for i in prange(pop):
        C, alpha, K, beta = P[i, 0], P[i, 1], P[i, 2], P[i, 3]
        # q = (K/C)^(1/alpha), clamped: beyond it the dashpot is rigid at this step anyway
        q = min(math.exp(math.log(K / C) / alpha), Q_MAX) if C > 0.0 and K > 0.0 else (Q_MAX if C <= 0.0 else 0.0)
        p = beta / alpha
        z = 0.0
        for k in range(1, n):
            for j in range(substeps):
                va, vb = _sub_velocities(v[k - 1], v[k], j, substeps)
                z = maxwell_step(z, 0.5 * (va + vb) * h, h, q, p)
            F[i, k] = K * powsign(z, beta)
    return F


def law7(d, v, dt, P, substeps=1):
    """Lu unified visco-elastic: F = K sign(z)|z|^beta (eqs. 10-11), z the spring deformation."""
    return _law7(d, v, dt, P, substeps)


@njit(parallel=True, cache=True)
def _law8(d, v, dt, P, substeps):
    pop, n = P.shape[0], d.size
    F = np.empty((pop, n))
    h = dt / substeps
    for i in prange(pop):
        C, K, muN = P[i, 0], P[i, 1], P[i, 2] * P[i, 3]
        k_slip = K / muN if muN > 0.0 else 0.0
        z = 0.0
        F[i, 0] = C * v[0]
        for k in range(1, n):
            for j in range(substeps):
                va, vb = _sub_velocities(v[k - 1], v[k], j, substeps)
                u1, u2 = split_travel(va, vb, h)
                z = slip_step(slip_step(z, u1, k_slip), u2, k_slip)
            F[i, k] = z * muN + C * v[k]
    return F


def law8(d, v, dt, P, substeps=1):
    """Lu unified friction + viscous: F = z mu N + C v (eqs. 12-13)."""
    return _law8(d, v, dt, P, substeps)


@njit(parallel=True, cache=True)
def _law9(d, v, dt, P, substeps):
    pop, n = P.shape[0], d.size
    F = np.empty((pop, n))
    h = dt / substeps
    for i in prange(pop):
        C, a, b = P[i, 0], P[i, 1], P[i, 2]
        z = 0.0
        F[i, 0] = C * v[0]
        for k in range(1, n):
            for j in range(substeps):
                va, vb = _sub_velocities(v[k - 1], v[k], j, substeps)
                u1, u2 = split_travel(va, vb, h)
                z = lugre_step(lugre_step(z, u1, a), u2, a)
            F[i, k] = b * z + C * v[k]
    return F


def law9(d, v, dt, P, substeps=1):
    """LuGre with eps = K = F0 = 0: F = beta z + C v (eqs. 14-15)."""
    return _law9(d, v, dt, P, substeps)
