"""scipy's trust-region-reflective helpers on Python floats: an iteration's model, its trial steps.

scipy's ``trf_bounds`` (tr_solver='exact') spends about 0.3 ms of Python
an iteration in its helpers, numpy calls on arrays of n = 1-10 entries.
Here the helpers are ported function for function
(``scipy.optimize._lsq.trf`` and ``scipy.optimize._lsq.common``, BSD-3;
each function names its original), operation for operation, on lists of
floats, with scipy's SVD (LAPACK's gesdd, called directly): about 25 us
an iteration at n = 2.  Vectors are lists, matrices lists of rows.
(Compiled with numba the same step runs in about 8 us, but compiles in
8.5 s on 2 cores, select_step alone 2.3 s however written: more than a
cold start can spend.)  tests/fit/test_trf.py holds them to scipy's
helpers on random problems, to 1e-12.
"""

from __future__ import annotations

import math
from operator import add, mul
from typing import NamedTuple

import numpy as np
from scipy.linalg.lapack import dgesdd as gesdd

EPS = np.finfo(float).eps
#: the trust-region solve's tolerance on |p| - Delta and its iterations (scipy's defaults)
TR_RTOL, TR_MAX_ITER = 0.01, 10


def dot(a, b) -> float:
    """a . b."""
    return sum(map(mul, a, b))


def dot_diag(a, diag, b) -> float:
    """(a * diag) . b (numpy's ``np.dot(a * diag, b)``)."""
    return sum(x * y * z for x, y, z in zip(a, diag, b))


def norm(a) -> float:
    """Euclidean norm (numpy's ``norm``: sqrt(a . a))."""
    return math.sqrt(dot(a, a))


def matvec(A, x) -> list:
    """A x."""
    return [dot(row, x) for row in A]


def scaled(a, t: float) -> list:
    """a t."""
    return [ai * t for ai in a]


def times(a, b) -> list:
    """a * b, elementwise."""
    return list(map(mul, a, b))


def plus(a, b) -> list:
    """a + b."""
    return list(map(add, a, b))


def jac_scale_inv(norms, scale_inv_old=None) -> list:
    """The variables' inverse scale under x_scale='jac' from J's column
    norms: the norms, 1 for a zero one, or at least the last ones (scipy's ``compute_jac_scale``)."""
    if scale_inv_old is None:
        return [c if c != 0 else 1.0 for c in norms]
    return [max(c, old) for c, old in zip(norms, scale_inv_old)]


def cl_scaling_vector(x, g, lb, ub):
    """(v, dv): the Coleman-Li scaling vector and its derivative (scipy's ``CL_scaling_vector``)."""
    v, dv = [1.0] * len(x), [0.0] * len(x)
    for i in range(len(x)):
        if g[i] < 0 and math.isfinite(ub[i]):
            v[i], dv[i] = ub[i] - x[i], -1.0
        if g[i] > 0 and math.isfinite(lb[i]):
            v[i], dv[i] = x[i] - lb[i], 1.0
    return v, dv


def optimality(g, v) -> float:
    """||g v||_inf: the first-order optimality trf stops on (``trf_bounds``' g_norm; v: ``cl_scaling_vector``'s)."""
    return max(abs(gi * vi) for gi, vi in zip(g, v))


def scaled_cl_vector(v, dv, scale_inv) -> list:
    """``cl_scaling_vector``'s v in the variables scaled by x_scale='jac'
    (its components that are not identically 1; ``trf_bounds``)."""
    return [vi * si if dvi != 0 else vi for vi, dvi, si in zip(v, dv, scale_inv)]


def initial_radius(x, v, dv, scale_inv) -> float:
    """The first trust radius: |x scale_inv / v^1/2|, or 1 if that is 0 (``trf_bounds``)."""
    v = scaled_cl_vector(v, dv, scale_inv)
    return norm([xi * si / math.sqrt(vi) for xi, si, vi in zip(x, scale_inv, v)]) or 1.0


