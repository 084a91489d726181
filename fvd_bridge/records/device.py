"""A device: the tests of one damper, identified together.

Labs test one damper at several amplitudes and velocities (EN 15129,
ASCE 7 chapter 18 prototype tests); one parameter set must hold on all of
them.  A ``Device`` groups those records; the fit's objective is the
weighted mean of the tests' OFs (eq. 18 on each test, each integrated from
rest), so no test dominates by its length or force level.  A single record
is a device of one test (``as_device``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError, option
from .cycles import dominant_period, reversals


@dataclass
class Device:
    """The tests (Records) of one device and their weights in the objective
    (normalised to sum 1; None: equal); ``warnings``: the tests' reading notes."""

    name: str
    tests: list
    weights: np.ndarray | None = None
    warnings: list = field(default_factory=list)

    def __post_init__(self):
        if not self.tests:
            raise InputError(f"device {self.name}: no tests")
        w = np.ones(len(self.tests)) if self.weights is None else np.asarray(self.weights, dtype=float)
        if w.shape != (len(self.tests),) or np.any(w < 0) or not np.isfinite(w).all() or w.sum() <= 0:
            raise InputError(f"device {self.name}: {option('--test-weights')} needs {len(self.tests)} non-negative numbers, "
                             f"not all zero")
        self.weights = w / w.sum()
        self.warnings = self.warnings or [w for t in self.tests for w in t.warnings]
        names = [t.name for t in self.tests]
        if len(set(names)) != len(names):
            raise InputError(f"device {self.name}: two tests are named alike ({', '.join(names)})")

    @property
    def test_names(self) -> list[str]:
        """The tests' names, in order."""
        return [t.name for t in self.tests]

    @property
    def n(self) -> int:
        """Samples over all tests."""
        return int(sum(t.n for t in self.tests))

    @property
    def dt(self) -> float:
        """The tests' median sampling step [s]."""
        return float(np.median([t.dt for t in self.tests]))

    def scales(self) -> dict:
        """Peak F [kN], v [mm/s], d [mm] over all tests (the auto bounds' scales)."""
        each = [t.scales() for t in self.tests]
        return {k: max(s[k] for s in each) for k in each[0]}

    def without(self, index: int) -> "Device":
        """The device without one test (leave-one-test-out).

        Parameters
        ----------
        index : int
            The test to leave out, by position.
        """
        keep = [k for k in range(len(self.tests)) if k != index]
        return Device(self.name, [self.tests[k] for k in keep], self.weights[keep])


def as_device(x) -> Device:
    """A Device as it is; a Record as a device of one test."""
    return x if isinstance(x, Device) else Device(x.name, [x])


def tested_range(record) -> dict:
    """What a test exercised: peak stroke d [mm], peak velocity v [mm/s] and
    its frequency f [Hz]: 1 / (2 x the median time between reversals of d),
    or the strongest spectral line of d with fewer than three reversals
    (None when d has none)."""
    s = record.scales()
    r = reversals(record.d)
    if r.size >= 3:
        f = 1.0 / (2.0 * float(np.median(np.diff(record.t[r]))))
    else:
        period = dominant_period(record.d, record.dt)
        f = 1.0 / period if np.isfinite(period) else None
    return {"d": s["d"], "v": s["v"], "f": f}
