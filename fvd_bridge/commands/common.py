"""Options shared by verbs that read records."""

from __future__ import annotations

import argparse
import os

from ..records import ReadOptions, parse_mapping, read_record


def add_record_options(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("reading records (or a YAML sidecar NAME.yaml next to each file)")
    g.add_argument("--columns", help="column mapping, e.g. t=time,d=disp,F=load (CSV header names) "
                                     "or d=0,F=2 (.mat column indices with --mat-var)")
    g.add_argument("--units", help="units of the columns, e.g. t=ms,d=m,F=N (default s, mm, kN, mm/s)")
    g.add_argument("--mat-var", help=".mat variable holding the columns, e.g. x_F")
    g.add_argument("--dt", type=float, help="time step [s] when the file has no time column")
    g.add_argument("--sg-window", type=int, help="Savitzky-Golay window [samples] for velocity, the same "
                                                 "over the whole record (odd; default: chosen per sample "
                                                 "from the record's noise, ICI rule)")
    g.add_argument("--sg-order", type=int, default=3, help="Savitzky-Golay polynomial order (default 3)")


def read_options(args) -> ReadOptions:
    return ReadOptions(columns=parse_mapping(args.columns, "--columns"),
                       units=parse_mapping(args.units, "--units"),
                       mat_var=args.mat_var, dt=args.dt,
                       sg_window=args.sg_window, sg_order=args.sg_order)


def read_records(paths, args):
    opts = read_options(args)
    return [read_record(p, opts) for p in paths]


def quiet_opensees() -> None:
    """Send OpenSees' console output (banners, per-step convergence warnings)
    to nowhere for the rest of this process: the analyses report their own
    solver trouble (FrameResult.solver, the export check's OF)."""
    import openseespy.opensees as ops

    ops.logFile(os.devnull, "-noEcho")
