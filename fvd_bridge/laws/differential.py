"""Differential laws 6-9 (paper sections 2.6-2.9): population drivers.

Each driver integrates z(t) from z = 0 with a fixed step equal to the
sampling step dt (optionally split in ``substeps``), v linear between
samples: P (pop, n_par) -> F (pop, n_t) [kN].  The population is cut into
blocks of members that advance in time together: a block keeps its members'
constants and states in the rows of one work array and applies the updates
of ``steps.py`` lane by lane (SIMD).  Per-member constants are computed once,
before the time loop.  A block is padded with copies of its last member, and
a member's force does not depend on the others.

Each law's kernel integrates a range of blocks; ``_run`` splits a population's
blocks over numba's threads (``numba.get_num_threads()``: one in a campaign's
worker processes), each part a kernel call that releases the GIL.  The kernels
are plain compiled functions, not numba ``prange`` loops: numba's parfor
passes analyse the whole inlined body of a ``prange``, which took 4-5x the
compile time of the kernel itself, for the same speed (the step functions
call nothing that keeps a lane loop scalar, ``fastmath.py``).
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from functools import cache

import numba
import numpy as np
from numba import njit

from .fastmath import FASTMATH, scalar
from .steps import (bouc_wen_constants, bouc_wen_step, law6_bouc_wen, law8_constants, law9_constants, linear_force,
                    lugre_step, maxwell_force, slip_step, split_travel)
from .trbdf2 import (LAM_MIN, NEWTON_MAXIT, law7_constants, maxwell_bdf2_rhs, maxwell_end, maxwell_newton,
                     maxwell_start, maxwell_tr_rhs)

# OpenMP threads busy-wait between parallel regions by default, taking the CPU
# that the GA's own Python code and other processes need; on a busy 2-core
# machine that made the prange kernels (then these, now the algebraic laws')
# up to 10x slower.  Read when numba starts its threads (``_run`` asks their
# number); a user's own setting is kept.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

# Blocks of members integrated together; the width is the length of a tuple,
# so that numba compiles it as a constant, and each width is a kernel compiled
# of its own (two per law).  Populations go 32 members a block (16 for law 7,
# whose Newton steps wait for a block's slowest member); up to NARROW_UPTO
# members go 4 a block (a local search's point and its forward-difference
# neighbours, a polish's single evaluation: about the time of one member
# alone, one SIMD register wide).
LANES_32, LANES_16, LANES_4 = (0.0,) * 32, (0.0,) * 16, (0.0,) * 4
NARROW_UPTO = 12
#: a law's kernel: (d, v, dt, c, substeps, lanes, b0, F) writes F, the rows of the blocks from b0 on
block_kernel = njit(cache=True, nogil=True, fastmath=FASTMATH, error_model="numpy")

# Rows of a block's work array (one value per member): the state, the
# per-member constants (from ``steps.lawN_constants``) and, last, the member's
# parameters as given.  One array allocated in the kernel lets the compiler
# prove the rows apart, so the lane loops are SIMD without run-time checks.
Z, FORCE = 0, 1  # every law: z and the force of the current sample [kN]
A_D, B_Z, C_V, STEP = 2, 3, 4, 5  # laws 6, 8, 9: F = a d + b z + C v; the step's constants from STEP
TRAVEL_PARS = 8  # laws 6, 8, 9: first parameter row
C_PHI, RHS, ABS_R, LAM, LAM1, LAM2, LN_R, E1, E2, INV_G1, DLAM, DONE = range(2, 14)  # law 7 state
LN_C, P, INV_P, LN_K, BETA = range(14, 19)  # law 7 constants
MAXWELL_PARS = 19  # law 7: first parameter row (C, alpha, K, beta)


def _run(kernel, wide, d, v, dt, substeps, *columns):
    """kernel(d, v, dt, c, substeps, lanes, b0, F) on the table c (n_par, n)
    of the members' parameter columns, n padded to whole blocks (up to
    NARROW_UPTO members in blocks of 4, more in blocks of len(wide)) by
    repeating the last member, the blocks split over numba's threads, each
    part writing its rows of F (a population of narrow blocks runs on one
    thread: a thread's start costs more); returns F (pop, n_t) [kN]."""
    table = np.vstack(np.broadcast_arrays(*[np.asarray(col, dtype=float) for col in columns]))
    pop = table.shape[1]
    lanes = LANES_4 if pop <= NARROW_UPTO else wide
    pad = np.repeat(table[:, -1:], -pop % len(lanes), axis=1)
    c = np.ascontiguousarray(np.concatenate([table, pad], axis=1))
    F = np.empty((c.shape[1], d.size))
    n_blocks = c.shape[1] // len(lanes)
    parts = min(numba.get_num_threads(), n_blocks) if lanes is wide else 1
    rows = [n_blocks * k // parts * len(lanes) for k in range(parts + 1)]
    others = [_threads().submit(kernel, d, v, dt, c, substeps, lanes, r0 // len(lanes), F[r0:r1])
              for r0, r1 in zip(rows[1:-1], rows[2:])]
    kernel(d, v, dt, c, substeps, lanes, 0, F[:rows[1]])
    for run in others:
        run.result()
    return F[:pop]


@cache
def _threads() -> ThreadPoolExecutor:
    """The threads that run a population's other parts (the caller runs the first)."""
    return ThreadPoolExecutor(max_workers=max(numba.config.NUMBA_NUM_THREADS - 1, 1),
                              thread_name_prefix="fvd_bridge-kernel")


@scalar
def _work(c, i0, first, lanes):
    """Work array (rows of len(lanes) values) of the block of members from i0,
    its rows from ``first`` on holding their constants (the rows of c), the
    others zero."""
    s = np.zeros((first + c.shape[0], len(lanes)))
    for row in range(c.shape[0]):
        for lane in range(s.shape[1]):
            s[first + row, lane] = c[row, i0 + lane]
    return s


@scalar
def _store(F, k, s, i0):
    """F[i0 + lane, k] = s[FORCE, lane] (a plain loop: a SIMD scatter is slower)."""
    for lane in range(s.shape[1]):
        F[i0 + lane, k] = s[FORCE, lane]


@scalar
def _sub_velocities(v0, v1, j, m):
    """Velocities at the ends of sub-step j of m within one sample step."""
    return v0 + (v1 - v0) * j / m, v0 + (v1 - v0) * (j + 1) / m


# --- laws 6, 8, 9: rate-independent, exact for v linear between samples -----

@njit(inline="always")
def _travel_force(d, v, dt, c, substeps, lanes, b0, F, setup, advance):
    """F = a d + b z + C v [kN] (``steps.linear_force``) of the blocks from b0 on (F's rows),
    the constants set by ``setup(s)`` from the parameters, z from 0 moved by
    ``advance(s, u)`` over each travel u of one sign (a step's travel is
    split where v changes sign).  Inlined into each law's kernel, which fixes
    ``setup`` and ``advance`` (function arguments would defeat numba's cache)."""
    n = d.size
    h = dt / substeps
    for block in range(b0, b0 + F.shape[0] // len(lanes)):
        s = _work(c, block * len(lanes), TRAVEL_PARS, lanes)
        setup(s)
        for k in range(n):
            for j in range(substeps if k > 0 else 0):
                va, vb = _sub_velocities(v[k - 1], v[k], j, substeps)
                for u in split_travel(va, vb, h):
                    if u != 0.0:
                        advance(s, u)
            for lane in range(s.shape[1]):
                s[FORCE, lane] = linear_force(s[A_D, lane], s[B_Z, lane], s[C_V, lane], d[k], s[Z, lane], v[k])
            _store(F, k, s, (block - b0) * len(lanes))


@scalar
def _bouc_wen_setup(s):
    """Each lane's constants from its parameters (C, K, alpha, A, beta, gamma)."""
    q = TRAVEL_PARS
    for lane in range(s.shape[1]):
        (s[A_D, lane], s[B_Z, lane], s[C_V, lane], s[STEP, lane], s[STEP + 1, lane],
         s[STEP + 2, lane]) = bouc_wen_constants(s[q, lane], s[q + 1, lane], s[q + 2, lane], s[q + 3, lane],
                                                 s[q + 4, lane], s[q + 5, lane])


@scalar
def _bouc_wen_advance(s, u):
    for lane in range(s.shape[1]):
        s[Z, lane] = bouc_wen_step(s[Z, lane], u, s[STEP, lane], s[STEP + 1, lane], s[STEP + 2, lane])


@block_kernel
def _bouc_wen_force(d, v, dt, c, substeps, lanes, b0, F):
    _travel_force(d, v, dt, c, substeps, lanes, b0, F, _bouc_wen_setup, _bouc_wen_advance)


def bouc_wen_force(d, v, dt, *, C, K, alpha, A, beta, gamma, substeps=1):
    """Bouc-Wen element (n = 1, ``steps.bouc_wen_step``) + viscous:
    ``steps.bouc_wen_constants`` (paper eq. 8).  Parameters are arrays of
    length pop (or scalars): C [kN/(mm/s)], K [kN/mm], alpha [-], A [-],
    beta and gamma [1/mm].  Returns F (pop, n_t) [kN]."""
    return _run(_bouc_wen_force, LANES_32, d, v, dt, substeps, C, K, alpha, A, beta, gamma)


def law6(d, v, dt, P, substeps=1):
    """Bouc-Wen + viscous with A = n = 1, beta = gamma (``steps.law6_bouc_wen``)."""
    C, K, alpha, A, beta, gamma = law6_bouc_wen.py_func(*P.T)
    return bouc_wen_force(d, v, dt, C=C, K=K, alpha=alpha, A=A, beta=beta, gamma=gamma, substeps=substeps)


@scalar
def _slip_setup(s):
    """Each lane's constants from its parameters (C, K, mu, N)."""
    q = TRAVEL_PARS
    for lane in range(s.shape[1]):
        s[A_D, lane], s[B_Z, lane], s[C_V, lane], s[STEP, lane] = law8_constants(
            s[q, lane], s[q + 1, lane], s[q + 2, lane], s[q + 3, lane])


@scalar
def _slip_advance(s, u):
    for lane in range(s.shape[1]):
        s[Z, lane] = slip_step(s[Z, lane], u, s[STEP, lane])


@block_kernel
def _slip_force(d, v, dt, c, substeps, lanes, b0, F):
    _travel_force(d, v, dt, c, substeps, lanes, b0, F, _slip_setup, _slip_advance)


def law8(d, v, dt, P, substeps=1):
    """Lu unified friction + viscous (``steps.law8_constants``, ``steps.slip_step``)."""
    return _run(_slip_force, LANES_32, d, v, dt, substeps, *P.T)


@scalar
def _lugre_setup(s):
    """Each lane's constants from its parameters (C, alpha, beta)."""
    q = TRAVEL_PARS
    for lane in range(s.shape[1]):
        s[A_D, lane], s[B_Z, lane], s[C_V, lane], s[STEP, lane] = law9_constants(
            s[q, lane], s[q + 1, lane], s[q + 2, lane])


@scalar
def _lugre_advance(s, u):
    for lane in range(s.shape[1]):
        s[Z, lane] = lugre_step(s[Z, lane], u, s[STEP, lane])


@block_kernel
def _lugre_force(d, v, dt, c, substeps, lanes, b0, F):
    _travel_force(d, v, dt, c, substeps, lanes, b0, F, _lugre_setup, _lugre_advance)


def law9(d, v, dt, P, substeps=1):
    """LuGre with eps = K = F0 = 0 (``steps.law9_constants``, ``steps.lugre_step``)."""
    return _run(_lugre_force, LANES_32, d, v, dt, substeps, *P.T)


# --- law 7: TR-BDF2 (steps.py) -------------------------------------------------

@scalar
def _maxwell_start(s, lane, r):
    """Start the solve of x + c sign(x)|x|^p = r in one lane (``steps.maxwell_start``)."""
    s[LAM, lane], s[LN_R, lane], s[ABS_R, lane] = maxwell_start(
        r, s[ABS_R, lane], s[LAM, lane], s[LAM1, lane], s[LAM2, lane], s[LN_R, lane], s[LN_C, lane], s[INV_P, lane])
    s[RHS, lane], s[DONE, lane] = r, 0.0


@scalar
def _maxwell_newton(s):
    """Newton steps (``steps.maxwell_newton``) until every lane has converged,
    at most 1 + NEWTON_MAXIT; a lane that has stays put, so its result does
    not depend on the others."""
    for _ in range(1 + NEWTON_MAXIT):
        moving = 0  # an integer 'or' over the lanes, which compiles to SIMD
        for lane in range(s.shape[1]):
            moving |= np.int64(s[DONE, lane] == 0.0)
        if moving == 0:
            return
        for lane in range(s.shape[1]):
            lam, e1, e2, inv_g1, done = maxwell_newton(s[LAM, lane], s[ABS_R, lane], s[LN_C, lane], s[P, lane])
            live = s[DONE, lane] == 0.0
            s[DLAM, lane] = lam - s[LAM, lane] if live else s[DLAM, lane]
            s[E1, lane] = e1 if live else s[E1, lane]
            s[E2, lane] = e2 if live else s[E2, lane]
            s[INV_G1, lane] = inv_g1 if live else s[INV_G1, lane]
            s[LAM, lane] = lam if live else s[LAM, lane]
            s[DONE, lane] = done if live else 1.0


@scalar
def _maxwell_end(s, lane):
    """Root of the lane's solve (``steps.maxwell_end``), keeping the slopes
    for the next start."""
    x, s[LAM1, lane], s[LAM2, lane] = maxwell_end(s[RHS, lane], s[E1, lane], s[E2, lane], s[INV_G1, lane],
                                                  s[DLAM, lane], s[P, lane])
    return x


@block_kernel
def _maxwell_force(d, v, dt, c, substeps, lanes, b0, F):
    """Law 7 for the blocks from b0 on of the parameter table c (rows C,
    alpha, K, beta), into F (their rows, n_t) [kN].  Constants (``steps.law7_constants``): ln c, p, 1/p, ln K,
    beta.  State rows: z, c phi(z) = r - z, and of the last solve its right
    side r, |r|, a coarse ln|r|, ln|x|, the slopes of ln|x|(ln|r|) and the
    last Newton evaluation (e1, e2, 1/(e1 + p e2), step, converged).  Each solve step appears
    once in the code (a loop over the two stages; a solve's root is taken at
    the start of the next one; every Newton step, the first too, in
    ``_maxwell_newton``): numba inlines each appearance anew, and its compile
    time grows with them."""
    n = d.size
    h = dt / substeps
    for block in range(b0, b0 + F.shape[0] // len(lanes)):
        s = _work(c, block * len(lanes), MAXWELL_PARS, lanes)
        q = MAXWELL_PARS
        for lane in range(s.shape[1]):
            s[LN_C, lane], s[P, lane], s[INV_P, lane], s[LN_K, lane], s[BETA, lane] = law7_constants(
                s[q, lane], s[q + 1, lane], s[q + 2, lane], s[q + 3, lane], h)
        # as after solving r = 0: x = e^LAM_MIN (0 to 1e-304), neutral slopes
        s[LAM], s[LAM1], s[LN_R], s[E1], s[INV_G1] = LAM_MIN, 1.0, LAM_MIN, np.exp(LAM_MIN), np.exp(-LAM_MIN)
        for k in range(n):
            for j in range(substeps if k > 0 else 0):
                va, vb = _sub_velocities(v[k - 1], v[k], j, substeps)
                for stage in range(2):  # trapezoidal to t + gamma h, then BDF2 to t + h
                    for lane in range(s.shape[1]):
                        x = _maxwell_end(s, lane)  # root of the previous solve
                        if stage == 0:  # that was z at the start of the step
                            s[Z, lane], s[C_PHI, lane] = x, s[RHS, lane] - x
                        r = (maxwell_tr_rhs(s[Z, lane], s[C_PHI, lane], va, vb, h) if stage == 0
                             else maxwell_bdf2_rhs(x, s[Z, lane], vb, h))
                        _maxwell_start(s, lane, r)
                    _maxwell_newton(s)
            for lane in range(s.shape[1]):  # z has the sign of r and ln|z| = lam
                s[FORCE, lane] = maxwell_force(s[RHS, lane], s[LAM, lane], s[LN_K, lane], s[BETA, lane])
            _store(F, k, s, (block - b0) * len(lanes))


def law7(d, v, dt, P, substeps=1):
    """Lu unified visco-elastic: F = K sign(z)|z|^beta (eqs. 10-11), z the spring deformation."""
    return _run(_maxwell_force, LANES_16, d, v, dt, substeps, *P.T)
