"""FitResult: what one fit of one model to one record produced."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import NamedTuple

import numpy as np

from .parameter import FittedParameter
from .space import Space


class Parent(NamedTuple):
    """The nested fit a fit started from: its model's spec and its OF."""

    spec: str
    of: float


@dataclass(frozen=True)
class FitResult:
    """Best parameters [units per ``units``], their OF (eq. 18) and how they were found
    (frozen: a changed fit is ``dataclasses.replace(fit, ...)``)."""

    spec: str
    names: list
    units: list
    values: np.ndarray  # the estimates [units per ``units``], in ``names``' order (``Calibration.values``)
    of: float
    bounds: np.ndarray
    bounds_mode: str
    optimizer: str
    seed: object  # int or list of ints
    evaluations: int
    history: list = field(default_factory=list)
    wall_s: float = 0.0
    record: str = ""
    log: list = field(default_factory=list)  # searched on a log scale, per parameter
    off: list = field(default_factory=list)  # value that switches an effect off (None for law parameters)
    tests: list = field(default_factory=list)  # the device's tests (one: the record)
    test_of: list = field(default_factory=list)  # OF (eq. 18) on each test
    widened: dict = field(default_factory=dict)  # {law parameter: (lower, upper)} automatic bounds widened
    parent: Parent | None = None  # the nested fit it started from
    stop: str = ""  # why the search stopped (the back-end's ``Search.stop``)
    flat_ends: list = field(default_factory=list)  # parameters whose bound widened without lowering the OF
    zero: dict | None = None  # {test: (F0 [kN], F1 [kN/s])}: the tests' force zero fitted beside it (fit.zero)
    floor: float | None = None  # the record's noise floor (fit.floor.device_floor) where the campaign judged the fit by it

    @property
    def params(self) -> dict[str, FittedParameter]:
        """{name: FittedParameter} in the fit's order (a per-test column 'NAME@TEST'
        its own), as ``Calibration.params``: the estimate [its unit], the search
        bounds, fixed (by the caller: lower bound == upper bound); no stderr or
        ci95 (a fit has no intervals).  The vector is ``values``."""
        return {n: FittedParameter(n, float(v), u, bounds=(float(lo), float(hi)), fixed=bool(lo == hi))
                for n, v, u, (lo, hi) in zip(self.names, self.values, self.units, self.bounds)}

    def named(self) -> dict[str, float]:
        """{name: estimate} in the fit's order, as ``Calibration.named``."""
        return {n: p.value for n, p in self.params.items()}

    def as_dict(self) -> dict:
        """The fit as a mapping (the unit files of a campaign's store keep it):
        the estimates under "params" ({name: value}, in the place and form
        files have always had; read back by ``campaign.store.result_from_dict``)."""
        d = {("params" if k == "values" else k): v for k, v in asdict(self).items()}
        d["params"] = self.named()
        d["bounds"] = {n: list(p.bounds) for n, p in self.params.items()}
        d["units"] = {n: p.unit for n, p in self.params.items()}
        d.pop("names")
        d["history"] = [float(h) for h in self.history]
        d["log"] = [bool(x) for x in self.log]
        d["test_of"] = [float(x) for x in self.test_of]
        d["widened"] = {n: [float(lo), float(hi)] for n, (lo, hi) in self.widened.items()}
        d["parent"] = [] if self.parent is None else [self.parent.spec, float(self.parent.of)]
        return d

    def on_bound(self, tol: float = 1e-3) -> list[tuple[str, str]]:
        """Parameters within ``tol`` of a bound in the search space (log-scaled ones
        judged on their log scale): [(name, 'lower'|'upper')].  A lower bound of 0
        and an effect's 'off' value are natural ends, not starvation; a fixed
        parameter is on neither."""
        x = Space.of(self.bounds, self.log or None).position(np.asarray(self.values))
        off = self.off or [None] * len(self.names)
        out = []
        for p, xi, o in zip(self.params.values(), x, off):
            if p.fixed:
                continue
            lo, hi = p.bounds
            if xi <= tol and lo != 0.0 and lo != o:
                out.append((p.name, "lower"))
            elif xi >= 1.0 - tol and hi != o:
                out.append((p.name, "upper"))
        return out
