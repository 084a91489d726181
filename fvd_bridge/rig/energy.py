"""Energy dissipated per cycle: from a loop, and the closed form of a pure orifice."""

from __future__ import annotations

import math

import numpy as np

from ..records.cycles import reversals


def cycle_bounds(d: np.ndarray, hysteresis: float | None = None) -> list[tuple[int, int]]:
    """Sample index pairs (start, stop) of full cycles, from one displacement
    maximum to the next (wiggles below ``hysteresis`` [mm] ignored; default 2%
    of the peak-to-peak displacement)."""
    d = np.asarray(d, dtype=float)
    r = reversals(d, hysteresis)
    if r.size < 2:
        return []
    nxt = np.append(d[r[1:]], d[r[-2]])  # compare each extreme with a neighbour
    maxima = r[d[r] > nxt]
    return [(int(a), int(b)) for a, b in zip(maxima[:-1], maxima[1:])]


def energy_per_cycle(d: np.ndarray, F: np.ndarray, hysteresis: float | None = None) -> np.ndarray:
    """Energy dissipated in each full cycle, integral F dd [kN mm = J]
    (trapezoidal rule over the samples between successive displacement maxima)."""
    d, F = np.asarray(d, dtype=float), np.asarray(F, dtype=float)
    out = []
    for a, b in cycle_bounds(d, hysteresis):
        dd = np.diff(d[a:b + 1])
        out.append(float(np.sum(0.5 * (F[a:b] + F[a + 1:b + 1]) * dd)))
    return np.asarray(out)


def loop_area(d: np.ndarray, F: np.ndarray) -> float:
    """Area [kN mm = J] enclosed by the closed polygon (d_i, F_i) (shoelace
    formula), positive when the loop is run clockwise, as a dissipating one is."""
    d, F = np.asarray(d, dtype=float), np.asarray(F, dtype=float)
    return float(-0.5 * np.sum(d * np.roll(F, -1) - np.roll(d, -1) * F))


def orifice_energy_per_cycle(C: float, alpha: float, amplitude: float, omega: float) -> float:
    """Energy [kN mm = J] that F = C sign(v)|v|^alpha dissipates in one cycle of
    d = A sin(omega t):

      W = C (A omega)^(1+alpha) (4/omega) int_0^(pi/2) cos^(1+alpha) phi dphi
        = 4 C A^(1+alpha) omega^alpha sqrt(pi) Gamma(1 + alpha/2) / (2 Gamma(3/2 + alpha/2)).

    (alpha = 1 gives pi C A^2 omega, the linear dashpot.)
    """
    lam = math.sqrt(math.pi) * math.gamma(1.0 + 0.5 * alpha) / (2.0 * math.gamma(1.5 + 0.5 * alpha))
    return 4.0 * C * amplitude ** (1.0 + alpha) * omega ** alpha * lam
