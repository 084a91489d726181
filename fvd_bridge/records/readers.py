"""read_record: a CSV or .mat file -> converted, validated, differentiated Record.

Steps: sidecar -> read columns (csvfile / matfile) -> finite -> units to
kN, mm, s (and the force's sign) -> time checks -> constant/absurd checks ->
uniform grid -> cycles -> velocity (measured, or Savitzky-Golay from d with a
window chosen per sample, velocity.py) and noise estimates -> doubts ->
provenance. Any fault is an InputError naming the file, row and column; notes
(resampling, suspicious units, no unit information at all) are kept in
``Record.warnings`` and issued as RecordWarning. Doubts are notes that make
a fit of the record wrong until the user settles them, in this order: d and
F columns that look swapped (validate.swapped_columns_note), magnitudes no
damper test has in a file without units (plausible.unit_doubt), loops that
generate energy (the force's sign; not asked when the columns look
swapped). They come first in ``Record.warnings``, and a verb that fits or
judges the record refuses them (``read_record(..., refuse_doubts=True)``);
a fault found later that the first two explain (a unit absurd, a measured
velocity far off) is reported as that doubt.
"""

from __future__ import annotations

import contextlib
import os
import warnings

import numpy as np

from ..errors import InputError, option
from ..units import CANONICAL, factor, unit_system
from . import plausible, validate
from .cycles import displacement_noise
from .csvfile import read_csv
from .matfile import read_mat
from .options import FORCE_SIGNS, Given, ReadOptions, parse_mapping, with_sidecar
from .raw import RawColumns
from .record import Record
from .velocity import acceleration_from_velocity, check_settings, derive

__all__ = ["ReadOptions", "RecordWarning", "cut", "parse_mapping", "read_as_stored", "read_record",
           "record_from_arrays"]


class RecordWarning(UserWarning):
    """A record was read but something about it deserves a look."""


def read_record(path: str, opts: ReadOptions | None = None, name: str | None = None,
                refuse_doubts: bool = False) -> Record:
    """Read, convert to kN/mm/s, validate and differentiate one record file.

    Parameters
    ----------
    path : str or path-like
        A CSV file with a header (t, d, F[, v]) or a .mat file; a YAML
        sidecar beside it (``NAME.yaml``) gives its columns and units.
    opts : ReadOptions, optional
        Columns, units, the .mat variable, the time step, the velocity
        differentiator's settings (default: the sidecar's, else kN, mm, s).
    name : str, optional
        The record's name; default the file's stem.
    refuse_doubts : bool
        Raise the first doubt (the force's sign, the units) as an InputError
        instead of issuing it as a RecordWarning (calibrate, diagnose,
        compare: a fit of such a record would be silently wrong).

    Returns
    -------
    Record
        Bad input raises InputError naming the file, row and column; notes
        are issued as RecordWarning.
    """
    path = os.fspath(path)
    if not os.path.exists(path):
        raise InputError(f"{path}: no such file")
    if os.path.isdir(path):
        raise InputError(f"{path}: is a directory, not a record file")
    given = opts or ReadOptions()
    opts = _checked(path, with_sidecar(path, given))
    raw = read_mat(path, opts) if path.lower().endswith(".mat") else read_csv(path, opts)
    rec = _assemble(path, raw, opts, name)
    if refuse_doubts and rec.provenance["doubts"]:
        raise InputError(rec.provenance["doubts"][0])
    rec.provenance["reading"] = given.as_dict()  # read again as it was read (export --check, compare)
    for note in rec.warnings:
        warnings.warn(note, RecordWarning, stacklevel=2)
    return rec


def record_from_arrays(t, d, F, v=None, units=None, name: str = "record") -> Record:
    """A Record from arrays, read as a file is: t [s], d, F (and a measured
    v) in ``units`` (FORCE,LENGTH,TIME: 'N,m,s', ('N', 'm', 's') or {F, d,
    t}; None: kN, mm, s), converted, checked and the velocity derived from d
    (``Record.from_arrays``).  Bad values are input errors naming the array
    and its index + 1 as the row."""
    system = unit_system(units, "units")
    where = f"Record.from_arrays({name})"
    data = {"t": t, "d": d, "F": F, **({} if v is None else {"v": v})}
    arrays = {}
    for key, x in data.items():
        try:
            arrays[key] = np.asarray(x, dtype=float).reshape(-1)
        except (TypeError, ValueError):
            raise InputError(f"{where}: {key} is not an array of numbers") from None
    sizes = {k: x.size for k, x in arrays.items()}
    if len(set(sizes.values())) != 1:
        raise InputError(f"{where}: t, d, F{', v' if v is not None else ''} need one length, got "
                         + ", ".join(f"{k} {n}" for k, n in sizes.items()))
    units_of = {"t": system["t"], "d": system["d"], "F": system["F"]}
    if v is not None:
        units_of["v"] = f"{system['d']}/{system['t']}"
    raw = RawColumns(arrays, np.arange(1, sizes["t"] + 1), {k: k for k in arrays})
    rec = _assemble(where, raw, ReadOptions(units=units_of), name)
    rec.provenance.update(file=None, format="arrays")
    for note in rec.warnings:
        warnings.warn(note, RecordWarning, stacklevel=3)
    return rec


