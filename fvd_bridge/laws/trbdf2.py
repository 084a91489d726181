"""Law 7 (Lu visco-elastic) integrated by TR-BDF2: the stage equation and
its Newton solver on ln|x|.

numba's cache does not notice an edit here in the drivers that inline these
functions (``differential.py``, ``effects``): clear NUMBA_CACHE_DIR after one.
"""

from __future__ import annotations

import math

from .fastmath import COARSE_LOG_ERROR, LN2_HI, coarse_log, fmax, fmin, horner, scalar, vexp, vlog
from .steps import maxwell_log_rate

# --- law 7: Lu visco-elastic spring deformation, TR-BDF2 ------------------
#
# dz/dt = v - q sign(z)|z|^p,  q = (K/C)^(1/alpha), p = beta/alpha (paper eq. 11).
# TR-BDF2 (Bank et al. 1985) with gamma = 2 - sqrt(2): a trapezoidal stage to
# t + gamma h, then a BDF2 stage to t + h; second order and L-stable, so the
# stiff members of a population (q h >> 1) neither ring nor blow up.  For
# this gamma both stages solve
#     x + c sign(x)|x|^p = r,   c = gamma h q / 2,
# which has one root, of the sign of r.  It is solved for lam = ln|x| by
# Newton's method on f(lam) = ln(e^lam + c e^(p lam)) - ln|r|, convex with a
# slope between min(1, p) and max(1, p); c enters only as ln c, so no
# stiffness overflows.  Each solve starts from a second-order Taylor
# prediction off the previous solve (lam as a function of ln|r|), clipped to
# the bracket of the root: one Newton step then usually meets the tolerance.

TRBDF2_GAMMA = 2.0 - math.sqrt(2.0)
LAM_MIN = -700.0  # ln|x| floor: |x| < 1e-304 mm counts as 0
R_MIN = 1e-300  # |r| floor [mm]
DEN_MIN = 1e-280  # a Newton step's denominator below this: at rest, no step (its reciprocal would overflow)
NEWTON_TOL = 1e-10  # a solve stops once the error estimate of ln|x| is below
NEWTON_MAXIT = 50


@scalar
def law7_constants(C, alpha, K, beta, h):
    """Constants of the TR-BDF2 solves over a step h [s]: (ln c, p, 1/p, ln K,
    beta), c = gamma h q/2, p = beta/alpha."""
    p = beta / alpha
    return (math.log(0.5 * TRBDF2_GAMMA * h) + maxwell_log_rate(C, alpha, K), p, 1.0 / p,
            vlog(fmax(K, 1e-300)), beta)


@scalar
def maxwell_tr_rhs(z, c_phi, v0, v1, h):
    """Right side r of the trapezoidal stage: z + (gamma h/2)(v0 + v_gamma) - c phi(z),
    v_gamma = v0 + gamma (v1 - v0) (v linear over the step h [s] from v0 to v1
    [mm/s]); c phi(z) is carried from the previous solve (c phi(x) = r - x)."""
    g = TRBDF2_GAMMA
    return z + 0.5 * g * h * (2.0 * v0 + g * (v1 - v0)) - c_phi


@scalar
def maxwell_bdf2_rhs(z_gamma, z, v1, h):
    """Right side r of the BDF2 stage: (z_gamma - (1-gamma)^2 z)/(gamma (2-gamma))
    + (gamma h/2) v1, v1 the velocity at the end of the step [mm/s]."""
    g = TRBDF2_GAMMA
    return (z_gamma - (1.0 - g) * (1.0 - g) * z) / (g * (2.0 - g)) + 0.5 * g * h * v1


