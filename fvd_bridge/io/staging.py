"""An output directory written all-or-nothing.

Files are written into a sibling staging directory; only when everything
succeeded are they moved into place, so an error leaves no partial output.
"""

from __future__ import annotations

import contextlib
import csv
import json
import math
import os
import shutil

import numpy as np

from ..errors import InputError



@contextlib.contextmanager
def staged_dir(out: str):
    """Yield a staging path; on success its content replaces/merges into ``out``."""
    out = os.path.abspath(out)
    parent = os.path.dirname(out)
    os.makedirs(parent, exist_ok=True)
    stage = os.path.join(parent, f".{os.path.basename(out)}.partial-{os.getpid()}")
    shutil.rmtree(stage, ignore_errors=True)
    os.makedirs(stage)
    try:
        yield stage
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        raise
    if not os.path.exists(out):
        os.replace(stage, out)
        return
    for root, _, files in os.walk(stage):
        rel = os.path.relpath(root, stage)
        os.makedirs(os.path.join(out, rel), exist_ok=True)
        for f in files:
            os.replace(os.path.join(root, f), os.path.join(out, rel, f))
    shutil.rmtree(stage, ignore_errors=True)


def output_folder_exists(path: str, flag: str = "-o") -> None:
    """An InputError unless the folder of the output file ``path`` exists
    (an output file's folder is not made on a typo's word)."""
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise InputError(f"{flag} {path}: folder {os.path.dirname(path) or folder} does not exist")


@contextlib.contextmanager
def atomic_file(path: str, mode: str = "w"):
    """Yield a file handle whose content replaces ``path`` only when the block
    succeeds (a temporary file beside it, renamed into place); on an error
    nothing is left behind."""
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    tmp = f"{path}.partial-{os.getpid()}"
    try:
        with open(tmp, mode) as fh:
            yield fh
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def num(x) -> float | None:
    """A finite float, else None (JSON and YAML have no NaN to trust)."""
    x = float(x)
    return x if math.isfinite(x) else None


def plain(x, finite: bool = False):
    """Numpy scalars and arrays, tuples -> plain JSON/YAML types, all the way
    down; with ``finite``, a NaN or infinite float -> None."""
    if isinstance(x, dict):
        return {str(k): plain(v, finite) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [plain(v, finite) for v in x]
    if isinstance(x, np.ndarray):
        return [plain(v, finite) for v in x.tolist()]
    if isinstance(x, np.generic):
        x = x.item()
    if finite and isinstance(x, float):
        return num(x)
    return x


def write_json(path: str, data) -> None:
    with open(path, "w") as fh:
        json.dump(data, fh, indent=1)


def write_csv_rows(path: str, header: list, rows: list) -> None:
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        w.writerows(rows)


def safe_name(name: str) -> str:
    """A file-name part from a device or model name: anything but letters,
    digits and - _ . + becomes _."""
    return "".join(c if c.isalnum() or c in "-_.+" else "_" for c in str(name))
