"""The search space: a unit cube mapped linearly (or logarithmically) onto parameter bounds."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

#: a log-scaled parameter whose lower bound is 0 starts this far below its upper bound
LOG_SPAN = 1e-6


@dataclass(frozen=True)
class Space:
    """Map x in [0, 1]^n to parameters within ``bounds`` (n_all, 2); ``log[i]``
    maps parameter i geometrically (for parameters spanning decades).  A
    parameter whose bounds are one value (lower == upper: fixed by the
    caller) is not a dimension of the cube: n counts the free ones, and
    ``to_params`` puts the fixed ones in."""

    bounds: np.ndarray
    log: np.ndarray

    @classmethod
    def of(cls, bounds, log=None) -> "Space":
        b = np.asarray(bounds, dtype=float)
        lg = np.zeros(len(b), bool) if log is None else np.asarray(log, bool) & (b[:, 1] > 0)
        return cls(b, lg)

    @property
    def free(self) -> np.ndarray:
        """Boolean (n_all,): the parameters the search moves."""
        return self.bounds[:, 1] > self.bounds[:, 0]

    @property
    def n(self) -> int:
        return int(self.free.sum())

    def _log_lo(self) -> np.ndarray:
        lo, hi = self.bounds[:, 0], self.bounds[:, 1]
        return np.where(lo > 0, lo, hi * LOG_SPAN)

    @cached_property
    def _mapping(self) -> tuple:
        """What ``to_params`` needs of the bounds, worked out once: (free (None:
        all), lower, span, log-scaled and free, ln of the log scale's lower
        end, its span in ln; the last three None without a log-scaled
        parameter)."""
        lo, hi = self.bounds[:, 0], self.bounds[:, 1]
        geo, free = self.log & self.free, None if self.free.all() else self.free
        if not self.log.any():
            return free, lo, hi - lo, None, None, None
        llo = np.log(self._log_lo())
        return free, lo, hi - lo, geo, llo, np.log(np.maximum(hi, 1e-300)) - llo

    def to_params(self, x: np.ndarray) -> np.ndarray:
        """(..., n) unit-cube points -> parameters (..., n_all)."""
        free, lo, span, geo, llo, lspan = self._mapping
        x = np.asarray(x, dtype=float)
        if free is None:  # every parameter free: the cube's point is the full vector's
            full = np.clip(x, 0.0, 1.0)
        else:
            full = np.zeros(x.shape[:-1] + (len(self.bounds),))
            full[..., free] = np.clip(x, 0.0, 1.0)
        lin = lo + full * span
        if geo is None:
            return lin
        return np.where(geo, np.exp(llo + full * lspan), lin)

    def position(self, p: np.ndarray) -> np.ndarray:
        """Parameters (..., n_all) -> their place in [0, 1] between their
        bounds (..., n_all); 0 for a fixed one."""
        lo, hi = self.bounds[:, 0], self.bounds[:, 1]
        with np.errstate(divide="ignore", invalid="ignore"):
            lin = np.where(hi > lo, (p - lo) / (hi - lo), 0.0)
            llo = np.log(self._log_lo())
            geo = (np.log(np.maximum(p, 1e-300)) - llo) / (np.log(np.maximum(hi, 1e-300)) - llo)
        return np.clip(np.where(self.log & self.free, geo, lin), 0.0, 1.0)

    def to_unit(self, p: np.ndarray) -> np.ndarray:
        """Parameters (..., n_all) -> unit-cube points (..., n): the inverse
        of to_params inside the bounds."""
        return self.position(p)[..., self.free]