class HatModel(NamedTuple):
    """The trust-region model of an iteration in the 'hat' variables
    (``trf_bounds``): d, their scaling (Coleman-Li's v^1/2 and
    x_scale='jac''s); diag_h, the diagonal term C = diag(g scale) Jv; g_h,
    the gradient; J_h = J d (R d, whose products and norms are J d's); and the SVD U diag(s) V^T of [J_h; diag(diag_h)^1/2] with uf =
    U^T [f; 0]; m residuals."""

    d: list
    diag_h: list
    g_h: list
    J_h: list
    s: list
    V: list
    uf: list
    m: int


def hat_model(v, dv, g, R: np.ndarray, qf: np.ndarray, scale_inv, m: int) -> HatModel:
    """The model at an iterate (``cl_scaling_vector`` (v, dv) there, gradient
    g, normal form (R, qf) of m residuals, x_scale='jac''s scale_inv;
    ``trf_bounds`` before its inner loop)."""
    v = scaled_cl_vector(v, dv, scale_inv)
    scale = [1.0 / si for si in scale_inv]
    d = [math.sqrt(vi) * sc for vi, sc in zip(v, scale)]  # scipy's v**0.5, which numpy computes as sqrt
    diag_h = [gi * dvi * sc for gi, dvi, sc in zip(g, dv, scale)]
    J_h = R * np.array(d)
    s, V, uf = augmented_svd(J_h, diag_h, qf)
    return HatModel(d, diag_h, times(d, g), J_h.tolist(), s, V, uf, m)


def augmented_svd(J_h: np.ndarray, diag_h, qf: np.ndarray):
    """(s, V, uf): U diag(s) V^T = [J_h; diag(diag_h)^1/2] and uf = U^T [f; 0]
    (``trf_bounds``; scipy's SVD, LAPACK's gesdd)."""
    k, n = J_h.shape  # k = n but from a QR of fewer than n + 1 residuals
    A = np.zeros((k + n, n))
    A[:k] = J_h
    for i, h in enumerate(diag_h):
        A[k + i, i] = math.sqrt(h)
    U, s, Vt, info = gesdd(A, compute_uv=1, full_matrices=0)
    if info > 0:
        raise np.linalg.LinAlgError("SVD did not converge")
    return s.tolist(), Vt.T.tolist(), (qf @ U[:k]).tolist()  # [f; 0]'s zeros add nothing


def phi_and_derivative(alpha: float, suf, s, Delta: float):
    """|p(alpha)| - Delta and its derivative in alpha (scipy's ``solve_lsq_trust_region.phi_and_derivative``)."""
    denom = [si * si + alpha for si in s]
    p_norm = norm([a / b for a, b in zip(suf, denom)])
    return p_norm - Delta, -sum([a * a / b ** 3 for a, b in zip(suf, denom)]) / p_norm


def solve_lsq_trust_region(n: int, m: int, uf, s, V, Delta: float, initial_alpha: float):
    """(p, alpha): the trust-region step of radius Delta from the SVD
    (More's method on one SVD; scipy's ``solve_lsq_trust_region``, rtol
    and max_iter its defaults)."""
    suf = times(s, uf)
    full_rank = m >= n and s[-1] > EPS * m * s[0]
    if full_rank:
        p = [-pi for pi in matvec(V, [a / b for a, b in zip(uf, s)])]
        if norm(p) <= Delta:
            return p, 0.0
    alpha_upper = norm(suf) / Delta
    alpha_lower = 0.0
    if full_rank:
        phi, phi_prime = phi_and_derivative(0.0, suf, s, Delta)
        alpha_lower = -phi / phi_prime
    if not full_rank and initial_alpha == 0:
        alpha = max(0.001 * alpha_upper, (alpha_lower * alpha_upper) ** 0.5)
    else:
        alpha = initial_alpha
    for _ in range(TR_MAX_ITER):
        if alpha < alpha_lower or alpha > alpha_upper:
            alpha = max(0.001 * alpha_upper, (alpha_lower * alpha_upper) ** 0.5)
        phi, phi_prime = phi_and_derivative(alpha, suf, s, Delta)
        if phi < 0:
            alpha_upper = alpha
        ratio = phi / phi_prime
        alpha_lower = max(alpha_lower, alpha - ratio)
        alpha -= (phi + Delta) * ratio / Delta
        if abs(phi) < TR_RTOL * Delta:
            break
    p = [-pi for pi in matvec(V, [a / (si * si + alpha) for a, si in zip(suf, s)])]
    return scaled(p, Delta / norm(p)), alpha  # on the trust region's boundary exactly


