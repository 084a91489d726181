"""The acceptance table of a device's tests, after the prototype and
production test checks of ASCE 7-16 section 18.6.2 and EN 15129:2018
section 7.3, each applied only to the tests its rule is written for.

Per test, split into full cycles at every second reversal of d, grouped in
levels (``levels``: consecutive cycles whose amplitude, peak velocity and
duration are within ``LEVEL_MATCH`` of the level's first cycle; a cycle that
straddles two levels belongs to neither):

- **force at the test velocity** (a production test, EN 15129 7.3): the
  mean over cycles of the peak force |F| against the nominal value, the
  series' calibrated model on the same motion (the mean over the series'
  devices); within the tolerance.  Written for a device of a series: with
  one device its own model is the nominal, so the check is not applicable;
- **force spread over cycles** (ASCE 7-16 18.6.2.3: the force of each cycle
  within 15% of the average over the cycles) and **energy per cycle**
  (ASCE 7-16 18.6.2.3, EN 15129 7.3.2: the energy dissipated per cycle, the
  loop's area, the integral of F dd): written for a test of constant-
  amplitude cycles at one stated velocity, so they are applied per level
  of at least ``MIN_CYCLES`` cycles, and are not applicable, with the
  reason, to a record without one (an amplitude that ramps, a random motion).

The tolerance is a setting (default +-15%); the rule and its source are
stated beside each row.  Units: kN, mm, mm/s, kN mm = J.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..records.cycles import reversals
from .numbers import rounded, share

#: the default tolerance of every check: +-15% (ASCE 7-16 18.6.2.3)
TOLERANCE = 0.15
#: cycles of one level: amplitude, peak velocity and duration within this share of the level's first cycle
LEVEL_MATCH = 0.05
#: the fewest cycles of one level the cycle-to-cycle rules are applied to (a level of three
#: sinusoidal cycles holds two whole reversal-to-reversal cycles)
MIN_CYCLES = 2

SOURCE_PRODUCTION = "EN 15129:2018 7.3 (production tests)"
SOURCE_SPREAD = "ASCE 7-16 18.6.2.3"
SOURCE_ENERGY = "ASCE 7-16 18.6.2.3, EN 15129:2018 7.3.2"


@dataclass(frozen=True)
class Check:
    """One row: what was checked, the rule and its source, the measured and
    reference values and the verdict; ``passed`` None when the rule does not
    apply to this test (``why_not`` says why)."""

    test: str
    what: str
    measured: float | None
    reference: float | None
    deviation: float | None  # the largest |measured / reference - 1|
    passed: bool | None
    rule: str
    source: str
    why_not: str = ""

    @property
    def verdict(self) -> str:
        """'pass', 'FAIL' or 'not applicable'."""
        return "not applicable" if self.passed is None else ("pass" if self.passed else "FAIL")


@dataclass(frozen=True)
class Level:
    """Consecutive full cycles of one amplitude [mm] and peak velocity [mm/s]."""

    cycles: tuple  # ((start, end) sample indices, ...)
    amplitude: float
    velocity: float

    def text(self) -> str:
        return f"{len(self.cycles)} cycles at {rounded(self.amplitude, digits=3)} mm, {rounded(self.velocity, digits=3)} mm/s"


def cycles(d: np.ndarray) -> list[tuple[int, int]]:
    """(start, end) sample indices of each full cycle: between every second reversal of d."""
    r = reversals(d)
    return [(int(r[k]), int(r[k + 2])) for k in range(0, len(r) - 2, 2)]


def cycle_peaks_and_energies(rec) -> tuple[np.ndarray, np.ndarray]:
    """Per full cycle: the peak |F| [kN] and the dissipated energy, the loop's area [kN mm]."""
    return _peaks_and_energies(rec, cycles(rec.d))


def _peaks_and_energies(rec, spans) -> tuple[np.ndarray, np.ndarray]:
    peaks, energies = [], []
    for a, b in spans:
        F, d = rec.F[a:b + 1], rec.d[a:b + 1]
        peaks.append(float(np.max(np.abs(F))))
        energies.append(float(abs(np.sum(0.5 * (F[1:] + F[:-1]) * np.diff(d)))))
    return np.array(peaks), np.array(energies)


