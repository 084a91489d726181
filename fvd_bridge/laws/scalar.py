"""The laws for one member, step by step: the reference for the FMU's C code.

The FMU's C code mirrors this module function for function: a member's
constants (``law_constants``), its state at rest (``new_state``), one
sub-step (``advance``) and the force of a sample (``force``); ``history``
loops them exactly as the population drivers do (``algebraic.py``,
``differential.py``).  Every equation is one of ``steps.py`` or
``trbdf2.py``, called here with plain loops over one member (no SIMD lanes);
tests/laws/test_scalar_laws.py checks the histories against the population
drivers (to 1e-12 of the peak force; laws 2 and 5-9 agree bit for bit, laws
1, 3, 4 to rounding, their drivers being ``F = C v`` and fastmath=True); a
law declared without a population kernel runs ``history`` per member
(``members``).
Units: kN, mm, s.

Constants k (``law_constants``) by law code:
  1-5: (C, alpha, K1, K2, K, beta) of the general algebraic law (``steps.algebraic_form``);
  6: (a, b, C, A, beta, gamma) (``steps.bouc_wen_constants``); 8: (a, b, C, k); 9: (a, b, C, alpha);
  7: (ln c, p, 1/p, ln K, beta) (``trbdf2.law7_constants``); 10: (K, C, Fr, p).
State (``new_state``): none for laws 1-5; (z,) for laws 6, 8, 9; (F,) for law
10 (its spring force, ``oil.py``); for law 7 the
rows of a ``differential._maxwell_force`` lane, indexed by the names below.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from .differential import _sub_velocities
from .fastmath import FASTMATH, scalar
from .oil import oil_step
from .steps import (algebraic_force, algebraic_form, bouc_wen_constants, bouc_wen_step, law6_bouc_wen,
                    law8_constants, law9_constants, linear_force, lugre_step, maxwell_force, sign_log, slip_step,
                    split_travel)
from .trbdf2 import (LAM_MIN, NEWTON_MAXIT, law7_constants, maxwell_bdf2_rhs, maxwell_end, maxwell_newton,
                     maxwell_start, maxwell_tr_rhs)

# the public functions; the helpers are inlined (``fastmath.scalar``) as in the
# drivers, so that LLVM fuses the same multiply-adds ('contract') and law 7
# agrees bit for bit (called, not inlined, it differs by ~1e-15 of the peak)
one_member = njit(cache=True, fastmath=FASTMATH, error_model="numpy")

Z = 0  # laws 6-9: the internal variable z (law 7: the spring deformation at the start of the step) [mm]; law 10: F [kN]
# law 7 state: c phi(z) = r - z, and of the last solve: r, |r|, coarse ln|r|, ln|x|, slopes of ln|x|(ln|r|),
# the last Newton evaluation (e1, e2, 1/(e1 + p e2), step) and whether it converged (1.0) or not (0.0)
C_PHI, RHS, ABS_R, LAM, LAM1, LAM2, LN_R, E1, E2, INV_G1, DLAM, DONE = range(1, 13)
LN_C, P, INV_P, LN_K, BETA = range(5)  # law 7 constants
STEP = 3  # laws 6, 8, 9: first constant of the step (after a, b, C)


@one_member
def law_constants(code, p, h):
    """Constants of law ``code`` (1-9) for parameters p (law order, paper
    units) and a sub-step h [s] (used by law 7 only)."""
    if code <= 5:
        return np.array(algebraic_form(code, p))
    if code == 6:
        C, K, alpha, A, beta, gamma = law6_bouc_wen(p[0], p[1], p[2], p[3])
        return np.array(bouc_wen_constants(C, K, alpha, A, beta, gamma))
    if code == 7:
        return np.array(law7_constants(p[0], p[1], p[2], p[3], h))
    if code == 8:
        return np.array(law8_constants(p[0], p[1], p[2], p[3]))
    if code == 10:
        return np.array((p[0], p[1], p[2], p[3]))
    return np.array(law9_constants(p[0], p[1], p[2]))


@one_member
def new_state(code):
    """State at rest: z = 0; law 7 as after solving r = 0 (x = e^LAM_MIN,
    0 to 1e-304, neutral slopes), as ``differential._maxwell_force`` starts a lane."""
    if code <= 5:
        return np.zeros(0)
    if code != 7:
        return np.zeros(1)
    s = np.zeros(DONE + 1)
    s[LAM], s[LAM1], s[LN_R], s[E1], s[INV_G1] = LAM_MIN, 1.0, LAM_MIN, math.exp(LAM_MIN), math.exp(-LAM_MIN)
    return s


@scalar
def _travel_step(code, k, z, u):
    """z after a travel u [mm] of one sign: laws 6, 8, 9's exact steps."""
    if code == 6:
        return bouc_wen_step(z, u, k[STEP], k[STEP + 1], k[STEP + 2])
    if code == 8:
        return slip_step(z, u, k[STEP])
    return lugre_step(z, u, k[STEP])


