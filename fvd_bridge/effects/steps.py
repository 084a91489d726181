"""The effects' stateless equations and heating as scalar functions, and
their population drivers.

Each equation is written once, as a scalar function of plain arithmetic that
ports line by line to C (the FMU, ``fmu/effects.c``): the asymmetry factor,
the friction term, the heat factor and energy; ``catalog.py`` applies them
to whole arrays (numba ufuncs of the same functions), ``scalar.py`` composes
them for one member, sample by sample, and the connection (``connection.py``)
solves them inside its implicit step.  Units: kN, mm, s.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange, vectorize


#: smoothing velocity of the friction term [mm/s] (fixed, not fitted)
FRICTION_V_F = 1.0
#: J (kN mm) -> MJ
J_TO_MJ = 1e-6


# ------------------------------------------------ stateless terms (scalar + ufunc)
@njit(cache=True)
def asymmetry_factor(F, r):
    """Tension/compression asymmetry: 1 + r where the law force F > 0 (tension),
    1 - r where F < 0 (compression), 1 at F = 0."""
    return 1.0 + r if F > 0.0 else (1.0 - r if F < 0.0 else 1.0)


@njit(cache=True)
def friction_term(Ff, u):
    """Seal friction Ff tanh(u / v_f) [kN], u [mm/s], v_f = FRICTION_V_F."""
    return Ff * math.tanh(u / FRICTION_V_F)


@njit(cache=True)
def heat_factor(theta, W0):
    """Heating hf = exp(-theta E) = 1 / (1 + theta W0), theta [1/MJ], W0 [MJ]
    the energy the unsoftened law would have dissipated (``thermal_population``)."""
    return 1.0 / (1.0 + theta * W0)


@njit(cache=True)
def parallel_spring(Kp, F0, x):
    """Accumulator (gas spring) and preload: Kp x + F0 [kN], Kp [kN/mm], F0 [kN], x [mm]."""
    return Kp * x + F0


@njit(cache=True)
def inertia_term(m, xa):
    """Moving mass: m xa 1e-6 [kN], m [kg], xa [mm/s^2] (1 kg mm/s^2 = 1e-6 kN)."""
    return m * 1e-6 * xa


asymmetry_factors = vectorize(["float64(float64, float64)"], cache=True)(asymmetry_factor)
friction_terms = vectorize(["float64(float64, float64)"], cache=True)(friction_term)
parallel_springs = vectorize(["float64(float64, float64, float64)"], cache=True)(parallel_spring)
inertia_terms = vectorize(["float64(float64, float64)"], cache=True)(inertia_term)


# ----------------------------------------------------------- thermal softening
@njit(cache=True)
def heat_energy(W0, p0, p1, dt):
    """W0 [MJ] after a sample step dt [s] in which the power F xv went from p0
    to p1 [kN mm/s]: the trapezoidal rule, 1 kN mm = 1e-6 MJ."""
    return W0 + 0.5 * dt * (p0 + p1) * J_TO_MJ


@njit(parallel=True, cache=True)
def thermal_population(F, xv, dt, theta):
    """Heating: F / (1 + theta W0(t)) for each row, W0 [MJ] = 1e-6 integral
    F xv dt (trapezoidal rule) with F [kN] the unsoftened force and xv [mm/s]
    the law's velocity; F (pop, n_t), xv (pop or 1, n_t), theta (pop,) [1/MJ].

    This is F exp(-theta E) with E = 1e-6 integral of the *softened* force
    times xv: dE/dt = exp(-theta E) dW0/dt integrates to
    exp(theta E) = 1 + theta W0."""
    pop, n = F.shape
    out = np.empty((pop, n))
    rows = np.zeros(pop, np.int64) if xv.shape[0] == 1 else np.arange(pop)
    for i in prange(pop):
        r = rows[i]
        W = 0.0
        out[i, 0] = F[i, 0]
        p_prev = F[i, 0] * xv[r, 0]
        for k in range(1, n):
            p = F[i, k] * xv[r, k]
            W = heat_energy(W, p_prev, p, dt)
            out[i, k] = F[i, k] * heat_factor(theta[i], W)
            p_prev = p
    return out
