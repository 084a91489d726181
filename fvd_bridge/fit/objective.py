"""The paper's objective function (eq. 18) and its noise floor."""

from __future__ import annotations

import numpy as np

#: an OF within this many times the noise floor: the model explains the record down to its noise
AT_FLOOR = 1.5
#: within this many: close to the noise, little left to explain (the floor's
#: input-noise part is an estimate); beyond it the model misses part of the record
NEAR_FLOOR = 3.0
#: an OF beyond this: the model explains little of the force, whatever the
#: floor (a force of zero gives mean|F|/std(F), 2 sqrt(2)/pi = 0.90 on a
#: sine; a model of half the force, 0.45): swapped columns, wrong units or sign, a wrong law
EXPLAINS_LITTLE = 0.5


def objective_weights(F_measured: np.ndarray, t: np.ndarray, mask: np.ndarray | None = None) -> np.ndarray:
    """c (n_t,) with OF = sum |p_m - p_e| c: eq. 18's trapezoidal weights
    over sigma_pm (t_end - t_start); with a boolean ``mask`` the weights
    (np.gradient's) of the masked samples over sigma_pm of their forces and
    their sum."""
    if mask is not None:
        w = np.gradient(t) * mask
        return w / (np.std(F_measured[mask]) * w.sum())
    w = np.zeros_like(t, dtype=float)
    w[:-1] += 0.5 * np.diff(t)
    w[1:] += 0.5 * np.diff(t)
    return w / (np.std(F_measured) * (t[-1] - t[0]))


def objective(F_measured: np.ndarray, F_model: np.ndarray, t: np.ndarray, mask: np.ndarray | None = None):
    """OF = 1 / (sigma_pm (t_end - t_start)) * integral |p_m - p_e| dt  (paper eq. 18).

    sigma_pm is the standard deviation of the measured force [kN]; the
    integral is the trapezoidal rule on the record's time grid
    (``objective_weights``).  F_model may be (n_t,) or (pop, n_t); returns a
    float or an array (pop,).  With a boolean ``mask`` (n_t,) the OF of the
    masked samples only.
    """
    return np.abs(np.asarray(F_model) - F_measured) @ objective_weights(F_measured, t, mask)


def mean_abs_noise(noise_std: float) -> float:
    """E|e| [kN] of Gaussian force noise e of std ``noise_std`` [kN]: s sqrt(2/pi)."""
    return float(noise_std * np.sqrt(2.0 / np.pi))


def noise_floor(noise_std: float, F_measured: np.ndarray) -> float:
    """Expected OF of the exact model under white force noise of std ``noise_std`` [kN]:
    OF_floor = E|e| / std(F) = s sqrt(2/pi) / std(F)."""
    return float(mean_abs_noise(noise_std) / np.std(F_measured))