def in_bounds(x, lb, ub) -> bool:
    """Whether lb <= x <= ub (scipy's ``in_bounds``)."""
    return all(lo <= xi <= hi for xi, lo, hi in zip(x, lb, ub))


def step_size_to_bound(x, s, lb, ub):
    """(t, hits): the least t >= 0 with x + t s on a bound, and which
    coordinates reach theirs there (-1 lower, 1 upper; scipy's
    ``step_size_to_bound``, for finite x and s)."""
    steps = [max((lo - xi) / si, (hi - xi) / si) if si != 0 else math.inf for xi, si, lo, hi in zip(x, s, lb, ub)]
    min_step = min(steps)
    return min_step, [(si > 0) - (si < 0) if st == min_step else 0 for st, si in zip(steps, s)]


def intersect_trust_region(x, s, Delta: float):
    """(t_neg, t_pos): where the line x + t s crosses |.| = Delta (scipy's ``intersect_trust_region``)."""
    a = dot(s, s)
    if a == 0:
        raise ValueError("`s` is zero.")
    b = dot(x, s)
    c = dot(x, x) - Delta ** 2
    if c > 0:
        raise ValueError("`x` is not within the trust region.")
    d = math.sqrt(b * b - a * c)
    q = -(b + math.copysign(d, b))  # without cancellation ("Numerical Recipes")
    t1, t2 = q / a, c / q
    return (t1, t2) if t1 < t2 else (t2, t1)


def build_quadratic_1d(J, g, s, diag, s0=None):
    """(a, b) or, given s0, (a, b, c): f(t) = a t^2 + b t + c = 0.5 (s0 +
    s t)^T (J^T J + diag) (s0 + s t) + g^T (s0 + s t) (scipy's ``build_quadratic_1d``)."""
    v = matvec(J, s)
    a = dot(v, v)
    a += dot_diag(s, diag, s)
    a *= 0.5
    b = dot(g, s)
    if s0 is None:
        return a, b
    u = matvec(J, s0)
    b += dot(u, v)
    c = 0.5 * dot(u, u) + dot(g, s0)
    b += dot_diag(s0, diag, s)
    c += 0.5 * dot_diag(s0, diag, s0)
    return a, b, c


def minimize_quadratic_1d(a: float, b: float, lb: float, ub: float, c: float = 0.0):
    """(t, y): the least y = a t^2 + b t + c over lb <= t <= ub, the first
    of lb, ub and the extremum on a tie (scipy's ``minimize_quadratic_1d``)."""
    t = [lb, ub]
    if a != 0:
        extremum = -0.5 * b / a
        if lb < extremum < ub:
            t.append(extremum)
    y = [ti * (a * ti + b) + c for ti in t]
    i = y.index(min(y))
    return t[i], y[i]


def evaluate_quadratic(J, g, s, diag) -> float:
    """0.5 s^T (J^T J + diag) s + g^T s (scipy's ``evaluate_quadratic``)."""
    Js = matvec(J, s)
    q = dot(Js, Js)
    q += dot_diag(s, diag, s)
    return 0.5 * q + dot(s, g)