@scalar
def maxwell_start(r, R_prev, lam, lam1, lam2, ln_r_prev, ln_c, inv_p):
    """Start of the solve of x + c sign(x)|x|^p = r: lam + lam1 dl + lam2 dl^2,
    dl = ln(R/R_prev) the change of R = |r| since the previous solve (lam,
    lam1, lam2: its root and the derivatives of lam(ln R) there), clipped to
    the bracket [min(ln(R/2), (ln(R/2) - ln c)/p), min(ln R, (ln R - ln c)/p)]
    of the root, widened by COARSE_LOG_ERROR.  dl = 2 atanh(t),
    t = (R - R_prev)/(R + R_prev), by its series to t^7 where |t| < 0.1 (error
    < 3e-10), else the difference of coarse logs (the bracket then decides).
    Returns (lam0, coarse ln R, R); R is floored at R_MIN."""
    R = fmax(abs(r), R_MIN)
    ln_r = coarse_log(R)
    t = (R - R_prev) / (R + R_prev)
    near = abs(t) < 0.1
    tn = t if near else 0.0
    dl = 2.0 * tn * horner(tn * tn, (1.0 / 7.0, 0.2, 1.0 / 3.0, 1.0)) if near else ln_r - ln_r_prev
    upper = fmin(ln_r, (ln_r - ln_c) * inv_p) + COARSE_LOG_ERROR
    lower = fmin(ln_r - LN2_HI, (ln_r - LN2_HI - ln_c) * inv_p) - COARSE_LOG_ERROR
    return fmax(fmin(fmax(lam + dl * (lam1 + lam2 * dl), lower), upper), LAM_MIN), ln_r, R


@scalar
def maxwell_newton(lam, R, ln_c, p):
    """One Newton step on f(lam) = ln(S/R), S = e1 + e2, e1 = e^lam,
    e2 = c e^(p lam), f' = (e1 + p e2)/S, with ln(S/R) replaced by
    2 (S - R)/(S + R) (same root and slope there, and a shorter step, so the
    iterates stay on the convex side).  The error left after a step d is
    about (f''/2f') d^2 + |d|^3/12 (the second term from the replacement),
    f'' = e1 e2 (p - 1)^2/S^2.  Returns (new lam, e1, e2, 1/(e1 + p e2),
    converged): whether that error is below NEWTON_TOL (or the step was
    stopped at LAM_MIN)."""
    e1 = vexp(lam)
    e2 = vexp(ln_c + p * lam)
    s = e1 + e2
    g1 = e1 + p * e2
    den = (s + R) * g1
    # at rest (|r| ~ 1e-304) the terms underflow: the root is 0 to machine precision; stay, slopes 0
    inv = 1.0 / den if den > DEN_MIN else 0.0
    new = fmax(lam - 2.0 * s * (s - R) * inv, LAM_MIN)
    d = abs(new - lam)
    converged = e1 * e2 * ((p - 1.0) * (p - 1.0)) * d * d <= (2.0 * NEWTON_TOL - d * d * d / 6.0) * s * g1
    return new, e1, e2, (s + R) * inv, converged


@scalar
def maxwell_end(r, e1, e2, inv_g1, dlam, p):
    """Root x = sign(r) e^lam from the last Newton evaluation (e1 = e^(lam - dlam),
    e2, inv_g1 = 1/(e1 + p e2)) and the step dlam taken from it (e^dlam to
    second order); and the derivatives of lam(ln R) there, lam1 = 1/f' and
    lam2 = -f''/(2 f'^3), f'' = e1 e2 (p - 1)^2/S^2.  Returns (x, lam1, lam2)."""
    s = e1 + e2
    lam1 = s * inv_g1
    # as three bounded ratios (e1/g1, e2/g1, S/g1): a root near 0 (a solve of r = 0, at rest)
    # makes g1 ~ 1e-300, where inv_g1 cubed alone would overflow and give lam2 = NaN
    lam2 = -0.5 * (e1 * inv_g1) * (e2 * inv_g1) * ((p - 1.0) * (p - 1.0)) * (s * inv_g1)
    return math.copysign(e1 * (1.0 + dlam * (1.0 + 0.5 * dlam)), r), lam1, lam2


@scalar
def maxwell_solve(r, ln_c, p):
    """Root x of x + c sign(x)|x|^p = r without a previous solve to start from
    (scalar code): Newton (``maxwell_newton``) from the upper end of the
    bracket, where the iterates approach the root from one side."""
    R = fmax(abs(r), R_MIN)
    ln_r = vlog(R)
    lam = fmax(fmin(ln_r, (ln_r - ln_c) / p), LAM_MIN)
    e1, e2, inv_g1, dlam = 0.0, 0.0, 1.0, 0.0
    for _ in range(NEWTON_MAXIT):
        new, e1, e2, inv_g1, done = maxwell_newton(lam, R, ln_c, p)
        dlam, lam = new - lam, new
        if done:
            break
    return maxwell_end(r, e1, e2, inv_g1, dlam, p)[0] if r != 0.0 else 0.0


