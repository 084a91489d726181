"""The paper's objective function (eq. 18) and its noise floor."""

from __future__ import annotations

import numpy as np


def objective(F_measured: np.ndarray, F_model: np.ndarray, t: np.ndarray, mask: np.ndarray | None = None):
    """OF = 1 / (sigma_pm (t_end - t_start)) * integral |p_m - p_e| dt  (paper eq. 18).

    sigma_pm is the standard deviation of the measured force [kN]; the
    integral is the trapezoidal rule on the record's time grid.  F_model may
    be (n_t,) or (pop, n_t); returns a float or an array (pop,).  With a
    boolean ``mask`` (n_t,) the OF of the masked samples only: the
    trapezoidal weights of those samples, sigma_pm of their forces.
    """
    err = np.abs(np.asarray(F_model) - F_measured)
    if mask is not None:
        w = np.gradient(t) * mask  # trapezoidal weights (dt/2 at the ends), masked
        return (err @ w) / (np.std(F_measured[mask]) * w.sum())
    integral = np.trapezoid(err, t, axis=-1)
    return integral / (np.std(F_measured) * (t[-1] - t[0]))


def mean_abs_noise(noise_std: float) -> float:
    """E|e| [kN] of Gaussian force noise e of std ``noise_std`` [kN]: s sqrt(2/pi)."""
    return float(noise_std * np.sqrt(2.0 / np.pi))


def noise_floor(noise_std: float, F_measured: np.ndarray) -> float:
    """Expected OF of the exact model under white force noise of std ``noise_std`` [kN]:
    OF_floor = E|e| / std(F) = s sqrt(2/pi) / std(F)."""
    return float(mean_abs_noise(noise_std) / np.std(F_measured))
