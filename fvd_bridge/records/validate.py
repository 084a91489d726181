"""Checks that turn a bad record into a one-line message naming file, row and column.

Every ``check_*`` raises InputError on a fault; notes that do not stop a
record (resampling, suspicious units) are returned as strings.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError, option
from .cycles import count_cycles, roughness
from .options import Given
from .plausible import ABSURD, LONG_STEP_S

#: relative deviation of a time step from the median step that is tolerated
#: by resampling onto a uniform grid (beyond it the record is refused)
TIME_STEP_TOLERANCE = 0.10
#: times within this fraction of a step of a uniform grid are round-off of
#: that grid: they are replaced by it without interpolation or warning
TIME_GRID_JITTER = 1.0e-3
#: fewest samples a record may have
MIN_SAMPLES = 8
#: fewest displacement cycles a record may have (a little under 1 for round-off)
MIN_CYCLES = 0.95
#: measured and differentiated peak velocity may differ by this factor either way
VELOCITY_RATIO = 10.0


def check_length(where: str, rows: np.ndarray) -> None:
    """Refuse a record with fewer than MIN_SAMPLES samples."""
    if rows.size < MIN_SAMPLES:
        span = f"row {rows[0]}" if rows.size == 1 else f"rows {rows[0]}..{rows[-1]}"
        raise InputError(f"{where}: {span}: only {rows.size} samples; a record needs at least {MIN_SAMPLES}")


def check_finite(where: str, name: str, x: np.ndarray, rows: np.ndarray) -> None:
    """Refuse NaN/inf; ``rows[i]`` is the file row of sample i."""
    bad = np.flatnonzero(~np.isfinite(x))
    if bad.size:
        raise InputError(f"{where}: row {rows[bad[0]]}, column '{name}': value {x[bad[0]]} is not finite")


def check_time(where: str, name: str, t: np.ndarray, rows: np.ndarray) -> float:
    """Refuse time [s] that does not increase or whose step is irregular beyond tolerance.

    Returns the largest distance of t from the uniform grid through its ends,
    as a fraction of the mean step (0 for a perfectly uniform grid).
    """
    steps = np.diff(t)
    bad = np.flatnonzero(steps <= 0)
    if bad.size:
        i = bad[0] + 1
        raise InputError(f"{where}: row {rows[i]}, column '{name}': time {t[i]:.10g} s does not "
                         f"increase (previous {t[i - 1]:.10g} s)")
    h = float(np.median(steps))
    dev = np.abs(steps - h) / h
    worst = int(np.argmax(dev))
    if dev[worst] > TIME_STEP_TOLERANCE:
        raise InputError(f"{where}: row {rows[worst + 1]}, column '{name}': time step {steps[worst]:.6g} s "
                         f"differs from the median step {h:.6g} s by {100 * dev[worst]:.0f}% "
                         f"(tolerance {100 * TIME_STEP_TOLERANCE:.0f}%)")
    mean = (t[-1] - t[0]) / (t.size - 1)
    return float(np.max(np.abs(t - (t[0] + mean * np.arange(t.size)))) / mean)


def uniform_grid(t: np.ndarray, cols: dict, where: str, off_grid: float) -> tuple[np.ndarray, dict, str | None]:
    """Put the samples on the uniform grid through t[0] and t[-1] with the same count.

    ``off_grid`` is check_time's result: within TIME_GRID_JITTER the times are
    only replaced; beyond it every column is linearly interpolated and a note
    says so.
    """
    tu = np.linspace(t[0], t[-1], t.size)
    if off_grid <= TIME_GRID_JITTER:
        return tu, cols, None
    note = (f"{where}: irregular time step (samples up to {100 * off_grid:.1f}% of a step off a uniform grid, "
            f"steps within the {100 * TIME_STEP_TOLERANCE:.0f}% tolerance); resampled linearly "
            f"to a uniform {tu[1] - tu[0]:.6g} s")
    return tu, {k: np.interp(tu, t, x) for k, x in cols.items()}, note


def check_signal(where: str, name: str, quantity: str, x: np.ndarray, rows: np.ndarray,
                 unit: str, to_canonical: float, canonical: str) -> None:
    """Refuse a constant signal or one whose peak is absurd for its stated unit.

    ``x`` is in the canonical unit (kN, mm, mm/s); ``unit`` is the unit the
    file was read in and ``to_canonical`` its factor.
    """
    if np.ptp(x) == 0.0:
        raise InputError(f"{where}: column '{name}' ({quantity}) is constant "
                         f"({x[0] / to_canonical:g} {unit} at rows {rows[0]}..{rows[-1]})")
    i = int(np.argmax(np.abs(x)))
    if quantity in ABSURD and abs(x[i]) > ABSURD[quantity]:
        raise InputError(f"{where}: row {rows[i]}, column '{name}': {quantity} = {x[i] / to_canonical:.4g} {unit} "
                         f"is absurd for a damper test (limit {ABSURD[quantity]:g} {canonical}); "
                         f"check the units (set them with {option('--units', Given({quantity: 'UNIT'}))} "
                         f"or the sidecar)")


def check_cycles(where: str, name: str, d: np.ndarray) -> float:
    """Refuse a record with less than one full displacement cycle; return the count."""
    n = count_cycles(d)
    if n < MIN_CYCLES:
        raise InputError(f"{where}: column '{name}': only {n:.2f} displacement cycles; "
                         f"at least one full cycle is needed")
    return n


def check_velocity(where: str, name: str, v: np.ndarray, v_from_d: np.ndarray) -> None:
    """Refuse a measured velocity [mm/s] whose peak is far from that of d's derivative."""
    peak, ref = float(np.max(np.abs(v))), float(np.max(np.abs(v_from_d)))
    if ref > 0 and not 1 / VELOCITY_RATIO <= peak / ref <= VELOCITY_RATIO:
        raise InputError(f"{where}: column '{name}': peak velocity {peak:.4g} mm/s is {peak / ref:.3g} times "
                         f"that of the displacement's derivative ({ref:.4g} mm/s); check the units of v and d")


