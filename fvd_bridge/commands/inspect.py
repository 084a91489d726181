"""``fvd-bridge inspect``: validate one record, print its summary, optionally plot it."""

from __future__ import annotations

import warnings

from ..records import RecordWarning, read_record, summarize
from ..text.record import format_summary
from .common import add_record_options, read_options


def add_parser(sub):
    p = sub.add_parser(
        "inspect", help="validate a record and print its summary (samples, dt, cycles, peaks, noise)",
        description="Read and validate a record (CSV with a header, or .mat), print its summary: "
                    "samples, time step [s], duration [s], cycles, peak d [mm], v [mm/s] and F [kN], "
                    "estimated force noise [kN], displacement noise [mm] and velocity noise [mm/s], "
                    "velocity method and warnings. Bad input: one line "
                    "on stderr naming file, row and column, exit code 2.")
    p.add_argument("record", metavar="RECORD", help="record file: .csv (header t,d,F[,v]) or .mat")
    p.add_argument("--plot", metavar="PNG", help="write a quick-look figure (F-t, d-t, F-d, F-v) to this file")
    add_record_options(p)
    p.set_defaults(func=run)


def run(args) -> int:
    opts = read_options(args)
    if args.plot:
        from ..plots.record import check_target, plot_record

        check_target(args.plot)  # before any output: a bad path is one line, exit 2
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RecordWarning)  # listed in the summary instead
        rec = read_record(args.record, opts)
    print(format_summary(summarize(rec)))
    if args.plot:
        plot_record(rec, args.plot)
        print(f"figure       {args.plot}")
    return 0
