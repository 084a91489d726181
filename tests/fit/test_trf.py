"""The local search's least squares (fvd_bridge/fit/trf.py) against scipy's
``least_squares(method='trf', loss='soft_l1', x_scale='jac')``, the
algorithm it restates on the n x n normal form: the same iterates, the
same stopping reason, the same answer, on a nonlinear problem with
outliers (an interior optimum, and one on a bound), and where the Jacobian
has a null direction (its QR path); and its trial step (fit/trf_step.py)
against scipy's helpers, on random problems."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import svd
from scipy.optimize import least_squares
from scipy.optimize._lsq.common import CL_scaling_vector, make_strictly_feasible, solve_lsq_trust_region
from scipy.optimize._lsq.trf import select_step

from fvd_bridge.fit import trf_step
from fvd_bridge.kernel_cache import kernel_array
from fvd_bridge.fit.trf import least_squares_soft_l1, loss_model
from fvd_bridge.fit.trf_kernels import soft_l1_cost

T = np.linspace(0.0, 4.0, 800)


def decay(x):
    return 3.0 * x[0] * np.exp(-4.0 * x[1] * T) + x[2] * np.sin(5.0 * T)


def decay_jac(x):
    e = np.exp(-4.0 * x[1] * T)
    return np.column_stack([3.0 * e, -12.0 * x[0] * T * e, np.sin(5.0 * T)])


def data(truth, seed=1):
    rng = np.random.default_rng(seed)
    y = decay(np.array(truth)) + 0.05 * rng.standard_normal(T.size)
    y[::37] += 2.0  # outliers: the robust loss's reason
    return y


@pytest.mark.parametrize("truth", [(0.6, 0.3, 0.2), (0.6, 0.3, 1.3)], ids=["interior", "on a bound"])
@pytest.mark.parametrize("x0", [(0.1, 0.9, 0.9), (0.9, 0.05, 0.01), (0.5, 0.5, 0.5)])
@pytest.mark.parametrize("f_scale", [0.05, 0.005])
def test_the_iterates_are_scipys(truth, x0, f_scale):
    y = data(truth)
    ref = least_squares(lambda x: decay(x) - y, x0, jac=decay_jac, bounds=(0.0, 1.0), loss="soft_l1",
                        f_scale=f_scale, x_scale="jac", max_nfev=40, xtol=1e-10, ftol=1e-10, gtol=1e-10)
    x, status, nfev = least_squares_soft_l1(lambda x: (decay(x) - y, decay_jac(x).T), x0, np.zeros(3), np.ones(3),
                                            f_scale, max_nfev=40, xtol=1e-10, ftol=1e-10, gtol=1e-10)
    assert (nfev, status) == (ref.nfev, ref.status)
    np.testing.assert_allclose(x, ref.x, atol=1e-9)
    if truth[2] > 1.0:
        assert x[2] == pytest.approx(1.0, abs=1e-6)  # the third parameter ends on its upper bound


def test_a_null_direction_takes_the_qr_path_and_the_same_answer():
    """x[2] and x[3] enter as their sum only: J has a null direction (the
    Gram matrix is singular), so R comes from a QR factorisation; the cost
    reached is scipy's, and the sum x[2] + x[3] is."""
    y = data((0.6, 0.3, 0.4))

    def fun(x):
        return decay(np.array([x[0], x[1], x[2] + x[3]])) - y

    def jac(x):
        J = decay_jac(np.array([x[0], x[1], x[2] + x[3]]))
        return np.column_stack([J, J[:, 2]])

    x0 = np.array([0.5, 0.5, 0.1, 0.1])
    R = loss_model(kernel_array(fun(x0)), kernel_array(jac(x0).T), 0.05)[0]
    assert abs(R[-1, -1]) < 1e-10 * np.abs(R).max()  # QR's R: the null direction's pivot is round-off
    np.testing.assert_allclose(R.T @ R, _scaled_gram(fun(x0), jac(x0), 0.05), atol=1e-10 * np.abs(R.T @ R).max())
    ref = least_squares(fun, x0, jac=jac, bounds=(0.0, 1.0), loss="soft_l1", f_scale=0.05, x_scale="jac",
                        max_nfev=40, xtol=1e-10, ftol=1e-10, gtol=1e-10)
    x, _, _ = least_squares_soft_l1(lambda x: (fun(x), jac(x).T), x0, np.zeros(4), np.ones(4), 0.05,
                                    max_nfev=40, xtol=1e-10, ftol=1e-10, gtol=1e-10)
    assert soft_l1_cost(kernel_array(fun(x)), 0.05)[0] == pytest.approx(ref.cost, rel=1e-8)
    assert x[2] + x[3] == pytest.approx(ref.x[2] + ref.x[3], abs=1e-6)


