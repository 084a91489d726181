"""Writing outputs all-or-nothing: an output path checked before any work
(``check_output``), an output directory staged beside its place
(``staged_dir``), a file written beside its place and renamed
(``atomic_file``); YAML/CSV/JSON helpers.

Files are written into a sibling staging directory (or a temporary file);
only when everything succeeded are they moved into place, so an error, a
Ctrl-C included, leaves no partial output.
"""

from __future__ import annotations

import contextlib
import csv
import json
import math
import os
import shutil

import numpy as np

from ..errors import InputError, option

#: what ``check_output`` checks a path for
KINDS = ("dir", "file")


def check_output(path: str, kind: str = "dir", flag: str | None = None, new_folders: bool | None = None) -> str:
    """``path`` as an output of ``kind`` ("dir": a folder, made or merged
    into; "file"), checked before any work: an InputError in one line
    naming ``flag`` (``errors.option``; None: the path alone) when a file
    stands where a folder is wanted or a folder where a file is, when the
    path lies inside a file, or when its folder is missing (a folder's own
    parents are made, a file's are not unless ``new_folders``) or not
    writable. Returns the absolute path."""
    if kind not in KINDS:
        raise ValueError(f"kind={kind!r}: expected one of {KINDS}")
    problem = _output_problem(path, kind, kind == "dir" if new_folders is None else new_folders)
    if problem:
        raise InputError(f"{option(flag, path) if flag else path}: {problem}")
    return os.path.abspath(path)


def _output_problem(given: str, kind: str, new_folders: bool) -> str | None:
    """Why the path ``given`` cannot be written as ``kind``, or None (folders
    named as the caller gave them)."""
    path = os.path.normpath(given)
    if os.path.isdir(path) and kind == "file":
        return "is a folder, not a file"
    if os.path.exists(path) and not os.path.isdir(path) and kind == "dir":
        return "is a file, not a folder"
    parent = existing = os.path.dirname(path) or "."
    while not os.path.exists(existing):
        existing = os.path.dirname(existing) or "."
    if not os.path.isdir(existing):
        return f"lies inside {existing}, which is a file"
    if existing != parent and not new_folders:
        return f"folder {parent} does not exist"
    for folder in [existing] + ([path] if os.path.isdir(path) else []):  # a folder's stage sits beside it
        if not os.access(folder, os.W_OK | os.X_OK):
            return f"folder {folder} is not writable"
    return None


@contextlib.contextmanager
def staged_dir(out: str):
    """Yield a staging path beside ``out`` (checked first, ``check_output``);
    when the block succeeds its content replaces or merges into ``out``; on
    any failure, KeyboardInterrupt included, the stage is removed."""
    out = check_output(out, "dir")
    parent = os.path.dirname(out)
    os.makedirs(parent, exist_ok=True)
    stage = os.path.join(parent, f".{os.path.basename(out)}.partial-{os.getpid()}")
    shutil.rmtree(stage, ignore_errors=True)
    os.makedirs(stage)
    try:
        yield stage
        _place(stage, out)
    finally:
        shutil.rmtree(stage, ignore_errors=True)


def _place(stage: str, out: str) -> None:
    """Move the staged tree into ``out``: renamed when ``out`` is new, else file by file."""
    if not os.path.exists(out):
        os.replace(stage, out)
        return
    for root, _, files in os.walk(stage):
        rel = os.path.relpath(root, stage)
        os.makedirs(os.path.join(out, rel), exist_ok=True)
        for f in files:
            os.replace(os.path.join(root, f), os.path.join(out, rel, f))


@contextlib.contextmanager
def removed_on_failure(out: str):
    """Within: when ``out`` did not exist before and the block fails (Ctrl-C
    included), ``out`` is removed (a verb that writes in steps, e.g. records,
    then their calibration)."""
    new = not os.path.exists(out)
    try:
        yield
    except BaseException:
        if new:
            shutil.rmtree(out, ignore_errors=True)
        raise


@contextlib.contextmanager
def atomic_file(path: str, mode: str = "w"):
    """Yield a file handle whose content replaces ``path`` only when the block
    succeeds (a temporary file beside it, renamed into place; its folders
    are made); on any failure, KeyboardInterrupt included, nothing is left."""
    check_output(path, "file", new_folders=True)
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
