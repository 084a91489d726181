"""Cycle counting, dominant period, dissipated energy and noise estimates (force, displacement) of a record."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from ..kernel_cache import kernel_array


def dominant_period(d: np.ndarray, dt: float) -> float:
    """Period [s] of the strongest spectral line of d (mean removed)."""
    x = d - np.mean(d)
    if x.size < 4 or not np.any(x):
        return float("nan")
    spec = np.abs(np.fft.rfft(x * np.hanning(x.size)))
    spec[0] = 0.0
    k = int(np.argmax(spec))
    return float(x.size * dt / k) if k > 0 else float("nan")


def reversals(d: np.ndarray, hysteresis: float | None = None) -> np.ndarray:
    """Indices where the displacement reverses, ignoring wiggles below ``hysteresis`` [mm]."""
    h = 0.02 * float(np.ptp(d)) if hysteresis is None else hysteresis
    return _reversals(kernel_array(d), float(h))  # one compiled type, a read-only d's too


@njit(cache=True)
def _reversals(d, h):
    """``reversals``, sample by sample: each extreme d moves away from by more than h."""
    idx = np.empty(d.size, np.int64)
    count, direction, ext = 0, 0, 0
    for i in range(1, d.size):
        if direction == 0:
            if abs(d[i] - d[0]) > h:
                direction, ext = (1 if d[i] > d[0] else -1), i
        elif direction * (d[i] - d[ext]) > 0:
            ext = i
        elif direction * (d[ext] - d[i]) > h:
            idx[count] = ext
            count += 1
            direction, ext = -direction, i
    return idx[:count].copy()


def count_cycles(d: np.ndarray) -> float:
    """Full displacement cycles: half the number of half-cycles between reversals.

    Motion before the first and after the last reversal counts as a fraction
    of a half-cycle by its travel relative to the median half-cycle travel.
    """
    r = reversals(d)
    if r.size == 0:
        return 0.0
    travel = np.abs(np.diff(d[r]))
    ref = float(np.median(travel)) if travel.size else float(np.ptp(d))
    ends = abs(d[r[0]] - d[0]) + abs(d[-1] - d[r[-1]])
    partial = min(ends / ref, 2.0) if ref > 0 else 0.0
    return 0.5 * (travel.size + partial)


def loop_energy(force: np.ndarray, deformation: np.ndarray) -> np.ndarray:
    """Energy [kN mm = J] of each column of force [kN] over deformation [mm]
    (samples down axis 0): E = integral F dDelta, by the trapezoidal rule
    sum (F_k + F_k+1)/2 (Delta_k+1 - Delta_k)."""
    F, d = np.asarray(force, dtype=float), np.asarray(deformation, dtype=float)
    return np.sum(0.5 * (F[1:] + F[:-1]) * np.diff(d, axis=0), axis=0)


@dataclass(frozen=True)
class ForceMeasures:
    """The peak force and the dissipated energy of a force F [kN] on a
    displacement history d [mm] (``force_measures``).

    peak: max |F| [kN]; peak_tension: max F, peak_compression: max -F [kN]
    (each a magnitude; F > 0 in tension); energy: the energy dissipated over
    the whole history, E = integral F dd [kN mm = J] (``loop_energy``);
    cycles: its displacement cycles (``count_cycles``); energy_per_cycle:
    E / cycles [kN mm = J], None when d reverses fewer than twice (no whole
    half-cycle to count cycles by: the total alone is given)."""

    peak: float
    peak_tension: float
    peak_compression: float
    energy: float
    cycles: float
    energy_per_cycle: float | None

    def as_dict(self) -> dict:
        """JSON fields, units in their names (the cycles are the motion's, not the force's: apart)."""
        return {"peak_force_kN": self.peak, "peak_tension_kN": self.peak_tension,
                "peak_compression_kN": self.peak_compression, "energy_kNmm": self.energy,
                "energy_per_cycle_kNmm": self.energy_per_cycle}


def force_measures(d: np.ndarray, F: np.ndarray) -> ForceMeasures:
    """Peak force and energy per cycle of F [kN] on d [mm] (``ForceMeasures``).

    The energy per cycle is E / N: E = integral F dd [kN mm = J] over the
    whole record, N = ``count_cycles(d)``, the full cycles between the
    reversals of d (2% hysteresis), the motion before the first and after
    the last reversal counted by its travel.  One definition for every
    record: on a sinusoidal test of n cycles it is one cycle's loop area
    (a linear dashpot F = c v on d = A sin(w t): pi c w A^2, its peak
    force c w A); on an irregular record (an earthquake test) it is the
    mean over its cycles of unequal amplitude, with the total E beside it.
    """
    d, F = np.asarray(d, dtype=float), np.asarray(F, dtype=float)
    energy = float(loop_energy(F, d))
    whole = reversals(d).size >= 2
    cycles = count_cycles(d) if whole else 0.0
    return ForceMeasures(float(np.max(np.abs(F))), max(float(np.max(F)), 0.0), max(float(-np.min(F)), 0.0),
                         energy, float(cycles), float(energy / cycles) if whole and cycles > 0 else None)


def force_noise(F: np.ndarray) -> float:
    """Standard deviation [kN] of white force noise, from the 4th difference.

    sigma = median|D4 F| / (0.6745 sqrt(70)), D4 F[i] = F[i-2] - 4F[i-1] +
    6F[i] - 4F[i+1] + F[i+2]: the 4th difference of white noise has variance
    70 sigma^2 and cancels a smooth signal up to its cubic part; the median
    makes the estimate robust to the signal's sharp features at reversals.
    """
    if F.size < 5:
        return float("nan")
    d4 = F[:-4] - 4.0 * F[1:-3] + 6.0 * F[2:-2] - 4.0 * F[3:-1] + F[4:]
    return float(np.median(np.abs(d4)) / (0.6745 * np.sqrt(70.0)))


def displacement_noise(d: np.ndarray) -> float:
    """Standard deviation [mm] of white displacement noise (any signal's, in its unit).

    The 4th-difference estimate of force_noise (a 40 mm, 500 mm/s sinusoid
    at 500 Hz has |D4 d| < 2e-5 mm, against 0.04 mm for 0.005 mm of noise),
    bounded below by the quantization noise q/sqrt(12) when the samples lie
    on a grid of step q (an encoder, an ADC; ``quantum``), so that a
    record quantized coarser than its noise (4th differences mostly zero)
    still gets a nonzero noise.
    """
    sigma = force_noise(d)
    q = quantum(d)
    return max(sigma, q / np.sqrt(12.0)) if np.isfinite(sigma) else sigma


#: fraction of the steps between samples that must be whole multiples of the
#: smallest one for a signal to count as quantized
QUANTIZED_FRACTION = 0.95


def quantum(x: np.ndarray) -> float:
    """The quantization step of x (its unit), 0 for a signal not on a grid.

    q starts as the smallest nonzero step between samples and is refined by
    least squares over the steps s ~ k q (k = round(s / q); steps up to 4,
    16, 64 q, then all, so that k stays right); x is on a grid
    when at least QUANTIZED_FRACTION of the steps are within 0.1 q of a whole
    multiple (values printed with a rounded format, or converted between
    units, keep that)."""
    steps = np.abs(np.diff(x))
    steps = steps[steps > 0]
    if steps.size < 8:
        return 0.0
    q = float(steps.min())
    for span in (4.0, 16.0, 64.0, np.inf):  # refine on small multiples first: k stays exact
        s = steps[steps <= span * q]
        k = np.maximum(np.round(s / q), 1.0)
        q = float(np.sum(k * s) / np.sum(k * k))
    k = np.maximum(np.round(steps / q), 1.0)
    on_grid = np.abs(steps - k * q) < 0.1 * q
    return q if np.mean(on_grid) >= QUANTIZED_FRACTION else 0.0


def roughness(x: np.ndarray) -> tuple[float, float]:
    """How rough a signal is for its range (any unit): (its white noise, the
    4th-difference estimate of ``displacement_noise`` with its quantization
    floor, / its std; the RMS of its 2nd difference / its std). A smooth,
    band-limited command (an actuator's sine or earthquake history) is low
    in both; a damper's force is rougher (noise of a load cell, jumps at
    reversals, the velocity's harmonics). (0, 0) for a constant."""
    scale = float(np.std(x))
    if x.size < 5 or scale == 0.0:
        return 0.0, 0.0
    return displacement_noise(x) / scale, float(np.sqrt(np.mean(np.diff(x, 2) ** 2))) / scale
