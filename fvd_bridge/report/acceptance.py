"""The acceptance table of a device's tests, after the prototype and
production test checks of ASCE 7-16 section 18.6.2 and EN 15129:2018
section 7.3, as far as sinusoidal force-displacement records allow.

Per test, split into full cycles at every second reversal of d:

- **force at the test velocity**: the mean over cycles of the peak force
  |F| against the nominal value, the series' calibrated model at that
  velocity (the mean over the series' devices); within the tolerance;
- **force spread over cycles**: each cycle's peak force within the
  tolerance of their mean (ASCE 7 18.6.2.3: the force of each cycle within
  15% of the average over the cycles);
- **energy per cycle**: each cycle's dissipated energy (the loop's area,
  the integral of F dd) within the tolerance of their mean (ASCE 7
  18.6.2.3, EN 15129 7.3.2: the energy dissipated per cycle).

The tolerance is a setting (default +-15%); the rule is stated beside each
row.  Units: kN, mm, kN mm = J.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..records.cycles import reversals

#: the default tolerance of every check: +-15% (ASCE 7-16 18.6.2.3)
TOLERANCE = 0.15


@dataclass(frozen=True)
class Check:
    """One row: what was checked, the measured and reference values, pass or not."""

    test: str
    what: str
    measured: float
    reference: float
    deviation: float  # the largest |measured / reference - 1|
    passed: bool
    rule: str


def cycles(d: np.ndarray) -> list[tuple[int, int]]:
    """(start, end) sample indices of each full cycle: between every second reversal of d."""
    r = reversals(d)
    return [(int(r[k]), int(r[k + 2])) for k in range(0, len(r) - 2, 2)]


def cycle_peaks_and_energies(rec) -> tuple[np.ndarray, np.ndarray]:
    """Per full cycle: the peak |F| [kN] and the dissipated energy, the loop's area [kN mm]."""
    peaks, energies = [], []
    for a, b in cycles(rec.d):
        F, d = rec.F[a:b + 1], rec.d[a:b + 1]
        peaks.append(float(np.max(np.abs(F))))
        energies.append(float(abs(np.sum(0.5 * (F[1:] + F[:-1]) * np.diff(d)))))
    return np.array(peaks), np.array(energies)


def checks_of_test(rec, nominal_force: float | None, tolerance: float = TOLERANCE) -> list[Check]:
    """The checks of one test (``nominal_force`` [kN]: the series' force at
    the test's peak velocity; None: that check is not made)."""
    peaks, energies = cycle_peaks_and_energies(rec)
    out = []
    pct = f"+-{tolerance:.0%}"
    if peaks.size and nominal_force:
        dev = abs(peaks.mean() / nominal_force - 1.0)
        out.append(Check(rec.name, f"force at {np.max(np.abs(rec.v)):.4g} mm/s [kN]", float(peaks.mean()),
                         float(nominal_force), dev, dev <= tolerance,
                         f"mean peak force within {pct} of the series' nominal value (EN 15129 7.3, production tests)"))
    if peaks.size >= 2:
        dev = float(np.max(np.abs(peaks / peaks.mean() - 1.0)))
        out.append(Check(rec.name, "peak force spread over cycles [kN]", float(peaks.max()), float(peaks.mean()),
                         dev, dev <= tolerance, f"every cycle's peak force within {pct} of their mean "
                                                f"({peaks.size} cycles; ASCE 7-16 18.6.2.3)"))
        dev = float(np.max(np.abs(energies / energies.mean() - 1.0)))
        out.append(Check(rec.name, "energy per cycle [kN mm]", float(energies.min()), float(energies.mean()),
                         dev, dev <= tolerance, f"every cycle's dissipated energy within {pct} of their mean "
                                                f"(ASCE 7-16 18.6.2.3, EN 15129 7.3.2)"))
    return out
