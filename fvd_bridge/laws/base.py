"""What a law is: parameters with units and bounds, an equation, a vectorized kernel."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..errors import InputError

BOUND_MODES = ("auto", "paper")


@dataclass(frozen=True)
class Parameter:
    """One parameter of a law or effect.

    ``paper``: the bounds of the paper's Table 4 (or a literature default);
    ``auto(scales)``: bounds derived from the record's peak force F [kN],
    velocity v [mm/s] and displacement d [mm]; ``log``: searched on a log
    scale by the default optimizer (parameters spanning decades).
    """

    name: str
    unit: str
    paper: tuple[float, float]
    auto: Callable[[dict], tuple[float, float]]
    description: str
    log: bool = False


@dataclass(frozen=True)
class Derived:
    """A quantity computed from a law's parameters, reported beside them
    (law 8's identifiable slip force mu*N [kN]); ``value(p)`` takes the law's
    parameter vector (law order); ``factors``: the parameters it combines,
    which alone may be non-identifiable."""

    name: str
    unit: str
    value: Callable
    description: str
    factors: tuple = ()


@dataclass(frozen=True)
class Law:
    """A damper law: ``population(d, v, dt, P, substeps) -> F`` evaluates a whole
    population, P of shape (pop, n_par), F of shape (pop, n_t) [kN]; d [mm],
    v [mm/s], dt [s].  ``derived``: quantities reported beside the parameters."""

    number: int
    name: str
    kind: str  # "algebraic" or "differential"
    equation: str
    source: str
    parameters: tuple[Parameter, ...]
    population: Callable
    note: str = ""
    derived: tuple = ()

    @property
    def key(self) -> str:
        return str(self.number)

    @property
    def names(self) -> list[str]:
        return [p.name for p in self.parameters]

    def bounds(self, mode: str, scales: dict) -> np.ndarray:
        """(n_par, 2) bounds: 'paper' (Table 4) or 'auto' (from the record's scales)."""
        if mode not in BOUND_MODES:
            raise InputError(f"--bounds '{mode}': expected one of {', '.join(BOUND_MODES)}")
        rows = [p.paper if mode == "paper" else p.auto(scales) for p in self.parameters]
        return np.asarray(rows, dtype=float)

    def force(self, d: np.ndarray, v: np.ndarray, dt: float, P: np.ndarray, substeps: int = 1) -> np.ndarray:
        """Force [kN] for each parameter row of P: (pop, n_par) -> (pop, n_t)."""
        P = np.atleast_2d(np.asarray(P, dtype=float))
        if P.shape[1] != len(self.parameters):
            raise InputError(f"law {self.number}: expected {len(self.parameters)} parameters "
                             f"({', '.join(self.names)}), got {P.shape[1]}")
        return self.population(np.ascontiguousarray(d, dtype=float), np.ascontiguousarray(v, dtype=float),
                           float(dt), np.ascontiguousarray(P), int(substeps))
