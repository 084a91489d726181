"""The compiled passes of ``fit.trf`` over the m residuals: the soft-L1 cost, the normal equations, the forward differences.

A solver's evaluation makes a pass over the record's m samples for the
cost and, accepted, one for the normal equations J_s^T J_s, J_s^T f_s of
the loss-scaled problem: about 50 us of numpy temporaries and calls at
2,865 samples, 15 us here.  Loops over scalars (numpy's array functions
in numba cost seconds of compilation), vectorised: fastmath
may reorder the sums (no 'nnan'/'ninf': the finiteness test stays
exact), so they differ from numpy's in the last bits.  Each kernel
compiles once (float64 C-contiguous writable arrays,
``kernel_cache.kernel_array``; cached on disk): 1.4-1.7 s on 2 cores,
``loss_scaled`` (an ill-conditioned Jacobian's) 0.3 s more when first needed.
"""

from __future__ import annotations

import numpy as np
from numba import njit

EPS = np.finfo(float).eps
#: the Gram matrix's Cholesky factor is used while the equilibrated
#: Jacobian's condition number stays below 1/GRAM_PIVOT (R then has about
#: 8 correct digits); a worse-conditioned Jacobian is factored by QR
GRAM_PIVOT = 1e-4
#: reordered sums and multiply-adds; no 'nnan'/'ninf' (isfinite and the comparisons stay exact)
FASTMATH = {"reassoc", "nsz", "arcp", "contract"}

kernel = njit(cache=True, error_model="numpy")  # as numpy: x/0 = inf
sample_pass = njit(cache=True, error_model="numpy", fastmath=FASTMATH)
inlined = njit(cache=True, error_model="numpy", fastmath=FASTMATH, inline="always")  # so that its loop vectorises


@inlined
def soft_l1_scales(r_k, f_scale):
    """(w^2, sqrt(t)) of a residual r_k under the soft-L1 loss, t = 1 +
    (r_k/f_scale)^2: scipy's loss-scaled Jacobian row and residual are J_k / w
    and r_k w / sqrt(t) (``scale_for_robust_loss_function``: w^-2 = rho' +
    2 rho'' r^2 = t^-3/2, clamped at EPS)."""
    z = r_k / f_scale
    t = 1.0 + z * z
    st = np.sqrt(t)
    w2 = t * st
    return (w2 if w2 < 1.0 / EPS else 1.0 / EPS), st


@sample_pass
def soft_l1_cost(r, f_scale):
    """(0.5 sum rho(r), whether every r is finite): scipy's soft-L1 cost,
    rho(r) = 2 f_scale^2 (sqrt(t) - 1)."""
    total = 0.0
    finite = True
    for k in range(r.size):
        total += soft_l1_scales(r[k], f_scale)[1]
        finite &= np.isfinite(r[k])
    return f_scale * f_scale * (total - r.size), finite


@sample_pass
def normal_equations(r, JT, f_scale):
    """(J_s^T J_s (n, n), J_s^T f_s (n,)) of residuals r (m,) and the
    Jacobian's transpose JT (n, m) under the soft-L1 loss (J_s, f_s:
    ``soft_l1_scales``): sum J_i J_j / w^2, and sum J_i r / sqrt(t) (w cancels)."""
    n, m = JT.shape
    inv_w2, u = np.empty(m), np.empty(m)
    for k in range(m):
        w2, st = soft_l1_scales(r[k], f_scale)
        inv_w2[k] = 1.0 / w2
        u[k] = r[k] / st
    G, g = np.empty((n, n)), np.empty(n)
    for i in range(n):
        for j in range(i + 1):
            total = 0.0
            for k in range(m):
                total += JT[i, k] * JT[j, k] * inv_w2[k]
            G[i, j] = G[j, i] = total
        total = 0.0
        for k in range(m):
            total += JT[i, k] * u[k]
        g[i] = total
    return G, g


@kernel
def forward_differences(R, h, fill):
    """(r (m,), J^T (n, m), whether r is finite) from the residuals R (n + 1,
    m) at a point (row 0) and at its neighbours x + h_i e_i: J_ik = (R_i+1,k
    - r_k) / h_i, a residual not finite at the point taken as ``fill``,
    one not finite at a neighbour giving J_ik = 0 (no slope known there)."""
    n, m = h.size, R.shape[1]
    r, JT = np.empty(m), np.empty((n, m))
    finite = True
    for k in range(m):
        ok = np.isfinite(R[0, k])
        r[k] = R[0, k] if ok else fill
        finite &= ok
    for i in range(n):
        for k in range(m):
            JT[i, k] = (R[i + 1, k] - r[k]) / h[i] if np.isfinite(R[i + 1, k]) else 0.0
    return r, JT, finite


@sample_pass
def loss_scaled(r, JT, f_scale):
    """(J_s^T (n, m), f_s (m,)): scipy's loss-scaled Jacobian and residuals (``soft_l1_scales``)."""
    n, m = JT.shape
    w, fs = np.empty(m), np.empty(m)
    for k in range(m):
        w2, st = soft_l1_scales(r[k], f_scale)
        w[k] = np.sqrt(w2)
        fs[k] = r[k] * w[k] / st
    JsT = np.empty((n, m))
    for i in range(n):
        for k in range(m):
            JsT[i, k] = JT[i, k] / w[k]
    return JsT, fs


@kernel
def gram_factor(G, b):
    """(R, y, True) with R^T R = G (n, n) (upper, the Cholesky factor of G
    equilibrated to a unit diagonal, scaled back) and R^T y = b; (.., False)
    when a pivot of the equilibrated factor is at most GRAM_PIVOT."""
    n = b.size
    norms = np.empty(n)
    for i in range(n):
        norms[i] = np.sqrt(G[i, i]) if G[i, i] != 0.0 else 1.0
    R = np.zeros((n, n))
    y = np.empty(n)
    for j in range(n):
        s = G[j, j] / (norms[j] * norms[j])
        for k in range(j):
            s -= R[k, j] * R[k, j]
        pivot = np.sqrt(max(s, 0.0))
        if not pivot > GRAM_PIVOT:
            return R, y, False
        R[j, j] = pivot
        for i in range(j + 1, n):
            s = G[j, i] / (norms[j] * norms[i])
            for k in range(j):
                s -= R[k, j] * R[k, i]
            R[j, i] = s / pivot
    for j in range(n):
        for i in range(j + 1):
            R[i, j] *= norms[j]
    for i in range(n):  # R^T y = b: forward substitution
        s = b[i]
        for k in range(i):
            s -= R[k, i] * y[k]
        y[i] = s / R[i, i]
    return R, y, True
