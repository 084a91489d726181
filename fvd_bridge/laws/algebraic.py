"""Algebraic laws 1-5 (paper section 2.1-2.5): force from d [mm] and v [mm/s].

Vectorized with numpy broadcasting: parameters (pop, 1) against signals (1, n_t).
"""

from __future__ import annotations

import numpy as np


def viscous(v: np.ndarray, C: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """Generalized viscous force C sign(v) |v|^alpha [kN] (paper eq. 2)."""
    return C * np.sign(v) * np.abs(v) ** alpha


def law1(d, v, dt, P, substeps=1):
    """Linear viscous, F = C v (eq. 1)."""
    return P[:, 0:1] * v[None, :]


def law2(d, v, dt, P, substeps=1):
    """Generalized viscous, F = C sign(v)|v|^alpha (eq. 2)."""
    return viscous(v[None, :], P[:, 0:1], P[:, 1:2])


def law3(d, v, dt, P, substeps=1):
    """Generalized viscous + linear spring, F = K1 d + C sign(v)|v|^alpha (eq. 5)."""
    return P[:, 2:3] * d[None, :] + viscous(v[None, :], P[:, 0:1], P[:, 1:2])


def law4(d, v, dt, P, substeps=1):
    """Generalized viscous + quadratic spring, F = K1 d + K2 d^2 + C sign(v)|v|^alpha (eq. 6).

    As printed: K2 d^2 is even in d (pushes the same way in tension and compression).
    """
    dd = d[None, :]
    return P[:, 2:3] * dd + P[:, 3:4] * dd * dd + viscous(v[None, :], P[:, 0:1], P[:, 1:2])


def law5(d, v, dt, P, substeps=1):
    """Generalized Kelvin-Voigt, F = K sign(d)|d|^beta + C sign(v)|v|^alpha (eq. 7)."""
    return viscous(d[None, :], P[:, 2:3], P[:, 3:4]) + viscous(v[None, :], P[:, 0:1], P[:, 1:2])