def select_step(x, J_h, diag_h, g_h, p, p_h, d, *, Delta: float, lb, ub, theta: float):
    """(step, step_h, predicted reduction): the trust-region step p if
    inside the bounds, else the best of it cut back at the bound, its
    reflection there and the scaled gradient's stride (scipy's ``select_step``)."""
    if in_bounds(plus(x, p), lb, ub):
        return p, p_h, -evaluate_quadratic(J_h, g_h, p_h, diag_h)
    p_stride, hits = step_size_to_bound(x, p, lb, ub)
    r_h = [-a if hit else a for a, hit in zip(p_h, hits)]  # the reflected direction
    r = times(d, r_h)
    p, p_h = scaled(p, p_stride), scaled(p_h, p_stride)  # restricted to hit the bound
    _, to_tr = intersect_trust_region(p_h, r_h, Delta)
    to_bound, _ = step_size_to_bound(plus(x, p), r, lb, ub)
    r_stride = min(to_bound, to_tr)  # along the reflection: the bounds' or the trust region's crossing first
    if r_stride > 0:
        r_stride_l = (1 - theta) * p_stride / r_stride
        r_stride_u = theta * to_bound if r_stride == to_bound else to_tr
    else:
        r_stride_l, r_stride_u = 0.0, -1.0
    r_value = math.inf
    if r_stride_l <= r_stride_u:
        a, b, c = build_quadratic_1d(J_h, g_h, r_h, diag_h, s0=p_h)
        r_stride, r_value = minimize_quadratic_1d(a, b, r_stride_l, r_stride_u, c=c)
        r_h = [a * r_stride + b for a, b in zip(r_h, p_h)]
        r = times(r_h, d)
    p, p_h = scaled(p, theta), scaled(p_h, theta)  # strictly inside
    p_value = evaluate_quadratic(J_h, g_h, p_h, diag_h)
    ag_h = [-a for a in g_h]
    ag = times(d, ag_h)
    to_tr = Delta / norm(ag_h)
    to_bound, _ = step_size_to_bound(x, ag, lb, ub)
    ag_stride = theta * to_bound if to_bound < to_tr else to_tr
    a, b = build_quadratic_1d(J_h, g_h, ag_h, diag_h)
    ag_stride, ag_value = minimize_quadratic_1d(a, b, 0.0, ag_stride)
    ag_h, ag = scaled(ag_h, ag_stride), scaled(ag, ag_stride)
    if p_value < r_value and p_value < ag_value:
        return p, p_h, -p_value
    if r_value < p_value and r_value < ag_value:
        return r, r_h, -r_value
    return ag, ag_h, -ag_value


def make_strictly_feasible(x, lb, ub, rstep: float = 1e-10) -> list:
    """x with a coordinate on or near a bound (within rstep of it, relative to
    the bound's size if above 1) moved that far inside, to the next float
    inside for rstep=0, and to the middle where the bounds are closer
    (scipy's ``make_strictly_feasible`` and ``find_active_constraints``)."""
    out = []
    for xi, lo, hi in zip(x, lb, ub):
        if rstep == 0:
            lower, upper = xi <= lo, xi >= hi
        else:
            lower_dist, upper_dist = xi - lo, hi - xi
            lower = math.isfinite(lo) and lower_dist <= min(upper_dist, rstep * max(1.0, abs(lo)))
            upper = math.isfinite(hi) and upper_dist <= min(lower_dist, rstep * max(1.0, abs(hi)))
        if upper:  # the upper bound wins
            xi = math.nextafter(hi, lo) if rstep == 0 else hi - rstep * max(1.0, abs(hi))
        elif lower:
            xi = math.nextafter(lo, hi) if rstep == 0 else lo + rstep * max(1.0, abs(lo))
        out.append(0.5 * (lo + hi) if xi < lo or xi > hi else xi)
    return out


def trial_step(x, model: HatModel, Delta: float, alpha: float, theta: float, lb, ub):
    """One trial of scipy's ``trf_bounds`` inner loop at x in ``model``
    (radius Delta, Levenberg-Marquardt parameter alpha, step back theta
    from the bounds): (x_new, step, step_h, predicted reduction, alpha)."""
    p_h, alpha = solve_lsq_trust_region(len(x), model.m, model.uf, model.s, model.V, Delta, alpha)
    p = times(model.d, p_h)
    step, step_h, predicted_reduction = select_step(x, model.J_h, model.diag_h, model.g_h, p, p_h, model.d,
                                                    Delta=Delta, lb=lb, ub=ub, theta=theta)
    x_new = make_strictly_feasible(plus(x, step), lb, ub, rstep=0)
    return x_new, step, step_h, predicted_reduction, alpha
