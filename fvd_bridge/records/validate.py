"""Checks that turn a bad record into a one-line message naming file, row and column."""

from __future__ import annotations

import warnings

import numpy as np

from ..errors import InputError
from .cycles import count_cycles

#: relative deviation of a time step from the median step that is tolerated
#: by resampling onto a uniform grid (beyond it the record is refused)
TIME_STEP_TOLERANCE = 0.10
#: jitter below this is round-off in the stored times, not irregular sampling
TIME_STEP_JITTER = 1e-6
#: peaks beyond these are absurd for a damper in kN, mm, s: a unit is wrong
ABSURD = {"F": 5.0e4, "d": 5.0e3, "v": 5.0e4}


def check_finite(where: str, name: str, x: np.ndarray, row0: int) -> None:
    """Refuse NaN/inf; ``row0`` is the file row of the first sample."""
    bad = np.flatnonzero(~np.isfinite(x))
    if bad.size:
        raise InputError(f"{where}: row {row0 + bad[0]}, column '{name}': value {x[bad[0]]} is not finite")


def check_time(where: str, name: str, t: np.ndarray, row0: int) -> bool:
    """Refuse time that does not increase or is irregular beyond tolerance.

    Returns True when the step is irregular within tolerance (resample).
    """
    steps = np.diff(t)
    bad = np.flatnonzero(steps <= 0)
    if bad.size:
        i = bad[0] + 1
        raise InputError(f"{where}: row {row0 + i}, column '{name}': time {t[i]:g} s does not "
                         f"increase (previous {t[i - 1]:g} s)")
    h = float(np.median(steps))
    dev = np.abs(steps - h) / h
    worst = int(np.argmax(dev))
    if dev[worst] > TIME_STEP_TOLERANCE:
        raise InputError(f"{where}: row {row0 + worst + 1}, column '{name}': time step {steps[worst]:g} s "
                         f"differs from the median step {h:g} s by {100 * dev[worst]:.0f}% "
                         f"(tolerance {100 * TIME_STEP_TOLERANCE:.0f}%)")
    return bool(dev[worst] > TIME_STEP_JITTER)


def check_signal(where: str, name: str, quantity: str, x: np.ndarray, unit_hint: str) -> None:
    """Refuse a constant signal or one whose peak is absurd for its units."""
    if np.ptp(x) == 0.0:
        raise InputError(f"{where}: column '{name}' ({quantity}) is constant")
    peak = float(np.max(np.abs(x)))
    if quantity in ABSURD and peak > ABSURD[quantity]:
        raise InputError(f"{where}: column '{name}': peak {peak:.4g} {unit_hint} is absurd for a damper "
                         f"test; check the units (e.g. --units {quantity}=...)")


def check_cycles(where: str, name: str, d: np.ndarray) -> float:
    """Refuse a record with less than one full displacement cycle; return the count."""
    n = count_cycles(d)
    if n < 0.95:
        raise InputError(f"{where}: column '{name}': only {n:.2f} displacement cycles; "
                         f"at least one full cycle is needed")
    return n


def resample_uniform(t: np.ndarray, cols: dict[str, np.ndarray], where: str) -> tuple[np.ndarray, dict]:
    """Linear resampling onto a uniform grid with the median step; warns."""
    h = float(np.median(np.diff(t)))
    n = int(np.floor((t[-1] - t[0]) / h + 1e-9)) + 1
    tu = t[0] + h * np.arange(n)
    warnings.warn(f"{where}: irregular time step (within {100 * TIME_STEP_TOLERANCE:.0f}%); "
                  f"resampled to a uniform {h:g} s", stacklevel=3)
    return tu, {k: np.interp(tu, t, x) for k, x in cols.items()}
