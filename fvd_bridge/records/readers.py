"""Readers: CSV with header and MATLAB .mat files -> validated Record.

Column mapping and units come from CLI options or a YAML sidecar
``NAME.yaml`` next to the file with the same keys (columns, units, mat_var,
dt); options given explicitly win over the sidecar.
"""

from __future__ import annotations

import csv
import os
import warnings
from dataclasses import dataclass, field

import numpy as np
import yaml

from ..errors import InputError
from ..units import CANONICAL, factor
from . import validate
from .record import Record
from .velocity import acceleration_from_velocity, differentiate


@dataclass
class ReadOptions:
    """How to read a record. ``columns`` maps t/d/F/v to a header name (CSV),
    a column index or a variable name (.mat); ``units`` maps t/d/F/v to a unit."""

    columns: dict = field(default_factory=dict)
    units: dict = field(default_factory=dict)
    mat_var: str | None = None
    dt: float | None = None
    sg_window: int | None = None
    sg_order: int = 3


def parse_mapping(text: str | None, option: str) -> dict:
    """'t=time,d=disp' -> {'t': 'time', 'd': 'disp'}; refuses keys other than t, d, F, v."""
    if not text:
        return {}
    out = {}
    for item in text.split(","):
        key, sep, value = item.partition("=")
        key, value = key.strip(), value.strip()
        if not sep or not value:
            raise InputError(f"{option} '{item}': expected KEY=VALUE (e.g. {option} t=time,d=disp,F=load)")
        if key not in CANONICAL:
            raise InputError(f"{option} '{item}': unknown key '{key}' (expected t, d, F or v)")
        out[key] = value
    return out


def _with_sidecar(path: str, opts: ReadOptions) -> ReadOptions:
    side = os.path.splitext(path)[0] + ".yaml"
    if not os.path.exists(side):
        return opts
    try:
        data = yaml.safe_load(open(side)) or {}
    except yaml.YAMLError as exc:
        raise InputError(f"{side}: not valid YAML ({str(exc).splitlines()[0]})") from None
    if not isinstance(data, dict):
        raise InputError(f"{side}: expected a mapping with keys columns, units, mat_var, dt")
    unknown = set(data) - {"columns", "units", "mat_var", "dt"}
    if unknown:
        raise InputError(f"{side}: unknown key '{sorted(unknown)[0]}' (expected columns, units, mat_var, dt)")
    return ReadOptions(
        columns={**{k: str(v) for k, v in (data.get("columns") or {}).items()}, **opts.columns},
        units={**(data.get("units") or {}), **opts.units},
        mat_var=opts.mat_var or data.get("mat_var"),
        dt=opts.dt if opts.dt is not None else data.get("dt"),
        sg_window=opts.sg_window, sg_order=opts.sg_order)


def read_record(path: str, opts: ReadOptions | None = None, name: str | None = None) -> Record:
    """Read, convert to kN/mm/s, validate and differentiate one record file."""
    opts = _with_sidecar(path, opts or ReadOptions())
    if not os.path.exists(path):
        raise InputError(f"{path}: no such file")
    ext = os.path.splitext(path)[1].lower()
    if ext == ".mat":
        cols, row0, names = _read_mat(path, opts)
    else:
        cols, row0, names = _read_csv(path, opts)
    return _assemble(path, cols, row0, names, opts, name)


def _read_csv(path: str, opts: ReadOptions):
    wanted = {"t": "t", "d": "d", "F": "F", **opts.columns}
    with open(path, newline="") as fh:
        lines = [ln for ln in fh]
    rows = list(csv.reader(ln for ln in lines))
    # skip comment lines ('#') before the header
    first = next((i for i, r in enumerate(rows) if r and not r[0].lstrip().startswith("#")), None)
    if first is None:
        raise InputError(f"{path}: empty file (expected a header such as t,d,F)")
    header = [h.strip() for h in rows[first]]
    body = [(i + 1, r) for i, r in enumerate(rows) if i > first and r and any(c.strip() for c in r)]
    if not body:
        raise InputError(f"{path}: header but no data rows")
    index, names = {}, {}
    for key, col in wanted.items():
        if col not in header:
            if key == "v" and "v" not in opts.columns:
                continue
            raise InputError(f"{path}: column '{col}' (for {key}) not found; header has: {', '.join(header)}")
        index[key], names[key] = header.index(col), col
    if "v" not in index and "v" in header:
        index["v"], names["v"] = header.index("v"), "v"
    data = {k: np.empty(len(body)) for k in index}
    for j, (row_no, r) in enumerate(body):
        if len(r) != len(header):
            raise InputError(f"{path}: row {row_no} has {len(r)} cells, the header has {len(header)} "
                             f"(columns of unequal length)")
        for key, c in index.items():
            cell = r[c].strip()
            try:
                data[key][j] = float(cell)
            except ValueError:
                raise InputError(f"{path}: row {row_no}, column '{names[key]}': '{cell}' is not a number") from None
    return data, body[0][0], names


