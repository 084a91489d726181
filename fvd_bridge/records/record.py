"""A damper test record: time, displacement, force, with derived velocity."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class Record:
    """One test of one device on a uniform time grid.

    t [s], d [mm], F [kN], v [mm/s], a [mm/s^2]; ``provenance`` says where
    each column came from (file, column mapping, unit factors, differentiator).
    """

    t: np.ndarray
    d: np.ndarray
    F: np.ndarray
    v: np.ndarray
    a: np.ndarray
    name: str = "record"
    provenance: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)

    @property
    def dt(self) -> float:
        """Sampling step [s]."""
        return float(self.t[1] - self.t[0])

    @property
    def n(self) -> int:
        return int(self.t.size)

    @property
    def duration(self) -> float:
        """t_end - t_start [s]."""
        return float(self.t[-1] - self.t[0])

    def scales(self) -> dict:
        """Peak magnitudes used to derive 'auto' bounds: F [kN], v [mm/s], d [mm]."""
        return {
            "F": float(np.max(np.abs(self.F))),
            "v": float(np.max(np.abs(self.v))),
            "d": float(np.max(np.abs(self.d - np.median(self.d)))),
        }

    def slice(self, start: int, stop: int, name: str | None = None) -> "Record":
        """Samples [start, stop) as a new record (provenance kept)."""
        s = np.s_[start:stop]
        return Record(self.t[s], self.d[s], self.F[s], self.v[s], self.a[s],
                      name or self.name, dict(self.provenance, slice=[start, stop]))
