"""Write a record as CSV (canonical columns t,d,F[,v] in s, mm, kN, mm/s)."""

from __future__ import annotations

import os

import numpy as np

from .record import Record


def write_csv(record: Record, path: str, with_velocity: bool = False, comment: str = "") -> None:
    """Write t,d,F (and v) with full precision; atomic (temp file, then rename)."""
    cols = [record.t, record.d, record.F] + ([record.v] if with_velocity else [])
    header = "t,d,F" + (",v" if with_velocity else "")
    tmp = f"{path}.part"
    with open(tmp, "w") as fh:
        for line in comment.splitlines():
            fh.write(f"# {line}\n")
        np.savetxt(fh, np.column_stack(cols), delimiter=",", header=header, comments="", fmt="%.10g")
    os.replace(tmp, path)