def _read_mat(path: str, opts: ReadOptions):
    import scipy.io

    try:
        mat = scipy.io.loadmat(path)
    except Exception as exc:  # scipy raises several types for corrupt files
        raise InputError(f"{path}: not a readable MATLAB file ({type(exc).__name__})") from None
    variables = [k for k in mat if not k.startswith("__")]
    wanted = opts.columns or {}
    for key in ("d", "F"):
        if key not in wanted:
            raise InputError(f"{path}: say which column holds {key}, e.g. --mat-var x_F --columns d=0,F=2")
    data, names = {}, {}
    if opts.mat_var is not None:
        if opts.mat_var not in mat:
            raise InputError(f"{path}: variable '{opts.mat_var}' not found (has: {', '.join(variables)})")
        arr = np.atleast_2d(np.asarray(mat[opts.mat_var], dtype=float))
        if arr.shape[0] < arr.shape[1]:
            arr = arr.T
        for key, col in wanted.items():
            try:
                c = int(col)
            except ValueError:
                raise InputError(f"{path}: --columns {key}={col}: expected a column index of '{opts.mat_var}'") from None
            if not 0 <= c < arr.shape[1]:
                raise InputError(f"{path}: --columns {key}={c}: '{opts.mat_var}' has columns 0..{arr.shape[1] - 1}")
            data[key], names[key] = arr[:, c].copy(), f"{opts.mat_var}[:,{c}]"
    else:
        for key, var in wanted.items():
            if var not in mat:
                raise InputError(f"{path}: variable '{var}' (for {key}) not found (has: {', '.join(variables)})")
            data[key], names[key] = np.asarray(mat[var], dtype=float).ravel(), var
        lengths = {names[k]: v.size for k, v in data.items()}
        if len(set(lengths.values())) > 1:
            raise InputError(f"{path}: columns of unequal length: "
                             + ", ".join(f"{k} has {n}" for k, n in lengths.items()))
    if "t" not in data:
        dt = opts.dt
        if dt is None and "Ts" in mat:
            dt = float(np.asarray(mat["Ts"]).ravel()[0])
        if dt is None:
            raise InputError(f"{path}: no time column; give --dt SECONDS or --columns t=...")
        n = next(iter(data.values())).size
        data["t"], names["t"] = dt * np.arange(n), f"dt={dt:g}"
    return data, 1, names


def _assemble(path, cols, row0, names, opts: ReadOptions, name) -> Record:
    units = {k: opts.units.get(k, CANONICAL[k]) for k in CANONICAL}
    for key in opts.units:
        factor(key, opts.units[key], f"{path}: --units: ")
    for key, x in cols.items():
        validate.check_finite(path, names[key], x, row0)
    conv = {k: x * factor(k, units[k], f"{path}: ") for k, x in cols.items()}
    t = conv.pop("t")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        if validate.check_time(path, names["t"], t, row0):
            t, conv = validate.resample_uniform(t, conv, path)
    for key in ("d", "F", "v"):
        if key in conv:
            validate.check_signal(path, names[key], key, conv[key], CANONICAL[key])
    n_cycles = validate.check_cycles(path, names["d"], conv["d"])
    dt = float(t[1] - t[0])
    if "v" in conv:
        v = conv["v"]
        a = acceleration_from_velocity(v, dt, opts.sg_window, opts.sg_order)
        vel = {"method": "measured", "column": names["v"]}
    else:
        v, a, vel = differentiate(conv["d"], dt, opts.sg_window, opts.sg_order)
    prov = {"file": os.path.abspath(path), "columns": names, "units": units,
            "velocity": vel, "cycles": round(n_cycles, 2)}
    rec = Record(t, conv["d"], conv["F"], v, a,
                 name=name or os.path.splitext(os.path.basename(path))[0], provenance=prov)
    rec.warnings = [str(w.message) for w in caught]
    return rec
