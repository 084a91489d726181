"""OUT/exports.json: the exports made of an output folder's calibrations.

A calibration file written by ``calibrate``, ``campaign`` or ``diagnose``
lives in OUT/params/DEVICE/; when ``fvd-bridge export`` writes an OpenSees
script or an FMU of it, the export, its units and its fidelity check are
noted here, and OUT/report.html lists them under the device.
"""

from __future__ import annotations

import json
import os
import time

from ..io.staging import atomic_file

LEDGER = "exports.json"


def output_folder(calibration_path: str) -> str | None:
    """The output folder a calibration file belongs to (OUT of
    OUT/params/DEVICE/x.yaml, with its report.html); None for a file elsewhere."""
    device_dir = os.path.dirname(os.path.abspath(calibration_path))
    params_dir = os.path.dirname(device_dir)
    out = os.path.dirname(params_dir)
    if os.path.basename(params_dir) == "params" and os.path.isfile(os.path.join(out, "report.html")):
        return out
    return None


def exports_of(out: str) -> list[dict]:
    """The exports noted in ``out`` (oldest first); [] when there are none."""
    path = os.path.join(out, LEDGER)
    if not os.path.isfile(path):
        return []
    with open(path) as fh:
        return json.load(fh)


def note_export(out: str, cal, calibration_path: str, kind: str, file: str, units: str, check: dict | None,
                exact: bool | None = None) -> None:
    """Note in ``out`` an export of ``cal`` (read from ``calibration_path``):
    ``kind`` 'opensees' or 'fmu', the ``file`` written, its ``units``
    (FORCE,LENGTH,TIME), ``check`` {record, of, bound, ok} (None: not checked)
    and, for OpenSees, whether the mapping is ``exact``. An export to the same
    file replaces the earlier note."""
    file = os.path.abspath(file)
    entry = {"kind": kind, "file": file, "device": cal.device or cal.record.name,
             "model": cal.spec, "calibration": os.path.relpath(os.path.abspath(calibration_path), out),
             "units": units, "exact": exact, "check": check, "written": time.strftime("%Y-%m-%d %H:%M:%S")}
    entries = [e for e in exports_of(out) if e["file"] != file] + [entry]
    with atomic_file(os.path.join(out, LEDGER)) as fh:
        json.dump(entries, fh, indent=1)
