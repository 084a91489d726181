"""``fvd-bridge export``: a calibrated damper as an OpenSees material (script or Tcl)."""

from __future__ import annotations

import os
import sys

from ..calibration import Calibration
from ..errors import InputError
from ..fit import objective
from ..golden import golden_record, reference_input
from ..io.staging import atomic_file, check_output
from ..units import system_text
from .common import (CALIBRATION_RECORD, add_plugin_option, add_record_options, add_test_option, read_as_calibrated,
                     read_records)


def add_parser(sub):
    p = sub.add_parser("export", help="export a calibrated damper: OpenSees material, FMI 3 co-simulation FMU",
                       description="Turn a calibration file (params/<device>/law<SPEC>.yaml) into the tools "
                                   "engineers use. 'opensees': the damper's uniaxial material as an OpenSeesPy "
                                   "script (.py) or Tcl (.tcl), native materials where exact; --check drives one "
                                   "OpenSees material with a record's displacement and compares the force. "
                                   "'fmu': an FMI 3.0 co-simulation FMU (C sources included), built, validated "
                                   "and checked against the Python model.")
    targets = p.add_subparsers(dest="target", metavar="TARGET", required=True)
    o = targets.add_parser("opensees", help="OpenSees uniaxial material (OpenSeesPy script or Tcl)",
                           description="Write the damper's OpenSees material definition; the language follows "
                                       "the suffix of -o (.py OpenSeesPy, .tcl Tcl; default: print the Python "
                                       "script). Models OpenSees cannot express are refused (exit 2) with the "
                                       "FMU export named as the way.")
    o.add_argument("params", metavar="PARAMS.yaml", help="calibration file")
    o.add_argument("-o", "--output", metavar="FILE", help="damper.py or damper.tcl (default: print to stdout)")
    o.add_argument("--tag", type=int, default=1, help="material tag of the damper (helpers get tag+1, ...)")
    o.add_argument("--units", dest="units_out", metavar="FORCE,LENGTH,TIME",
                   help="units of the OpenSees model the damper goes into, e.g. kN,m,s or N,mm,s or kip,in,s "
                        "(or F=kN,d=m,t=s; default kN,mm,s): every value is converted, a dashpot's C with its "
                        "exponent")
    o.add_argument("--check", metavar="RECORD", nargs="?", const=CALIBRATION_RECORD,
                   help="drive the OpenSees material with this record's displacement (without RECORD: the "
                        "calibration record, read as it was read) and compare its force with fvd_bridge's model "
                        "(eq. 18); exit 1 with a figure when it misses the documented bound")
    add_test_option(o)
    add_plugin_option(o)
    add_record_options(o, units_flag="--record-units")
    o.set_defaults(func=run_opensees)
    f = targets.add_parser("fmu", help="FMI 3.0 co-simulation FMU of the calibrated damper",
                           description="Build an FMI 3.0 co-simulation FMU (input d [mm], optional v, a; output F "
                                       "[kN], z, E) with the calibrated parameters as start values, compile its "
                                       "binary with the system C compiler (the C sources stay inside), run "
                                       "fmpy's validation and simulate it on the calibration record (or --check "
                                       "RECORD; the golden input when the record is not found): the export "
                                       "fails (exit 1, with a figure) when the OF against the Python model "
                                       "exceeds 0.002.")
    f.add_argument("params", metavar="PARAMS.yaml", help="calibration file")
    f.add_argument("-o", "--output", required=True, metavar="FILE.fmu", help="the FMU to write")
    f.add_argument("--h-max", type=float, metavar="S",
                   help="largest internal sub-step [s] (default: the calibration record's dt)")
    f.add_argument("--check", metavar="RECORD", help="check on this record instead of the calibration record")
    add_test_option(f)
    add_plugin_option(f)
    add_record_options(f)
    f.set_defaults(func=run_fmu)


def run_opensees(args) -> int:
    from ..export.opensees import opensees_export, to_script

    if args.tag < 1:
        raise InputError(f"--tag {args.tag}: must be at least 1")
    lang = "py"
    if args.output:
        ext = os.path.splitext(args.output)[1].lower()
        if ext not in (".py", ".tcl"):
            raise InputError(f"-o {args.output}: the suffix must be .py (OpenSeesPy) or .tcl (Tcl)")
        check_output(args.output, "file", "-o")
        lang = ext[1:]
    cal = Calibration.load(args.params, plugins=args.plugin).for_test(args.test)
    export = opensees_export(cal.model, cal.named(), args.tag, units=args.units_out, tested=cal.tested)
    record = None
    if args.check == CALIBRATION_RECORD:
        record = read_as_calibrated(cal.record, args)
        if record is None:
            raise InputError(f"--check: the calibration record of {args.params} is not found "
                             f"({cal.record.file}); give --check RECORD")
    elif args.check:
        record = read_records([args.check], args)[0]
    if record is not None:
        _warn_beyond(cal, record)
    script = to_script(export, lang, cal.export_lines(export))
    res = None if record is None else _check(cal, export, record, args)
    if res is not None and not res.ok:
        return 1  # the export failed its check: no script written
    if args.output:
        with atomic_file(args.output) as fh:
            fh.write(script)
        print(f"wrote {args.output}: model {cal.spec}, damper material {export.tag} "
              f"({'exact' if export.exact else 'approximate: ' + export.note})", file=sys.stderr)
        check = None if res is None else {"record": record.name, "of": res.of, "bound": res.bound, "ok": res.ok}
        _note(cal, args, "opensees", args.output, system_text(export.units), check, export.exact)
    else:
        sys.stdout.write(script)
    return 0