def unit_notes(where: str, dt: float, names: dict) -> list[str]:
    """A note on a time step [s] that suggests time in ms (plausible.LONG_STEP_S)."""
    if dt <= LONG_STEP_S:
        return []
    return [f"{where}: column '{names['t']}': time step {dt:g} s is long for a damper test; "
            f"is time in ms? ({option('--units', Given(t='ms'))})"]


#: the d and F columns look swapped when the column read as d is the
#: rougher (cycles.roughness, each channel for its own range): its white
#: noise SWAPPED times the F column's, and its 2nd difference more. Read the
#: right way round, the d column is the smoother: on the rig's records of
#: the ten laws and of its friction, gap and spring devices (paper,
#: acceptance and earthquake protocols; force noise 0.3-1% of the peak,
#: displacement noise 0.005-0.02 mm) d's noise share is at most 0.21 of F's
#: and its 2nd difference 0.47 (a hysteretic law under an earthquake); with
#: 0.2% force noise and 0.01 mm on a 10 mm stroke, a linear dashpot's 0.54
#: and 0.68; the shared friction and MR dampers' at most 0.13 and 0.024.
#: Swapped, the inverse: 1.8 and 1.4 or more.
SWAPPED = 1.5
#: an F column whose noise share is below this is exact (a model's output
#: written out, not a load cell's: real ones are 1e-4 and more): its noise
#: then tells nothing, and a linear dashpot's exact force is as smooth as
#: its displacement
EXACT = 1.0e-5


def swapped_columns_note(where: str, names: dict, specs: dict, d: np.ndarray, F: np.ndarray) -> str | None:
    """The note when the d and F columns look swapped, else None.

    ``names``: the file's names of the columns; ``specs``: how the caller
    names them in ``--columns`` (header names, .mat indices). The imposed
    displacement is the smooth, band-limited channel; the damper's force
    is the rough one (SWAPPED, EXACT)."""
    (dn, dc), (fn, fc) = roughness(d), roughness(F)
    if not (fn > EXACT and dn > SWAPPED * fn and dc > fc):
        return None
    return (f"{where}: the d and F columns look swapped (column '{names['F']}' is the smoother, band-limited one: "
            f"column '{names['d']}' has {dn / fn:.3g}x its noise and {dc / fc:.3g}x its 2nd difference, each for "
            f"its range): name them with {option('--columns', Given(d=specs['F'], F=specs['d']))}")


#: a rest at the start of a record counts from this long [s]
REST_S = 0.5
#: the displacement moves less than this share of its range during a rest
REST_TRAVEL = 0.005
#: a force at rest from this share of the peak force is an offset worth saying
REST_OFFSET = 0.05


