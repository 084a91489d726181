"""Columns as a reader found them, before unit conversion and checks."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class RawColumns:
    """What a reader hands to the checks.

    ``data`` maps t/d/F/v to values in the file's own units; ``rows`` holds,
    for every sample, the row that messages name (1-based: the line of a CSV
    file, the row of a .mat matrix); ``names`` says how each column is called
    in the file; ``time_given`` is False when t [s] was built from a time step;
    ``units`` maps t/d/F/v to the unit the file itself gives (a CSV header's
    ``d [mm]``), fvd_bridge.units names.
    """

    data: dict
    rows: np.ndarray
    names: dict
    time_given: bool = True
    units: dict = field(default_factory=dict)

    @property
    def n(self) -> int:
        """Number of samples."""
        return int(self.rows.size)
