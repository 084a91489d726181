"""``fvd-bridge export``: a calibrated damper as an OpenSees material (script
or Tcl), an FMU, or a SAP2000/ETABS damper link."""

from __future__ import annotations

import math
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
    p = sub.add_parser("export", help="export a calibrated damper: OpenSees material, FMI 3 co-simulation FMU, "
                                      "SAP2000/ETABS link",
                       description="Turn a calibration file (params/<device>/law<SPEC>.yaml) into the tools "
                                   "engineers use. 'opensees': the damper's uniaxial material as an OpenSeesPy "
                                   "script (.py) or Tcl (.tcl), native materials where exact; --check drives one "
                                   "OpenSees material with a record's displacement and compares the force. "
                                   "'fmu': an FMI 3.0 co-simulation FMU (C sources included), built, validated "
                                   "and checked against the Python model. 'sap2000', 'etabs': the damper as a "
                                   "SAP2000 ($2k tables) or ETABS (.e2k) damper link property.")
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
    for target, program, suffix in (("sap2000", "SAP2000", ".s2k"), ("etabs", "ETABS", ".e2k")):
        _add_csi(targets, target, program, suffix)


def _add_csi(targets, target: str, program: str, suffix: str) -> None:
    """``export sap2000`` / ``export etabs``: the damper as a CSI damper link (``export.csi``)."""
    c = targets.add_parser(target, help=f"{program} damper link property ({suffix} text file to import)",
                           description=f"Write the damper as a {program} link property ({suffix}; default: print "
                                       "it): Damper - Exponential for laws 1, 2 (alone or with a series spring) and "
                                       "law 7 with beta 1, Damper - Bilinear for law 10; other models are refused "
                                       "(exit 2). The file carries the nonlinear properties and the linear "
                                       "effective stiffness and damping for linear load cases at a design motion "
                                       "(energy-equivalent, as FEMA 356 / ASCE 41), and says how each was made; "
                                       "the link's force is compared with the model's on the calibration record. "
                                       f"Not run in {program} here.")
    c.add_argument("params", metavar="PARAMS.yaml", help="calibration file")
    c.add_argument("-o", "--output", metavar="FILE", help=f"the file to write (damper{suffix}; default: print it)")
    c.add_argument("--units", dest="units_out", metavar="FORCE,LENGTH,TIME",
                   help=f"units of the {program} model, e.g. kN,m,s or N,mm,s or kip,in,s (default kN,mm,s; "
                        "seconds only): every value is converted, the dashpot's c with its exponent")
    c.add_argument("--amplitude", type=float, metavar="MM",
                   help="design amplitude [mm, whatever --units] of the linear effective properties "
                        "(default: the tested peak stroke)")
    c.add_argument("--frequency", type=float, metavar="HZ",
                   help="design frequency [Hz] of the linear effective properties (default: the sine that "
                        "reaches the tested peak velocity at that amplitude)")
    c.add_argument("--name", default="FVD1", help="the link property's name (default FVD1)")
    c.add_argument("--spring-deflection", type=float, metavar="SHARE",
                   help="a model without a series spring gets a stiff one that deflects this share of the tested "
                        "stroke under the force at the tested velocity (default 0.005, as the frames' solving "
                        "springs; smaller is stiffer and closer to the dashpot). Better: calibrate the spring "
                        "(--laws 2+series_stiffness)")
    add_test_option(c)
    add_plugin_option(c)
    add_record_options(c, units_flag="--record-units")
    c.set_defaults(func=run_csi)


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


def run_csi(args) -> int:
    """``export sap2000`` / ``export etabs``: the link file, checked before any
    work and written whole; the link's force against the model's on the
    calibration record, said on stderr."""
    from ..export.csi import csi_link
    from ..export.opensees import SOLVING_DEFLECTION
    from ..export.csi_files import SUFFIXES, sap2000_units, to_text

    suffixes = SUFFIXES[args.target]
    if args.output:
        if not args.output.lower().endswith(suffixes):
            raise InputError(f"-o {args.output}: the suffix must be {' or '.join(suffixes)}")
        check_output(args.output, "file", "-o")
    cal = Calibration.load(args.params, plugins=args.plugin).for_test(args.test)
    link = csi_link(cal.model, cal.named(), units=args.units_out, tested=cal.tested, amplitude=args.amplitude,
                    frequency=args.frequency, name=args.name,
                    deflection=SOLVING_DEFLECTION if args.spring_deflection is None else args.spring_deflection)
    u0, f = link.linear.u0, link.linear.frequency
    for line in cal.beyond_tested({"d": u0, "v": 2.0 * math.pi * f * u0, "f": f}, what_of="the design motion"):
        print(f"warning: {line}", file=sys.stderr)
    check = _csi_check(cal, link, args)
    said = ([] if check is None else
            [f"checked on {check['record']}: the link's force against the model's, OF {check['of']:.3g} (eq. 18)"])
    text = to_text(link, args.target, cal.provenance_lines() + said)
    if not args.output:
        sys.stdout.write(text)
        return 0
    with atomic_file(args.output, "wb") as fh:  # the CRLF lines as they are, on any platform
        fh.write(text.encode("utf-8"))
    print(f"wrote {args.output}: model {cal.spec} as the {link.kind} link {link.name} ({sap2000_units(link)}); "
          f"k: {link.spring}", file=sys.stderr)
    _note(cal, args, args.target, args.output, system_text(link.units), check)
    return 0


def _csi_check(cal, link, args) -> dict | None:
    """The link's force (``export.csi.link_force``) against the model's on the
    calibration record, as eq. 18's OF, said on stderr (None: no record)."""
    from ..export.csi import link_force

    try:
        record = read_as_calibrated(cal.record, args)
    except InputError as exc:
        record, why = None, str(exc)
    else:
        why = f"its file {cal.record.file} is not found"
    if record is None:
        print(f"not checked on the calibration record: {why}", file=sys.stderr)
        return None
    of = float(objective(cal.force(record), link_force(link, record), record.t))
    stiff = (f"; the stiff spring's, beside the calibration's own OF {cal.of:.3g}" if "stiff spring" in link.spring
             else "")
    print(f"check on {record.name}: OF(link vs model) = {of:.3g} (eq. 18, the model's force as reference{stiff})",
          file=sys.stderr)
    return {"record": record.name, "of": of, "bound": None, "ok": True}


def _check(cal, export, record, args):
    """OpenSees against the model on the record's motion
    (``opensees_check.check_on_record``): its CheckResult, said on stderr,
    with a figure when it misses its bound."""
    from ..export.opensees_check import check_on_record, quiet_opensees

    quiet_opensees()
    res = check_on_record(cal, record, export)
    verdict = "within" if res.ok else "OUTSIDE"
    how = ("; two materials in series: driven as two zeroLength elements through an internal node, TRBDF2"
           if export.connection else "")
    print(f"check on {record.name}: OF(OpenSees vs model) = {res.of:.3g}, {verdict} the bound {res.bound:.3g} "
          f"({'exact mapping' if res.exact else 'approximation'}{how})", file=sys.stderr)
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