Record._from_arrays = staticmethod(record_from_arrays)  # Record.from_arrays (record.py)


def cut(record: Record, t0: float, t1: float) -> Record:
    """The samples with t0 <= t <= t1 [s] (at least one), the window kept in the provenance."""
    keep = np.flatnonzero((record.t >= t0) & (record.t <= t1))
    out = record.slice(int(keep[0]), int(keep[-1]) + 1)
    out.provenance["window"] = [t0, t1]
    return out


def read_as_stored(source, name: str | None = None) -> Record | None:
    """A calibration's record (its RecordSource: file, reading, window [s])
    read again as it was read: its stored reading options and window (notes
    said then are not repeated), named ``name`` (a test's; default the
    file's); None when its file is not there."""
    if not source.file or not os.path.isfile(source.file):
        return None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RecordWarning)
        record = read_record(source.file, ReadOptions.from_dict(source.reading), name=name)
    return cut(record, *source.window) if source.window else record


def _checked(path: str, opts: ReadOptions) -> ReadOptions:
    """Refuse option values that no file could satisfy (the sidecar checked its own)."""
    for key, unit in opts.units.items():
        factor(key, unit, f"{path}: {option('--units', Given({key: unit}))}: ")
    if opts.dt is not None and not (np.isfinite(opts.dt) and opts.dt > 0):
        raise InputError(f"{option('--dt', f'{opts.dt:g}')}: must be a positive time step in s")
    check_settings(opts.sg_window, opts.sg_order)
    if opts.force_sign not in (None, *FORCE_SIGNS):
        raise InputError(f"{option('--force-sign', opts.force_sign)}: expected {' or '.join(FORCE_SIGNS)}")
    return opts