def _scaled_gram(r, J, f_scale):
    """J_s^T J_s by scipy's own scaling (``scale_for_robust_loss_function``)."""
    from scipy.optimize._lsq.common import scale_for_robust_loss_function
    from scipy.optimize._lsq.least_squares import construct_loss_function

    rho = construct_loss_function(r.size, "soft_l1", f_scale)(r.copy())
    Js, _ = scale_for_robust_loss_function(J.copy(), r.copy(), rho)
    return Js.T @ Js


def test_a_callback_stops_the_solve_where_it_is():
    y = data((0.6, 0.3, 0.2))
    seen = []

    def stop_on_third(x):
        seen.append(x.copy())
        if len(seen) == 3:
            raise StopIteration

    x, status, _ = least_squares_soft_l1(lambda x: (decay(x) - y, decay_jac(x).T), (0.1, 0.9, 0.9), np.zeros(3),
                                         np.ones(3), 0.05, max_nfev=40, xtol=1e-10, ftol=1e-10, gtol=1e-10,
                                         callback=stop_on_third)
    assert status == -2 and len(seen) == 3
    np.testing.assert_array_equal(x, seen[-1])


def scipy_trial(x, g, R, qf, scale_inv, lb, ub, Delta, alpha, theta, m):
    """One trial of scipy's ``trf_bounds`` (tr_solver='exact') with scipy's
    own helpers, R (n x n) in place of the Jacobian: (x_new, step, step_h,
    predicted reduction, alpha, whether the trust-region step stays inside)."""
    n = x.size
    v, dv = CL_scaling_vector(x, g, lb, ub)
    v[dv != 0] *= scale_inv[dv != 0]
    scale = 1 / scale_inv
    d = v ** 0.5 * scale
    diag_h = g * dv * scale
    g_h = d * g
    J_h = R * d
    U, s, Vt = svd(np.vstack([J_h, np.diag(diag_h ** 0.5)]), full_matrices=False)
    uf = U.T.dot(np.concatenate([qf, np.zeros(n)]))
    p_h, alpha, _ = solve_lsq_trust_region(n, m, uf, s, Vt.T, Delta, initial_alpha=alpha)
    p = d * p_h
    inside = bool(np.all((x + p >= lb) & (x + p <= ub)))
    step, step_h, predicted = select_step(x, J_h, diag_h, g_h, p, p_h, d, Delta=Delta, lb=lb, ub=ub, theta=theta)
    return make_strictly_feasible(x + step, lb, ub, rstep=0), step, step_h, predicted, alpha, inside