def rest_offset_note(where: str, t: np.ndarray, d: np.ndarray, F: np.ndarray, names: dict) -> list[str]:
    """A note when the record starts at rest (d within REST_TRAVEL of its
    range for at least REST_S) with a mean force there of at least
    REST_OFFSET of the peak force (median force at rest; the peak about
    it): a load-cell offset or a preload the fit would take for the
    damper's."""
    span = float(np.ptp(d))
    moving = np.flatnonzero(np.abs(d - d[0]) > REST_TRAVEL * span) if span > 0 else np.array([], int)
    end = int(moving[0]) if moving.size else 0
    if end < 2 or t[end] - t[0] < REST_S:
        return []
    offset = float(np.median(F[:end]))
    peak = float(np.max(np.abs(F - offset)))  # the damper's own force, about the offset
    if peak == 0.0 or abs(offset) < REST_OFFSET * peak:
        return []
    return [f"{where}: column '{names['F']}': the record starts with {t[end] - t[0]:.3g} s at rest with a force of "
            f"{offset:.3g} kN ({abs(offset) / peak:.0%} of the peak force): a load-cell offset? leave the rest out "
            f"with {option('--window', f'{t[end]:.3g},{t[-1]:.6g}', t0=f'{t[end]:.3g}', t1=f'{t[-1]:.6g}')} "
            f"(and check the zero of the force)"]


#: the loops generate energy (the force's sign is reversed) when the work
#: done on the device, sum (F - mean F) v dt, is negative by more than this
#: share of sum |(F - mean F) v| dt. A damper's share is near +1 (the shared
#: friction damper's and MR damper's tests 0.95 and 1.0), reversed near -1;
#: a pure spring over at least one cycle stays within +-0.2 (a quarter cycle
#: left over), and a viscoelastic loop with loss factor 0.17 is at 0.25.
REVERSED_WORK = 0.25


def reversed_force_note(where: str, name: str, t: np.ndarray, F: np.ndarray, v: np.ndarray) -> str | None:
    """The note for loops that generate energy, None for loops that do not.

    The work done on the device is W = int (F - mean F) v dt [kN mm] (the
    mean force taken out: an offset does no work over closed cycles); W <
    -REVERSED_WORK int |(F - mean F) v| dt means the load cell reads the
    opposite sign. F [kN], v [mm/s], t [s] on a uniform grid.
    """
    power = (F - np.mean(F)) * v
    scale = float(np.sum(np.abs(power)))
    work = float(np.sum(power))
    if scale == 0.0 or work >= -REVERSED_WORK * scale:
        return None
    dt = float(t[1] - t[0])
    return (f"{where}: column '{name}': the force-displacement loops generate energy (dissipated energy "
            f"{work * dt:.4g} kN mm, {work / scale:.0%} of the sum of |F dd|): the force's sign looks reversed; "
            f"read it negated with {option('--force-sign', 'flip')} (sidecar: force_sign: flip), or say the sign "
            f"is right with {option('--force-sign', 'keep')}")


#: a record whose peak force, stroke or peak force per stroke is this many
#: times its reference's (or its inverse) is in other units (m for mm, N for
#: kN: 1000x; both: 10^6x in force per stroke), not another test (a 1%
#: velocity level moves 25x less than the paper's test). A record on its
#: own is held against the ranges of any damper test (plausible.py).
UNIT_MISMATCH = 100.0
_SCALE_WORDS = {"F": ("peak force", "kN"), "d": ("stroke", "mm"), "F/d": ("peak force per stroke", "kN/mm")}


def scale_mismatch(where: str, scales: dict, reference: dict, against: str) -> str | None:
    """The message when a record's scale is UNIT_MISMATCH times beyond its
    reference's, else None.

    ``scales``: the record's {"F": peak |F| [kN], "d": stroke [mm]}
    (``Record.scales``); ``reference``: {key: (lo, hi)} for key F, d or F/d
    (peak force per stroke [kN/mm]); the record is refused when its value is
    above UNIT_MISMATCH * hi or below lo / UNIT_MISMATCH. ``against`` names
    the reference ("a.yaml's calibration record"). A zero scale (a history
    without force) is not compared.
    """
    values = {"F": scales["F"], "d": scales["d"], "F/d": scales["F"] / scales["d"] if scales["d"] else 0.0}
    for key, (lo, hi) in reference.items():
        x = values[key]
        if not x or lo <= x <= hi:
            continue
        bound = hi if x > hi else lo
        ratio = x / bound
        if ratio > UNIT_MISMATCH or ratio < 1.0 / UNIT_MISMATCH:
            what, unit = _SCALE_WORDS[key]
            parts = f" ({scales['F']:.4g} kN over {scales['d']:.4g} mm)" if key == "F/d" else ""
            return (f"{where}: {what} {x:.4g} {unit}{parts} is {ratio:.3g}x that of {against} ({bound:.4g} {unit}): "
                    f"are the record's units right? give them with {option('--units')}, e.g. "
                    f"{option('--units', Given(F='N', d='m'))}")
    return None