def levels(rec, match: float = LEVEL_MATCH, fewest: int = MIN_CYCLES) -> list[Level]:
    """The record's levels of at least ``fewest`` constant-amplitude cycles at
    one velocity: consecutive full cycles whose amplitude (half the peak-to-
    peak d) [mm], peak |v| [mm/s] and duration [s] are within ``match`` of the
    level's first."""
    spans = cycles(rec.d)
    amp = np.array([0.5 * np.ptp(rec.d[a:b + 1]) for a, b in spans])
    vel = np.array([np.max(np.abs(rec.v[a:b + 1])) for a, b in spans])
    period = np.array([rec.t[b] - rec.t[a] for a, b in spans])
    found, k = [], 0
    while k < len(spans):
        j = k + 1
        while j < len(spans) and all(abs(x[j] / x[k] - 1.0) <= match for x in (amp, vel, period)):
            j += 1
        if j - k >= fewest:
            found.append(Level(tuple(spans[k:j]), float(amp[k:j].mean()), float(vel[k:j].mean())))
        k = j
    return found


def _no_level(rec, fewest: int) -> str:
    """Why the cycle-to-cycle rules do not apply to a record without a level."""
    spans = cycles(rec.d)
    if len(spans) < fewest:
        return f"{len(spans)} full cycle(s): the rule is written for at least {fewest} constant-amplitude cycles"
    amp = [0.5 * np.ptp(rec.d[a:b + 1]) for a, b in spans]
    vel = [np.max(np.abs(rec.v[a:b + 1])) for a, b in spans]
    return (f"the cycles' amplitude goes {rounded(min(amp), digits=2)}-{rounded(max(amp), digits=2)} mm and their "
            f"peak velocity {rounded(min(vel), digits=2)}-{rounded(max(vel), digits=2)} mm/s: no {fewest} cycles "
            f"of constant amplitude at one velocity, which the rule is written for")


def checks_of_test(rec, nominal_force: float | None, tolerance: float = TOLERANCE,
                   series_size: int = 2) -> list[Check]:
    """The checks of one test: ``nominal_force`` [kN], the series' force on the
    test's motion (None: that check is not made); ``series_size``: the
    devices of the series (one: the production check is not applicable)."""
    pct = f"+-{share(tolerance)}"
    out = []
    if nominal_force:
        rule = f"mean peak force within {pct} of the series' nominal value"
        what = f"force at {rounded(np.max(np.abs(rec.v)), digits=3)} mm/s [kN]"
        if series_size < 2:
            out.append(Check(rec.name, what, None, None, None, None, rule, SOURCE_PRODUCTION,
                             "one device: its own model is the nominal; the rule compares a device with its series"))
        else:
            peaks, _ = cycle_peaks_and_energies(rec)
            if peaks.size:
                dev = abs(peaks.mean() / nominal_force - 1.0)
                out.append(Check(rec.name, what, float(peaks.mean()), float(nominal_force), dev, dev <= tolerance,
                                 rule, SOURCE_PRODUCTION))
    spread_rule = f"every cycle's peak force within {pct} of their mean"
    energy_rule = f"every cycle's dissipated energy within {pct} of their mean"
    found = levels(rec)
    if not found:
        why = _no_level(rec, MIN_CYCLES)
        return out + [Check(rec.name, "peak force spread over cycles [kN]", None, None, None, None, spread_rule,
                            SOURCE_SPREAD, why),
                      Check(rec.name, "energy per cycle [kN mm]", None, None, None, None, energy_rule,
                            SOURCE_ENERGY, why)]
    for level in found:
        peaks, energies = _peaks_and_energies(rec, level.cycles)
        at = f" ({level.text()})"
        for what, values, rule, source in ((f"peak force spread over cycles [kN]{at}", peaks, spread_rule, SOURCE_SPREAD),
                                           (f"energy per cycle [kN mm]{at}", energies, energy_rule, SOURCE_ENERGY)):
            off = np.abs(values / values.mean() - 1.0)
            worst = int(np.argmax(off))  # the measured value shown: the cycle farthest from the mean
            out.append(Check(rec.name, what, float(values[worst]), float(values.mean()), float(off[worst]),
                             bool(off[worst] <= tolerance), rule, source))
    return out
