"""Velocity and acceleration from sampled displacement by a smoothing differentiator."""

from __future__ import annotations

import numpy as np
from scipy.signal import savgol_filter

from ..errors import InputError


def default_window(d: np.ndarray, dt: float) -> int:
    """Savitzky-Golay window [samples]: about 1/25 of the dominant period, odd, 5..101."""
    from .cycles import dominant_period

    period = dominant_period(d, dt)
    w = int(round(period / dt / 25.0)) if np.isfinite(period) else 11
    w = min(max(w, 5), 101)
    return w if w % 2 else w + 1


def differentiate(d: np.ndarray, dt: float, window: int | None = None,
                  polyorder: int = 3) -> tuple[np.ndarray, np.ndarray, dict]:
    """Savitzky-Golay first and second derivatives of d [mm] on step dt [s].

    Returns v [mm/s], a [mm/s^2] and the settings, which go into the record's
    provenance so that a fit can be reproduced.
    """
    if window is None:
        window = default_window(d, dt)
    if window % 2 == 0 or window <= polyorder or window > d.size:
        raise InputError(f"--sg-window {window}: must be odd, larger than --sg-order {polyorder} "
                         f"and at most the number of samples ({d.size})")
    v = savgol_filter(d, window, polyorder, deriv=1, delta=dt, mode="interp")
    a = savgol_filter(d, window, max(polyorder, 2), deriv=2, delta=dt, mode="interp")
    return v, a, {"method": "savgol", "window": int(window), "polyorder": int(polyorder)}


def acceleration_from_velocity(v: np.ndarray, dt: float, window: int | None = None,
                               polyorder: int = 3) -> np.ndarray:
    """Acceleration [mm/s^2] from a measured velocity [mm/s]."""
    w = window or 11
    w = min(w if w % 2 else w + 1, v.size - (1 - v.size % 2))
    return savgol_filter(v, w, min(polyorder, w - 1), deriv=1, delta=dt, mode="interp")
