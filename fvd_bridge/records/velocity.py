"""Velocity and acceleration from sampled displacement by a Savitzky-Golay differentiator.

The filter fits a polynomial of order ``polyorder`` to ``window`` samples
around each point by least squares and returns its derivative there (see
savgol.py for the equation). Its settings go into the record's provenance.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from .savgol import savgol_derivative

#: default window [samples] = dominant period / WINDOW_PER_PERIOD, clipped to this range
WINDOW_PER_PERIOD = 25.0
WINDOW_RANGE = (5, 101)


def default_window(d: np.ndarray, dt: float, polyorder: int = 3) -> int:
    """Savitzky-Golay window [samples]: about 1/25 of the dominant period of d, odd, 5..101,
    and at least polyorder + 2."""
    from .cycles import dominant_period

    period = dominant_period(d, dt)
    w = int(round(period / dt / WINDOW_PER_PERIOD)) if np.isfinite(period) else 11
    w = min(max(w, WINDOW_RANGE[0], polyorder + 2), WINDOW_RANGE[1])
    w = w if w % 2 else w + 1
    return min(w, d.size if d.size % 2 else d.size - 1)


def check_settings(window: int | None, polyorder: int, n: int | None = None, where: str = "") -> None:
    """Refuse a window [samples] / order pair the filter cannot use on n samples
    (window None: the order alone; n None: not checked against a record)."""
    if polyorder < 1:
        raise InputError(f"--sg-order {polyorder}: must be at least 1")
    if window is None:
        return
    if window % 2 == 0:
        raise InputError(f"--sg-window {window}: must be odd")
    if window <= polyorder:
        raise InputError(f"--sg-window {window}: must be larger than --sg-order {polyorder}")
    if n is not None and window > n:
        raise InputError(f"{where}--sg-window {window}: larger than the record's {n} samples")


def differentiate(d: np.ndarray, dt: float, window: int | None = None,
                  polyorder: int = 3, where: str = "") -> tuple[np.ndarray, np.ndarray, dict]:
    """Savitzky-Golay first and second derivatives of d [mm] on step dt [s].

    ``where`` prefixes messages (e.g. the file name). Returns v [mm/s],
    a [mm/s^2] and the settings (method, window [samples],
    window_s [s], polyorder), which go into the record's provenance so that a
    fit can be reproduced.
    """
    auto = window is None
    if auto:
        window = default_window(d, dt, polyorder)
    check_settings(window, polyorder, d.size, where)
    v = savgol_derivative(d, window, polyorder, 1, dt)
    a = savgol_derivative(d, window, max(polyorder, 2), 2, dt)
    return v, a, {"method": "savgol", "window": int(window), "window_s": float(window * dt),
                  "polyorder": int(polyorder), "window_chosen": "auto" if auto else "user"}


def acceleration_from_velocity(v: np.ndarray, dt: float, window: int | None = None,
                               polyorder: int = 3, where: str = "") -> tuple[np.ndarray, dict]:
    """Acceleration [mm/s^2] from a measured velocity [mm/s] (Savitzky-Golay, 1st derivative).

    Returns the acceleration and the settings used.
    """
    auto = window is None
    if auto:
        window = default_window(v, dt, polyorder)
    check_settings(window, polyorder, v.size, where)
    a = savgol_derivative(v, window, polyorder, 1, dt)
    return a, {"window": int(window), "window_s": float(window * dt), "polyorder": int(polyorder),
               "window_chosen": "auto" if auto else "user"}
