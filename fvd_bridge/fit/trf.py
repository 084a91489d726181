"""Trust-region reflective least squares with the soft-L1 loss, on the problem's n x n normal form.

The algorithm is scipy's ``least_squares(method='trf', tr_solver='exact',
loss='soft_l1', x_scale='jac')`` inside bounds (Branch, Coleman & Li 1999;
``scipy.optimize._lsq.trf.trf_bounds``, BSD-3), step for step.  What
changed: the steps' linear algebra uses the n x n triangular factor R of
the loss-scaled Jacobian J_s = Q R and Q^T f_s, not the m x n Jacobian and
m residuals.  Both give the same singular values, gradient and quadratic
model; scipy's work per iteration grows with the record (0.13 ms at 300
samples, 1.1 ms at 14,000, 3 parameters), here it is one Gram product.
And the code around it: the passes over the m residuals (the cost, the
normal equations) are compiled (``fit.trf_kernels``), and scipy's helpers
of an iteration run on Python floats (``fit.trf_step``): scipy spends
about 0.35 ms of Python an iteration at n = 2, this loop about 60 us
with its passes over 2,865 residuals.  ``tests/fit/test_trf.py`` holds
it to scipy's iterates, and its steps to scipy's helpers'.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize._lsq.common import check_termination, update_tr_radius

from ..kernel_cache import kernel_array
from . import trf_kernels as kernels
from .trf_step import (cl_scaling_vector, hat_model, initial_radius, jac_scale_inv, make_strictly_feasible, norm,
                       optimality, trial_step)


def strictly_inside(x, lb, ub) -> np.ndarray:
    """x moved off any bound it lies on (scipy's ``make_strictly_feasible``):
    where the solver starts from x."""
    return np.array(make_strictly_feasible(np.asarray(x, dtype=float).tolist(), np.asarray(lb, dtype=float).tolist(),
                                           np.asarray(ub, dtype=float).tolist()))


def loss_model(r: np.ndarray, JT: np.ndarray, f_scale: float):
    """(R, Q^T f_s, the gradient J_s^T f_s, J_s's column norms) of kernel
    arrays r (m,) and J^T (n, m): R is the Gram matrix's Cholesky factor
    while well conditioned (``trf_kernels.gram_factor``), else QR's."""
    G, g = kernels.normal_equations(r, JT, f_scale)
    R, qf, factored = kernels.gram_factor(G, g)
    if not factored:
        JsT, fs = kernels.loss_scaled(r, JT, f_scale)
        Raug = np.linalg.qr(np.column_stack([JsT.T, fs]), mode="r")
        R, qf = Raug[:-1, :-1], Raug[:-1, -1]
    return R, qf, g.tolist(), np.sqrt(G.diagonal()).tolist()


def least_squares_soft_l1(fun_jac, x0, lb, ub, f_scale: float, *, max_nfev: int, xtol: float = 1e-8,
                          ftol: float = 1e-8, gtol: float = 1e-8, callback=None):
    """Minimise 0.5 sum rho(r(x)) over lb <= x <= ub from x0.  ``fun_jac(x)
    -> (r (m,), J^T (n, m))``, the Jacobian transposed (the residuals must
    be finite at x0);
    ``callback(x)`` after each iteration may raise StopIteration to stop.
    Returns (x, status, nfev) with scipy's status codes (0: max_nfev, 1-4:
    gtol, ftol, xtol, both; -2: stopped by the callback)."""
    f_scale = float(f_scale)
    lb, ub = np.asarray(lb, dtype=float), np.asarray(ub, dtype=float)
    lo, hi = lb.tolist(), ub.tolist()
    x = strictly_inside(x0, lb, ub)
    r, JT = _evaluate(fun_jac, x)
    m = r.size
    nfev = 1
    cost, finite = kernels.soft_l1_cost(r, f_scale)
    if not finite:
        raise ValueError("the residuals are not finite at x0")
    R, qf, g, norms = loss_model(r, JT, f_scale)
    xl = x.tolist()  # the iterate, as floats
    scale_inv = jac_scale_inv(norms)
    alpha, status = 0.0, None
    Delta = initial_radius(xl, *cl_scaling_vector(xl, g, lo, hi), scale_inv)
    while True:
        v, dv = cl_scaling_vector(xl, g, lo, hi)
        g_norm = optimality(g, v)
        if g_norm < gtol:
            status = 1
        if status is not None or nfev == max_nfev:
            break
        model = hat_model(v, dv, g, R, qf, scale_inv, m)
        theta = max(0.995, 1.0 - g_norm)
        actual_reduction = -1.0
        while actual_reduction <= 0 and nfev < max_nfev:
            x_new, step, step_h, predicted_reduction, alpha = trial_step(xl, model, Delta, alpha, theta, lo, hi)
            r_new, JT_new = _evaluate(fun_jac, np.array(x_new))
            nfev += 1
            step_h_norm = norm(step_h)
            cost_new, finite = kernels.soft_l1_cost(r_new, f_scale)
            if not finite:
                Delta = 0.25 * step_h_norm
                continue
            actual_reduction = cost - cost_new
            Delta_new, ratio = update_tr_radius(Delta, actual_reduction, predicted_reduction, step_h_norm,
                                                step_h_norm > 0.95 * Delta)
            status = check_termination(actual_reduction, cost, norm(step), norm(xl), ratio, ftol, xtol)
            if status is not None:
                break
            alpha *= Delta / Delta_new
            Delta = Delta_new
        if actual_reduction > 0:
            xl = x_new
            R, qf, g, norms = loss_model(r_new, JT_new, f_scale)
            cost = cost_new
            scale_inv = jac_scale_inv(norms, scale_inv)
        if callback is not None:
            try:
                callback(np.array(xl))
            except StopIteration:
                status = -2
                break
    return np.array(xl), (0 if status is None else status), nfev


def _evaluate(fun_jac, x: np.ndarray):
    """(r, J^T) at x as kernel arrays."""
    r, JT = fun_jac(x)
    return kernel_array(r), kernel_array(JT)
