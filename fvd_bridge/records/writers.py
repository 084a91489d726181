"""Write a record as CSV (canonical columns t,d,F[,v] in s, mm, kN, mm/s)
with its unit sidecar NAME.yaml."""

from __future__ import annotations

import os

import numpy as np

from ..io.staging import atomic_file
from ..units import CANONICAL
from .options import sidecar_path
from .record import Record


def write_csv(record: Record, path: str, with_velocity: bool = False, comment: str = "",
              sidecar: bool = True) -> list[str]:
    """Write t,d,F (and v) with full precision and, with ``sidecar``, the
    sidecar NAME.yaml stating their units (s, mm, kN, mm/s), so that the file
    reads back without a 'no unit information' warning. Each file is written
    atomically, the sidecar first. Returns the paths written (the CSV first)."""
    keys = ["t", "d", "F"] + (["v"] if with_velocity else [])
    written = [path]
    if sidecar:
        side = sidecar_path(path)
        with atomic_file(side) as fh:
            fh.write(f"# units of {os.path.basename(path)} (written by fvd_bridge)\n"
                     "units: {" + ", ".join(f"{k}: {CANONICAL[k]}" for k in keys) + "}\n")
        written.append(side)
    with atomic_file(path) as fh:
        for line in comment.splitlines():
            fh.write(f"# {line}\n")
        np.savetxt(fh, np.column_stack([getattr(record, k) for k in keys]), delimiter=",",
                   header=",".join(keys), comments="", fmt="%.10g")
    return written
