"""The search space: a unit cube mapped linearly (or logarithmically) onto parameter bounds."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: a log-scaled parameter whose lower bound is 0 starts this far below its upper bound
LOG_SPAN = 1e-6


@dataclass(frozen=True)
class Space:
    """Map x in [0, 1]^n to parameters within ``bounds`` (n, 2); ``log[i]`` maps
    parameter i geometrically (for parameters spanning decades)."""

    bounds: np.ndarray
    log: np.ndarray

    @classmethod
    def of(cls, bounds, log=None) -> "Space":
        b = np.asarray(bounds, dtype=float)
        lg = np.zeros(len(b), bool) if log is None else np.asarray(log, bool) & (b[:, 1] > 0)
        return cls(b, lg)

    @property
    def n(self) -> int:
        return len(self.bounds)

    def _log_lo(self) -> np.ndarray:
        lo, hi = self.bounds[:, 0], self.bounds[:, 1]
        return np.where(lo > 0, lo, hi * LOG_SPAN)

    def to_params(self, x: np.ndarray) -> np.ndarray:
        """(..., n) unit-cube points -> parameters."""
        x = np.clip(x, 0.0, 1.0)
        lo, hi = self.bounds[:, 0], self.bounds[:, 1]
        lin = lo + x * (hi - lo)
        if not self.log.any():
            return lin
        llo = np.log(self._log_lo())
        geo = np.exp(llo + x * (np.log(np.maximum(hi, 1e-300)) - llo))
        return np.where(self.log, geo, lin)

    def to_unit(self, p: np.ndarray) -> np.ndarray:
        """Parameters -> unit-cube points (inverse of to_params inside bounds)."""
        lo, hi = self.bounds[:, 0], self.bounds[:, 1]
        with np.errstate(divide="ignore", invalid="ignore"):
            lin = np.where(hi > lo, (p - lo) / (hi - lo), 0.0)
            llo = np.log(self._log_lo())
            geo = (np.log(np.maximum(p, 1e-300)) - llo) / (np.log(np.maximum(hi, 1e-300)) - llo)
        return np.clip(np.where(self.log, geo, lin), 0.0, 1.0)
