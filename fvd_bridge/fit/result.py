"""FitResult: what one fit of one model to one record produced."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np


@dataclass
class FitResult:
    """Best parameters [units per ``units``], their OF (eq. 18) and how they were found."""

    spec: str
    names: list
    units: list
    params: np.ndarray
    of: float
    bounds: np.ndarray
    bounds_mode: str
    optimizer: str
    seed: object  # int or list of ints
    evaluations: int
    history: list = field(default_factory=list)
    wall_s: float = 0.0
    record: str = ""

    def as_dict(self) -> dict:
        d = asdict(self)
        d["params"] = {n: float(v) for n, v in zip(self.names, self.params)}
        d["bounds"] = {n: [float(lo), float(hi)] for n, (lo, hi) in zip(self.names, self.bounds)}
        d["units"] = dict(zip(self.names, self.units))
        d.pop("names")
        d["history"] = [float(h) for h in self.history]
        return d

    def on_bound(self, rtol: float = 1e-3) -> list[tuple[str, str]]:
        """Parameters that ended on a bound: [(name, 'lower'|'upper'), ...]."""
        out = []
        for name, p, (lo, hi) in zip(self.names, self.params, self.bounds):
            span = (hi - lo) or 1.0
            if p - lo <= rtol * span and lo != 0.0:
                out.append((name, "lower"))
            elif hi - p <= rtol * span:
                out.append((name, "upper"))
        return out
