"""``fvd-bridge report OUT``: build OUT/report.html again from an output folder."""

from __future__ import annotations

import os
import sys

from ..errors import InputError
from ..io.staging import check_output
from .common import add_plugin_option


def add_parser(sub):
    p = sub.add_parser(
        "report", help="build OUT/report.html again from an output folder (calibrate, campaign, diagnose, "
                       "compare, frame)",
        description="Build one self-contained HTML page (figures embedded, nothing fetched from another host) "
                    "from what an output folder holds: per device its tests, fit tables with intervals and "
                    "warnings, the acceptance table, the loops; the series' statistics and Pareto front; a "
                    "diagnosis; a comparison; a frame's verdict. calibrate, campaign, demo, diagnose, compare "
                    "and frame write it themselves.")
    p.add_argument("out", metavar="OUT", help="an output folder of fvd-bridge")
    p.add_argument("--tolerance", type=float, default=None,
                   help="the acceptance checks' tolerance as a share (default: the page's own, else 0.15: +-15%%)")
    add_plugin_option(p)
    p.set_defaults(func=run)


def run(args) -> int:
    from ..report.page import build_report

    if not os.path.isdir(args.out):
        raise InputError(f"{args.out}: no such output folder")
    check_output(args.out, "dir")  # a folder report.html can be written into
    tolerance = args.tolerance
    if tolerance is not None and not 0.0 < tolerance < 1.0:
        raise InputError(f"--tolerance {tolerance:g}: must be a share between 0 and 1 (0.15 is +-15%)")
    known = ("summary.json", "frame_summary.json", "params")
    if not any(os.path.exists(os.path.join(args.out, k)) for k in known) and not any(
            f.endswith(("_diagnose.json", "_compare.json")) for f in os.listdir(args.out)):
        raise InputError(f"{args.out}: not an output folder of fvd-bridge (no params/, summary.json, "
                         f"*_diagnose.json, *_compare.json or frame_summary.json)")
    path = build_report(args.out, tolerance, plugins=args.plugin)
    print(f"wrote {path}", file=sys.stderr)
    return 0