def random_trial(rng, n, at_bounds):
    """A trial's inputs: bounds, a point inside them (``at_bounds``: some
    coordinates near the bound the gradient pushes to, one a float away),
    a well-conditioned normal form (R, qf) of m residuals, a radius, alpha, theta."""
    lb = -rng.uniform(0.1, 2.0, n)
    ub = rng.uniform(0.1, 2.0, n)
    x = rng.uniform(lb, ub)
    m = n + int(rng.integers(1, 200))
    R = np.linalg.qr(rng.standard_normal((2 * n + 2, n)), mode="r") * 10.0 ** rng.uniform(-1.5, 1.0, n)
    qf = rng.standard_normal(n)
    g = R.T @ qf
    if at_bounds:
        near = np.flatnonzero(rng.random(n) < 0.6)
        gap = (ub - lb) * 10.0 ** rng.uniform(-4.0, -0.5, n)
        x[near] = np.where(g < 0, ub - gap, lb + gap)[near]
        i = near[:1]
        x[i] = np.where(g[i] < 0, np.nextafter(ub[i], lb[i]), np.nextafter(lb[i], ub[i]))
    scale_inv = np.sqrt((R ** 2).sum(axis=0)) * 10.0 ** rng.uniform(0.0, 0.5, n)  # at least the column norms
    Delta = 10.0 ** rng.uniform(-2.0, 2.0)
    alpha = 0.0 if rng.random() < 0.5 else 10.0 ** rng.uniform(-3.0, 1.0)
    return x, g, R, qf, scale_inv, lb, ub, Delta, alpha, rng.uniform(0.995, 1.0), m


@pytest.mark.parametrize("at_bounds", [False, True], ids=["inside", "at bounds"])
@pytest.mark.parametrize("n", range(1, 7))
def test_a_trial_step_is_scipys(n, at_bounds):
    """``trf_step``'s trial (its model of the iteration, then the step) is
    scipy's helpers' to 1e-12, on random problems: trust-region steps that
    stay inside and ones that hit a bound (cut back, reflected, or the
    scaled gradient's stride)."""
    rng = np.random.default_rng(100 * n + at_bounds)
    crossing = 0
    for _ in range(60):
        args = random_trial(rng, n, at_bounds)
        x, g, R, qf, scale_inv, lb, ub, Delta, alpha, theta, m = args
        *ref, inside = scipy_trial(*args)
        crossing += not inside
        v, dv = trf_step.cl_scaling_vector(x.tolist(), g.tolist(), lb.tolist(), ub.tolist())
        model = trf_step.hat_model(v, dv, g.tolist(), R, qf, scale_inv.tolist(), m)
        x_new, step, step_h, predicted, alpha_new = trf_step.trial_step(x.tolist(), model, Delta, alpha, theta,
                                                                         lb.tolist(), ub.tolist())
        # step_h by its norm (the solver's use): a coordinate a float off its bound has d ~ 1e-8, and its
        # step_h = step / d magnifies the rounding of x there
        ours = x_new, step, np.linalg.norm(step_h), predicted, alpha_new
        for a, b in zip(ours, (ref[0], ref[1], np.linalg.norm(ref[2]), ref[3], ref[4])):
            np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12 * np.max(np.abs(b)))
    assert 0 < crossing < 60 or n == 1  # both kinds (in 1-D a step from a float off a bound lands on it: inside)


@pytest.mark.parametrize("rstep", [1e-10, 0.0])
def test_moving_inside_is_scipys(rstep):
    """``trf_step.make_strictly_feasible`` (where a solve starts, rstep
    1e-10; where a trial lands, 0) is scipy's, bit for bit: points on their
    bounds, beyond them, within rstep of them, and between bounds closer
    than that."""
    rng = np.random.default_rng(7)
    lb = rng.uniform(-3.0, 1.0, 400)
    ub = lb + np.where(rng.random(400) < 0.1, 1e-12, rng.uniform(0.0, 2.0, 400))
    x = rng.uniform(lb - 0.5, ub + 0.5)
    x[::4], x[1::4] = lb[::4], ub[1::4]
    x[2::8] = lb[2::8] + 1e-11
    ours = trf_step.make_strictly_feasible(x.tolist(), lb.tolist(), ub.tolist(), rstep)
    np.testing.assert_array_equal(ours, make_strictly_feasible(x, lb, ub, rstep=rstep))
