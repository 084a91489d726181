"""MATLAB .mat reader (v4 to v7; not v7.3/HDF5).

Two layouts:

* one matrix holding the columns: ``mat_var='x_F'``, ``columns={'d': '0',
  'F': '2'}`` (0-based column indices; a matrix stored one signal per row is
  transposed);
* one vector variable per signal: ``columns={'t': 'tout', 'd': 'dist', 'F': 'forc'}``.

Time comes from a ``t`` column, else from ``dt`` [s], else from a scalar
variable ``Ts`` [s] in the file. Rows in messages are matrix rows, from 1.
"""

from __future__ import annotations

import numpy as np
import scipy.io

from ..errors import InputError, option
from .options import Given, ReadOptions
from .raw import RawColumns

#: scalar variable taken as the time step [s] when no t column and no dt is given
TS_VARIABLE = "Ts"


def read_mat(path: str, opts: ReadOptions) -> RawColumns:
    """Read the t/d/F[/v] columns of a .mat file (values in the file's units)."""
    mat = _load(path)
    variables = [k for k in mat if not k.startswith("__")]
    for key in ("d", "F"):
        if key not in opts.columns:
            raise InputError(f"{path}: say which column holds {key}, e.g. {option('--mat-var', 'x_F')} "
                             f"{option('--columns', Given(d=0, F=2))} "
                             f"(variables: {_listing(variables)})")
    if opts.mat_var is not None:
        data, names = _from_matrix(path, mat, variables, opts)
    else:
        data, names = _from_vectors(path, mat, variables, opts)
    time_given = "t" in data
    if not time_given:
        dt, source = _time_step(path, mat, opts)
        n = next(iter(data.values())).size
        data["t"], names["t"] = dt * np.arange(n), f"<dt {dt:g} s from {source}>"
    n = next(iter(data.values())).size
    return RawColumns(data, np.arange(1, n + 1), names, time_given)


def _load(path: str) -> dict:
    try:
        return scipy.io.loadmat(path)
    except NotImplementedError:
        raise InputError(f"{path}: MATLAB v7.3 (HDF5) files are not supported; save with -v7") from None
    except Exception as exc:  # scipy raises several types for corrupt files
        detail = (str(exc).splitlines() or [""])[0][:80]
        raise InputError(f"{path}: not a readable MATLAB file ({type(exc).__name__}"
                         f"{': ' + detail if detail else ''})") from None


def _listing(variables: list[str]) -> str:
    return ", ".join(variables) if variables else "none"


def _numeric(path: str, mat: dict, var: str) -> np.ndarray:
    arr = np.asarray(mat[var])
    if arr.dtype.kind not in "biuf":
        raise InputError(f"{path}: variable '{var}' is not a numeric matrix ({arr.dtype})")
    return arr.astype(float)


def _from_matrix(path: str, mat: dict, variables: list[str], opts: ReadOptions):
    var = opts.mat_var
    if var not in mat:
        raise InputError(f"{path}: variable '{var}' not found (variables: {_listing(variables)})")
    arr = _numeric(path, mat, var)
    if arr.ndim != 2:
        raise InputError(f"{path}: variable '{var}' has {arr.ndim} dimensions; expected a matrix")
    if arr.shape[0] < arr.shape[1]:
        arr = arr.T
    data, names = {}, {}
    for key, col in opts.columns.items():
        try:
            c = int(col)
        except ValueError:
            raise InputError(f"{path}: column '{col}' (for {key}): expected a column index of '{var}' "
                             f"(0..{arr.shape[1] - 1})") from None
        if not 0 <= c < arr.shape[1]:
            raise InputError(f"{path}: column {c} (for {key}) not found: '{var}' is {arr.shape[0]}x{arr.shape[1]}, "
                             f"columns 0..{arr.shape[1] - 1}")
        data[key], names[key] = arr[:, c].copy(), f"{var} column {c}"
    return data, names


def _from_vectors(path: str, mat: dict, variables: list[str], opts: ReadOptions):
    data, names = {}, {}
    for key, var in opts.columns.items():
        if var not in mat:
            hint = f" (give {option('--mat-var', 'NAME')} for column indices)" if var.lstrip("-").isdigit() else ""
            raise InputError(f"{path}: variable '{var}' (for {key}) not found{hint} (variables: {_listing(variables)})")
        arr = _numeric(path, mat, var)
        if arr.ndim > 2 or (arr.ndim == 2 and min(arr.shape) > 1):
            raise InputError(f"{path}: variable '{var}' (for {key}) is {'x'.join(map(str, arr.shape))}, not a vector; "
                             f"use {option('--mat-var', var)} {option('--columns', Given({key: 'INDEX'}))}")
        data[key], names[key] = arr.ravel(), var
    lengths = {names[k]: v.size for k, v in data.items()}
    if len(set(lengths.values())) > 1:
        short = min(lengths, key=lengths.get)
        raise InputError(f"{path}: row {lengths[short] + 1}, column '{short}': missing (columns of unequal length: "
                         + ", ".join(f"{k} has {n}" for k, n in lengths.items()) + ")")
    return data, names


def _time_step(path: str, mat: dict, opts: ReadOptions) -> tuple[float, str]:
    if opts.dt is not None:
        return float(opts.dt), "--dt or sidecar"
    if TS_VARIABLE in mat:
        ts = np.asarray(mat[TS_VARIABLE])
        if ts.size == 1 and ts.dtype.kind in "biuf":
            dt = float(ts.ravel()[0])
            if np.isfinite(dt) and dt > 0:
                return dt, f"variable {TS_VARIABLE}"
        raise InputError(f"{path}: variable '{TS_VARIABLE}' is not a positive time step; give {option('--dt', 'SECONDS')}")
    raise InputError(f"{path}: no time column; give {option('--dt', 'SECONDS')} or {option('--columns', Given(t='...'))}")