def _check(cal, export, record, args):
    """OpenSees against the model on the record's motion
    (``opensees_check.check_on_record``): its CheckResult, said on stderr,
    with a figure when it misses its bound."""
    from ..export.opensees_check import check_on_record, quiet_opensees

    quiet_opensees()
    res = check_on_record(cal, record, export)
    verdict = "within" if res.ok else "OUTSIDE"
    print(f"check on {record.name}: OF(OpenSees vs model) = {res.of:.3g}, {verdict} the bound {res.bound:.3g} "
          f"({'exact mapping' if res.exact else 'approximation'})", file=sys.stderr)
    if res.ok:
        return res
    from ..plots.export import check_figure

    base = os.path.splitext(args.output)[0] if args.output else f"{cal.spec}_opensees"
    path = check_figure(record, res.F_model, res.F_opensees, f"OpenSees vs model {cal.spec}: OF {res.of:.3g} "
                        f"(bound {res.bound:.3g})", f"{base}_check.png")
    print(f"the export misses its bound: see {path}", file=sys.stderr)
    return res


def _warn_beyond(cal, record) -> None:
    """Say on stderr where a check record goes beyond the calibration's tested range."""
    for line in cal.beyond_tested(record):
        print(f"warning: {line}", file=sys.stderr)


def _fmu_check_record(cal, args):
    """The record the FMU is checked on: --check, the calibration record
    (read as it was read), or the golden input when that record is gone
    (said on stderr)."""
    if args.check:
        return read_records([args.check], args)[0]
    try:
        record = read_as_calibrated(cal.record, args)
    except InputError as exc:  # a file written before calibration files kept their reading options
        print(f"warning: checked on the golden input: the calibration record needs its reading options "
              f"(give --check RECORD with them): {exc}", file=sys.stderr)
    else:
        if record is not None:
            return record
        print(f"warning: checked on the golden input: the calibration record "
              f"({cal.record.file}) is not found; give --check RECORD", file=sys.stderr)
    t, d, v, a = reference_input()
    return golden_record({"t": t, "d": d, "v": v, "a": a})


def run_fmu(args) -> int:
    """Build, validate and check the FMU; nothing is left at -o when a step fails."""
    from ..export.fmu import OF_BOUND, build_fmu, fmu_forces
    from ..export.fmu_toolchain import toolchain_problem

    if not args.output.lower().endswith(".fmu"):
        raise InputError(f"-o {args.output}: the file name must end in .fmu")
    check_output(args.output, "file", "-o")
    problem = toolchain_problem()  # before any other word: building cannot work here
    if problem:
        raise InputError(problem)
    cal = Calibration.load(args.params, plugins=args.plugin).for_test(args.test)
    record = _fmu_check_record(cal, args)
    if args.check:
        _warn_beyond(cal, record)
    tmp = f"{args.output}.partial-{os.getpid()}.fmu"  # build_fmu writes atomically; moved into place once checked
    try:
        build_fmu(cal, tmp, args.h_max)
        F_model, F_fmu = fmu_forces(tmp, cal, record, ("dva@end", "d"))
        of_mirror, of_d = (float(objective(F_model, F, record.t)) for F in (F_fmu["dva@end"], F_fmu["d"]))
        print(f"check on {record.name}: OF(FMU vs model) = {of_mirror:.3g} with the record's d, v, a at each "
              f"step's end (bound {OF_BOUND:g}); {of_d:.3g} with d alone at the communication points, as an FMI "
              f"master sets it (the FMU differentiates d and extrapolates it over the step)", file=sys.stderr)
        if of_mirror > OF_BOUND:
            from ..plots.export import check_figure

            path = check_figure(record, F_model, F_fmu["dva@end"], f"FMU vs model {cal.spec}: OF {of_mirror:.3g}",
                                f"{os.path.splitext(args.output)[0]}_check.png", label="FMU")
            print(f"the FMU misses its bound: see {path}", file=sys.stderr)
            return 1
        os.replace(tmp, args.output)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)
    print(f"wrote {args.output}: model {cal.spec}, FMI 3.0 co-simulation, validated", file=sys.stderr)
    _note(cal, args, "fmu", args.output, system_text(),  # the FMU speaks kN, mm, s
          {"record": record.name, "of": of_mirror, "bound": OF_BOUND, "ok": True, "of_d_only": of_d})
    return 0


def _note(cal, args, kind, file, units, check, exact=None) -> None:
    """Note the export in its calibration's output folder (``export.ledger``)
    and build that folder's report again (with the verb's plugins); nothing
    when the file lives elsewhere."""
    from ..export.ledger import note_export, output_folder
    from ..report.page import build_report

    out = output_folder(args.params)
    if out is None:
        return
    note_export(out, cal, args.params, kind, file, units, check, exact)
    try:
        print(f"noted in {build_report(out, plugins=args.plugin)}", file=sys.stderr)
    except InputError as exc:  # the export stands; the page waits for `fvd-bridge report`
        print(f"warning: noted in {out}/exports.json; its report.html was not built again: {exc}", file=sys.stderr)
