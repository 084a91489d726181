"""Options shared by verbs that read records or calibration files."""

from __future__ import annotations

import argparse
import os

import numpy as np

from .. import timing
from ..errors import InputError
from ..records import ReadOptions, parse_mapping, read_record
from ..records.options import FORCE_SIGNS, NO_COLUMN
from ..records.readers import cut, read_as_stored


def add_record_options(p: argparse.ArgumentParser, units_flag: str = "--units") -> None:
    """The reading options; ``units_flag``: the flag of the columns' units
    (a verb whose --units means something else names it otherwise)."""
    g = p.add_argument_group("reading records (or a YAML sidecar NAME.yaml next to each file)")
    g.add_argument("--columns", help="column mapping, e.g. t=time,d=disp,F=load (CSV header names) "
                                     "or d=0,F=2 (.mat column indices with --mat-var); v=none leaves a "
                                     "measured velocity out (v derived from d)")
    g.add_argument(units_flag, dest="units",
                   help="units of the columns, e.g. t=ms,d=m,F=N (default s, mm, kN, mm/s)")
    g.add_argument("--mat-var", help=".mat variable holding the columns, e.g. x_F")
    g.add_argument("--dt", type=float, help="time step [s] when the file has no time column")
    g.add_argument("--force-sign", choices=FORCE_SIGNS,
                   help="flip: negate F (the load cell reads the opposite sign: the loops generate energy); "
                        "keep: the sign is right as read. Default: a record whose loops generate energy is "
                        "refused (inspect lists it)")
    g.add_argument("--sg-window", type=int, help="Savitzky-Golay window [samples] for velocity, the same "
                                                 "over the whole record (odd; default: chosen per sample "
                                                 "from the record's noise, ICI rule)")
    g.add_argument("--sg-order", type=int, default=3, help="Savitzky-Golay polynomial order (default 3)")
    g.add_argument("--window", metavar="T0,T1", help="use only T0 <= t <= T1 [s] of each record (e.g. to leave "
                                                     "out a rest at the start); the velocity is derived first")


def add_plugin_option(p: argparse.ArgumentParser) -> None:
    """--plugin FILE.py: a plugin the calibration files' models need (a file never runs code by itself)."""
    p.add_argument("--plugin", action="append", default=[], metavar="FILE.py",
                   help="plugin file of effects of your own that a calibration file's model needs (repeatable); "
                        "it must be the file the calibration records (name and sha256). A calibration file "
                        "never runs code: its plugins run only when you give them here")


def add_test_option(p: argparse.ArgumentParser) -> None:
    """--test NAME: the test whose values a calibration with parameters fitted per test takes."""
    p.add_argument("--test", metavar="NAME",
                   help="a calibration with a parameter fitted per test (calibrate --per-test) takes this test's "
                        "values, and its header names the test; without it such a calibration is refused (exit 2) "
                        "with its tests named. Calibrations whose parameters are all shared need none")


def read_options(args) -> ReadOptions:
    columns = parse_mapping(args.columns, "--columns")
    derive = columns.get("v") == NO_COLUMN  # --columns v=none: derive v from d
    if derive:
        del columns["v"]
    return ReadOptions(columns=columns, units=parse_mapping(args.units, "--units"),
                       mat_var=args.mat_var, dt=args.dt, sg_window=args.sg_window, sg_order=args.sg_order,
                       derive_velocity=derive, force_sign=args.force_sign)


def window(record, text: str):
    """The record's samples with T0 <= t <= T1 (``--window T0,T1`` [s]), the
    window kept in its provenance; one line naming the option when it holds
    too few samples."""
    try:
        t0, t1 = (float(x) for x in text.split(","))
    except ValueError:
        raise InputError(f"--window '{text}': expected T0,T1 in s, e.g. 2,10") from None
    kept = int(np.count_nonzero((record.t >= t0) & (record.t <= t1)))
    if not t0 < t1 or kept < 16:
        raise InputError(f"--window '{text}': holds {kept} samples of {record.name} "
                         f"({record.t[0]:g} to {record.t[-1]:g} s); need T0 < T1 and at least 16")
    return cut(record, t0, t1)


def read_records(paths, args):
    """The records at ``paths``, read with the verb's reading options (and
    cut to ``--window``); a doubt (loops that generate energy, a force per
    stroke beyond any damper test's) is refused: these verbs fit or judge
    the record, and the result would be silently wrong."""
    opts = read_options(args)
    with timing.stage("read records, derive velocity"):
        records = [read_record(p, opts, refuse_doubts=True) for p in paths]
    return [window(r, args.window) for r in records] if getattr(args, "window", None) else records


#: ``--check`` without a value: the calibration record
CALIBRATION_RECORD = "<the calibration record>"
#: the verbs' reading options (add_record_options)
READING = ("columns", "units", "mat_var", "dt", "sg_window", "window", "force_sign")


def read_as_calibrated(source, args):
    """The calibration's record (its RecordSource, ``Calibration.record``)
    read again as calibrate read it (``records.readers.read_as_stored``), or
    with the verb's reading options where the user gives any; None when the
    file is not there."""
    path = source.file
    if path and os.path.isfile(path) and any(getattr(args, key, None) is not None for key in READING):
        return read_records([path], args)[0]
    return read_as_stored(source)