def _assemble(path: str, raw: RawColumns, opts: ReadOptions, name: str | None) -> Record:
    notes: list[str] = []
    validate.check_length(path, raw.rows)
    for key, x in raw.data.items():
        validate.check_finite(path, raw.names[key], x, raw.rows)
    stated = {**raw.units, **opts.units}  # the caller's and the sidecar's win over the header's
    units = {k: stated.get(k, CANONICAL[k]) for k in raw.data}
    if not raw.time_given:
        if "t" in opts.units and opts.units["t"] != "s":
            notes.append(f"{path}: {option('--units', Given(t=opts.units['t']))} ignored: there is no time column "
                         f"and the time step is in s")
        units["t"] = "s"
    factors = {k: factor(k, units[k], f"{path}: ") for k in raw.data}
    conv = {k: x * factors[k] for k, x in raw.data.items()}
    if opts.force_sign == "flip":  # the load cell reads the opposite sign
        conv["F"] = -conv["F"]
    t = conv.pop("t")
    off_grid = validate.check_time(path, raw.names["t"], t, raw.rows)
    early = _early_doubts(path, raw, opts, conv, stated)
    with _explained_by(early):
        for key in ("d", "F", "v"):
            if key in conv:
                validate.check_signal(path, raw.names[key], key, conv[key], raw.rows,
                                      units[key], factors[key], CANONICAL[key])
        t, conv, note = validate.uniform_grid(t, conv, path, off_grid)
        notes += [note] if note else []
        n_cycles = validate.check_cycles(path, raw.names["d"], conv["d"])
        dt = float(t[1] - t[0])
        der = derive(conv["d"], dt, opts.sg_window, opts.sg_order, f"{path}: ", t0=float(t[0]))
        if "v" in conv:
            validate.check_velocity(path, raw.names["v"], conv["v"], der.v)
    if "v" in conv:
        v = conv["v"]
        v_noise = np.full(v.size, displacement_noise(v))
        a, a_noise, acc = acceleration_from_velocity(v, dt, opts.sg_window, opts.sg_order, f"{path}: ",
                                                     float(v_noise[0]))
        vel = {"method": "measured", "column": raw.names["v"], "d_noise_mm": der.d_noise,
               "v_noise_mm_s": float(v_noise[0]), "acceleration": acc}
    else:
        v, a, v_noise, a_noise, vel = der.v, der.a, der.v_noise, der.a_noise, der.settings
    if not stated:
        notes.append(f"{path}: no unit information: read as " + ", ".join(
            f"{k} [{CANONICAL[k]}]" for k in ("t", "d", "F", "v") if k in raw.data)
            + f"; give the units ({option('--units', Given(d='m', F='N'))}, e.g.), a sidecar or a header such "
            f"as 'F [N]'")
    overrides = unit_overrides(path, raw, opts)
    notes += overrides + validate.unit_notes(path, dt, raw.names)
    notes += validate.rest_offset_note(path, t, conv["d"], conv["F"], raw.names)
    prov = {"file": os.path.abspath(path), "format": "mat" if path.lower().endswith(".mat") else "csv",
            "columns": dict(raw.names), "units": units, "factors": factors,
            "rows": [int(raw.rows[0]), int(raw.rows[-1])], "resampled": note is not None,
            "velocity": vel, "cycles": round(n_cycles, 2)}
    if raw.units:
        prov["header_units"] = dict(raw.units)
    if overrides:  # carried into a calibration's warnings (Calibration.from_fit)
        prov["unit_overrides"] = overrides
    if opts.mat_var is not None and prov["format"] == "mat":
        prov["mat_var"] = opts.mat_var
    if opts.sidecar:
        prov["sidecar"] = os.path.abspath(opts.sidecar)
    if opts.force_sign:
        prov["force_sign"] = opts.force_sign
    rec = Record(t, conv["d"], conv["F"], v, a, name=name or os.path.splitext(os.path.basename(path))[0],
                 provenance=prov, warnings=notes, d_noise=der.d_noise, v_noise=v_noise, a_noise=a_noise,
                 windows=None if "v" in conv else (der.v_window, der.a_window))
    swapped = any("look swapped" in doubt for doubt in early)
    sign = None if opts.force_sign or swapped else validate.reversed_force_note(path, raw.names["F"], t, rec.F, rec.v)
    doubts = early + ([sign] if sign else [])
    rec.provenance["doubts"] = doubts
    rec.warnings[:0] = doubts
    return rec


def unit_overrides(path: str, raw: RawColumns, opts: ReadOptions) -> list[str]:
    """A note per column read in a unit other than the one the file states
    (its sidecar's, replaced by the caller's; its header's, replaced by the
    caller's or the sidecar's) by a different factor: the reading follows
    the caller, visibly (a file in in/kip read as mm/kN is a plausible
    small damper that no later check can tell apart)."""
    notes = []
    side = f"its sidecar {os.path.basename(opts.sidecar)}" if opts.sidecar else ""
    for states, units in ((side, opts.sidecar_units), ("its header", raw.units)):
        for key, unit in units.items():
            used = opts.units.get(key, unit)
            if key in raw.names and factor(key, used) != factor(key, unit):
                by = side if opts.sidecar_units.get(key) == used else option("--units", Given({key: used}))
                notes.append(f"{path}: column '{raw.names[key]}' read in {used} ({by}) where {states} says {unit}, "
                             f"a factor {factor(key, unit) / factor(key, used):.4g} apart: check which is right")
    return notes


def _early_doubts(path: str, raw: RawColumns, opts: ReadOptions, conv: dict, stated: dict) -> list[str]:
    """The doubts seen on the columns as read (kN, mm), before any other
    check: the d and F columns swapped, then a file without units whose
    magnitudes no damper test has."""
    specs = {k: opts.columns.get(k, k) for k in ("d", "F")}
    doubts = (validate.swapped_columns_note(path, raw.names, specs, conv["d"], conv["F"]),
              plausible.unit_doubt(path, conv["d"], conv["F"], raw.names, stated))
    return [doubt for doubt in doubts if doubt]


@contextlib.contextmanager
def _explained_by(doubts: list[str]):
    """A fault found within that an earlier doubt explains (a unit absurd, a
    measured velocity off, too few cycles of a force read as d) is reported
    as the doubt, which names the cause."""
    try:
        yield
    except InputError:
        if doubts:
            raise InputError(doubts[0]) from None
        raise
