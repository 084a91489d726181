"""``fvd-bridge export``: a calibrated damper as an OpenSees material (script or Tcl)."""

from __future__ import annotations

import os
import sys

from ..errors import InputError
from .common import add_record_options, read_records


def add_parser(sub):
    p = sub.add_parser("export", help="export a calibrated damper: OpenSees material definition",
                       description="Turn a calibration file (params/<device>/law<SPEC>.yaml) into the tools "
                                   "engineers use. 'opensees': the damper's uniaxial material as an OpenSeesPy "
                                   "script (.py) or Tcl (.tcl), native materials where exact; --check drives one "
                                   "OpenSees material with a record's displacement and compares the force.")
    targets = p.add_subparsers(dest="target", metavar="TARGET", required=True)
    o = targets.add_parser("opensees", help="OpenSees uniaxial material (OpenSeesPy script or Tcl)",
                           description="Write the damper's OpenSees material definition; the language follows "
                                       "the suffix of -o (.py OpenSeesPy, .tcl Tcl; default: print the Python "
                                       "script). Models OpenSees cannot express are refused (exit 2) with the "
                                       "FMU export named as the way.")
    o.add_argument("params", metavar="PARAMS.yaml", help="calibration file")
    o.add_argument("-o", "--output", metavar="FILE", help="damper.py or damper.tcl (default: print to stdout)")
    o.add_argument("--tag", type=int, default=1, help="material tag of the damper (helpers get tag+1, ...)")
    o.add_argument("--check", metavar="RECORD",
                   help="drive the OpenSees material with this record's displacement and compare its force with "
                        "fvd_bridge's model (eq. 18); exit 1 with a figure when it misses the documented bound")
    add_record_options(o)
    o.set_defaults(func=run_opensees)


def run_opensees(args) -> int:
    from ..calibration import Calibration
    from ..export.opensees import opensees_export, to_script

    if args.tag < 1:
        raise InputError(f"--tag {args.tag}: must be at least 1")
    lang = "py"
    if args.output:
        ext = os.path.splitext(args.output)[1].lower()
        if ext not in (".py", ".tcl"):
            raise InputError(f"-o {args.output}: the suffix must be .py (OpenSeesPy) or .tcl (Tcl)")
        lang = ext[1:]
    cal = Calibration.load(args.params)
    export = opensees_export(cal.model, cal.named(), args.tag)
    record = read_records([args.check], args)[0] if args.check else None
    script = to_script(export, lang)
    if record is not None and _check(cal, record, args):
        return 1  # the export failed its check: no script written
    if args.output:
        tmp = f"{args.output}.partial-{os.getpid()}"
        with open(tmp, "w") as fh:
            fh.write(script)
        os.replace(tmp, args.output)
        print(f"wrote {args.output}: model {cal.spec}, damper material {export.tag} "
              f"({'exact' if export.exact else 'approximate: ' + export.note})", file=sys.stderr)
    else:
        sys.stdout.write(script)
    return 0


def _check(cal, record, args) -> int:
    """OpenSees against the model on the record's motion; 1 when off its bound.

    Both are driven by one consistent motion: the displacement integrated from
    the record's velocity (trapezoidal rule, from 0 where OpenSees materials
    start), so that displacement noise, which the derived velocity has
    smoothed away, reaches neither."""
    import numpy as np

    from ..export.opensees_check import check

    d = np.concatenate([[0.0], np.cumsum(0.5 * (record.v[1:] + record.v[:-1]) * np.diff(record.t))])
    res = check(cal.model, cal.named(), record.t, d, record.v, record.a)
    verdict = "within" if res.ok else "OUTSIDE"
    print(f"check on {record.name}: OF(OpenSees vs model) = {res.of:.3g}, {verdict} the bound {res.bound:.3g} "
          f"({'exact mapping' if res.exact else 'approximation'})", file=sys.stderr)
    if res.ok:
        return 0
    from ..plots.export import check_figure

    base = os.path.splitext(args.output)[0] if args.output else f"{cal.spec}_opensees"
    path = check_figure(record, res.F_model, res.F_opensees, f"OpenSees vs model {cal.spec}: OF {res.of:.3g} "
                        f"(bound {res.bound:.3g})", f"{base}_check.png")
    print(f"the export misses its bound: see {path}", file=sys.stderr)
    return 1