@scalar
def _maxwell_solve(k, s, r):
    """Solve x + c sign(x)|x|^p = r (law 7's stage): start from the previous
    solve (``trbdf2.maxwell_start``), Newton steps until converged (at most
    1 + NEWTON_MAXIT); as ``differential._maxwell_start`` and ``_maxwell_newton``."""
    lam0, s[LN_R], R = maxwell_start(r, s[ABS_R], s[LAM], s[LAM1], s[LAM2], s[LN_R], k[LN_C], k[INV_P])
    lam, s[E1], s[E2], s[INV_G1], done = maxwell_newton(lam0, R, k[LN_C], k[P])
    s[RHS], s[ABS_R], s[LAM], s[DLAM], s[DONE] = r, R, lam, lam - lam0, done
    for _ in range(NEWTON_MAXIT):
        if s[DONE] != 0.0:
            return
        lam, s[E1], s[E2], s[INV_G1], done = maxwell_newton(s[LAM], s[ABS_R], k[LN_C], k[P])
        s[DLAM], s[LAM], s[DONE] = lam - s[LAM], lam, done


@scalar
def _maxwell_root(k, s):
    """Root of the last solve (``trbdf2.maxwell_end``), keeping its slopes
    for the next start; as ``differential._maxwell_end``."""
    x, s[LAM1], s[LAM2] = maxwell_end(s[RHS], s[E1], s[E2], s[INV_G1], s[DLAM], k[P])
    return x


@one_member
def advance(code, k, s, va, vb, h):
    """One sub-step of h [s], v linear from va to vb [mm/s]: update the state
    s in place.  Laws 6, 8, 9: the travel split where v changes sign
    (``steps.split_travel``), each nonzero part by the law's exact step;
    law 7: TR-BDF2, a trapezoidal stage to t + gamma h then a BDF2 stage to
    t + h (``trbdf2.py``); laws 1-5 have no state."""
    if code == 7:
        for stage in range(2):  # trapezoidal to t + gamma h, then BDF2 to t + h
            x = _maxwell_root(k, s)  # root of the previous solve
            if stage == 0:  # that was z at the start of the step
                s[Z], s[C_PHI] = x, s[RHS] - x
            r = maxwell_tr_rhs(s[Z], s[C_PHI], va, vb, h) if stage == 0 else maxwell_bdf2_rhs(x, s[Z], vb, h)
            _maxwell_solve(k, s, r)
    elif code == 10:
        s[Z] = oil_step(k[0], k[1], k[2], k[3], s[Z], va, vb, h)
    elif code >= 6:
        for u in split_travel(va, vb, h):
            if u != 0.0:
                s[Z] = _travel_step(code, k, s[Z], u)


@one_member
def force(code, k, s, d, v):
    """Force [kN] at displacement d [mm] and velocity v [mm/s] with the state s:
    ``steps.algebraic_force`` (1-5), ``steps.maxwell_force`` (7, z of the sign
    of the last r and ln|z| = lam), ``steps.linear_force`` (6, 8, 9)."""
    if code <= 5:
        sign_v, log_v = sign_log(v)
        sign_d, log_d = sign_log(d)
        return algebraic_force(k[0], k[1], k[2], k[3], k[4], k[5], d, sign_v, log_v, sign_d, log_d)
    if code == 7:
        return maxwell_force(s[RHS], s[LAM], k[LN_K], k[BETA])
    if code == 10:
        return s[Z]
    return linear_force(k[0], k[1], k[2], d, s[Z], v)


@one_member
def history(code, p, d, v, dt, substeps=1):
    """Force history [kN] of one member of law ``code`` with parameters p for
    d [mm], v [mm/s] sampled every dt [s], from rest, each sample step cut in
    ``substeps`` sub-steps with v linear between samples."""
    h = dt / substeps
    k, s = law_constants(code, p, h), new_state(code)
    F = np.empty(d.size)
    for i in range(d.size):
        for j in range(substeps if i > 0 else 0):
            va, vb = _sub_velocities(v[i - 1], v[i], j, substeps)
            advance(code, k, s, va, vb, h)
        F[i] = force(code, k, s, d[i], v[i])
    return F


@njit(parallel=True, cache=True)
def members(code, d, v, dt, P, substeps):
    """Population driver of a law without a vectorized kernel of its own:
    ``history`` for each parameter row of P (pop, n_par), in parallel (numba
    prange) -> F (pop, n_t) [kN]."""
    F = np.empty((P.shape[0], d.size))
    for i in prange(P.shape[0]):
        F[i] = history(code, P[i], d, v, dt, substeps)
    return F
