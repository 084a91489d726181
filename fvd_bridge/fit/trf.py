"""Trust-region reflective least squares with the soft-L1 loss, on the problem's n x n normal form.

The algorithm is scipy's ``least_squares(method='trf', tr_solver='exact',
loss='soft_l1', x_scale='jac')`` inside bounds (Branch, Coleman & Li 1999;
``scipy.optimize._lsq.trf.trf_bounds``, BSD-3), step for step, and its
helpers are scipy's.  One change: the steps' linear algebra uses the n x n
triangular factor R of the loss-scaled Jacobian J_s = Q R and Q^T f_s, not
the m x n Jacobian and m residuals.  Both give the same singular values,
gradient and quadratic model; scipy's work per iteration grows with the
record (0.13 ms at 300 samples, 1.1 ms at 14,000, 3 parameters), here it
is one Gram product.  ``tests/fit/test_trf.py`` holds it to scipy's iterates.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize._lsq.common import (CL_scaling_vector, check_termination, compute_jac_scale,
                                        make_strictly_feasible, solve_lsq_trust_region, update_tr_radius)
from scipy.optimize._lsq.trf import select_step

EPS = np.finfo(float).eps
#: the Gram matrix's Cholesky factor is used while the equilibrated
#: Jacobian's condition number stays below 1/GRAM_PIVOT (R then has about
#: 8 correct digits); a worse-conditioned Jacobian is factored by QR
GRAM_PIVOT = 1e-4


def strictly_inside(x, lb, ub) -> np.ndarray:
    """x moved off any bound it lies on (scipy's ``make_strictly_feasible``):
    where the solver starts from x."""
    return make_strictly_feasible(np.asarray(x, dtype=float), lb, ub)


def soft_l1_cost(r: np.ndarray, f_scale: float) -> float:
    """0.5 sum rho(r), rho(r) = 2 f_scale^2 (sqrt(1 + (r/f_scale)^2) - 1): scipy's soft-L1 cost."""
    return float(f_scale ** 2 * (np.sqrt(1.0 + (r / f_scale) ** 2).sum() - r.size))


def normal_form(r: np.ndarray, J: np.ndarray, f_scale: float):
    """(R, Q^T f_s) of residuals r (m,) and Jacobian J (m, n) under the
    soft-L1 loss: J_s and f_s are scipy's loss-scaled Jacobian and residuals
    (``scale_for_robust_loss_function``: J_s = sqrt(rho' + 2 rho'' r^2) J,
    which is t^-3/4 J with t = 1 + (r/f_scale)^2, and f_s = rho' r /
    sqrt(...)), J_s = Q R."""
    t = 1.0 + (r / f_scale) ** 2
    st = np.sqrt(t)
    w = np.sqrt(np.minimum(t * st, 1.0 / EPS))  # 1 / sqrt(rho' + 2 rho'' r^2), at most EPS^-1/2 (scipy's clamp)
    JsT = np.ascontiguousarray(J.T) / w  # J_s^T (n, m): one row per parameter
    fs = r * w / st
    G = JsT @ JsT.T
    norms = np.sqrt(np.diag(G))
    norms[norms == 0.0] = 1.0
    try:
        U = np.linalg.cholesky(G / np.outer(norms, norms)).T  # of the equilibrated Gram matrix (unit diagonal)
        if np.min(np.abs(np.diag(U))) > GRAM_PIVOT:
            R = U * norms[None, :]
            return R, np.linalg.solve(R.T, JsT @ fs)
    except np.linalg.LinAlgError:
        pass
    Js = JsT.T
    Raug = np.linalg.qr(np.column_stack([Js, fs]), mode="r")
    return Raug[:-1, :-1], Raug[:-1, -1]


def least_squares_soft_l1(fun_jac, x0, lb, ub, f_scale: float, *, max_nfev: int, xtol: float = 1e-8,
                          ftol: float = 1e-8, gtol: float = 1e-8, callback=None):
    """Minimise 0.5 sum rho(r(x)) over lb <= x <= ub from x0.  ``fun_jac(x)
    -> (r (m,), J (m, n))`` (the residuals must be finite at x0);
    ``callback(x)`` after each iteration may raise StopIteration to stop.
    Returns (x, status, nfev) with scipy's status codes (0: max_nfev, 1-4:
    gtol, ftol, xtol, both; -2: stopped by the callback)."""
    lb, ub = np.asarray(lb, dtype=float), np.asarray(ub, dtype=float)
    x = strictly_inside(x0, lb, ub)
    r, J = fun_jac(x)
    m, n = J.shape
    nfev = 1
    cost = soft_l1_cost(r, f_scale)
    R, qf = normal_form(r, J, f_scale)
    g = R.T @ qf
    scale, scale_inv = compute_jac_scale(R)
    alpha, status = 0.0, None
    v, dv = CL_scaling_vector(x, g, lb, ub)
    v[dv != 0] *= scale_inv[dv != 0]
    Delta = np.linalg.norm(x * scale_inv / v ** 0.5) or 1.0
    zeros = np.zeros(n)
    while True:
        v, dv = CL_scaling_vector(x, g, lb, ub)
        g_norm = np.linalg.norm(g * v, ord=np.inf)
        if g_norm < gtol:
            status = 1
        if status is not None or nfev == max_nfev:
            break
        v[dv != 0] *= scale_inv[dv != 0]
        d = v ** 0.5 * scale
        diag_h = g * dv * scale
        g_h = d * g
        J_h = R * d  # n x n: J_h's products and norms as the m x n J d's
        U, s, Vt = np.linalg.svd(np.vstack([J_h, np.diag(diag_h ** 0.5)]), full_matrices=False)
        V = Vt.T
        uf = U.T @ np.concatenate([qf, zeros])
        theta = max(0.995, 1.0 - g_norm)
        actual_reduction = -1.0
        while actual_reduction <= 0 and nfev < max_nfev:
            p_h, alpha, _ = solve_lsq_trust_region(n, m, uf, s, V, Delta, initial_alpha=alpha)
            p = d * p_h
            step, step_h, predicted_reduction = select_step(x, J_h, diag_h, g_h, p, p_h, d, Delta, lb, ub, theta)
            x_new = make_strictly_feasible(x + step, lb, ub, rstep=0)
            r_new, J_new = fun_jac(x_new)
            nfev += 1
            step_h_norm = np.linalg.norm(step_h)
            if not np.all(np.isfinite(r_new)):
                Delta = 0.25 * step_h_norm
                continue
            cost_new = soft_l1_cost(r_new, f_scale)
            actual_reduction = cost - cost_new
            Delta_new, ratio = update_tr_radius(Delta, actual_reduction, predicted_reduction, step_h_norm,
                                                step_h_norm > 0.95 * Delta)
            status = check_termination(actual_reduction, cost, np.linalg.norm(step), np.linalg.norm(x), ratio,
                                       ftol, xtol)
            if status is not None:
                break
            alpha *= Delta / Delta_new
            Delta = Delta_new
        if actual_reduction > 0:
            x = x_new
            R, qf = normal_form(r_new, J_new, f_scale)
            cost = cost_new
            g = R.T @ qf
            scale, scale_inv = compute_jac_scale(R, scale_inv)
        if callback is not None:
            try:
                callback(x)
            except StopIteration:
                status = -2
                break
    return x, (0 if status is None else status), nfev
