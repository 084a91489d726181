"""``fvd-bridge compare``: calibrated models on a record they were not fitted to."""

from __future__ import annotations

import json
import os
import sys

import numpy as np

from ..calibration import Calibration
from ..errors import InputError
from ..fit import objective
from ..io.staging import check_output, safe_name, staged_dir, write_json
from ..records import Record
from ..records.cycles import force_measures
from ..records.validate import scale_mismatch
from ..report.numbers import rounded
from ..rig.protocols import read_history
from .common import add_plugin_option, add_record_options, add_test_option, read_records, window


def add_parser(sub):
    p = sub.add_parser(
        "compare", help="check calibrated models on another test record (or predict on a displacement history)",
        description="Evaluate calibrated models (PARAMS.yaml: any law + effects) on a record they were not fitted "
                    "to (another amplitude or frequency, or a damper's displacement history from `frame`): each "
                    "model's OF (eq. 18), its peak force and energy per cycle beside the measured ones, where "
                    "it fails (as diagnose), overlaid loops and time histories; the table is best first. A t,d file without force predicts: each model's force on that motion.")
    p.add_argument("files", nargs="+", metavar="PARAMS.yaml... RECORD",
                   help="calibration files, then the record (CSV/.mat t,d,F; or a t,d history)")
    p.add_argument("--out", default=os.path.join("results", "compare"), metavar="DIR",
                   help="folder for the figure and the JSON report (default results/compare)")
    p.add_argument("--json", action="store_true",
                   help='print {"record": PATH, "models": [{"file", "model", "of", "peak_force_kN", '
                        '"energy_per_cycle_kNmm", ...}, ...] best first, "measured": {the same of the record}, '
                        '"cycles"}')
    p.add_argument("--no-figures", action="store_true", help="write no figure")
    add_test_option(p)
    add_plugin_option(p)
    add_record_options(p)
    p.set_defaults(func=run)


def _read(path: str, args):
    """The record, or a t,d history (force 0, prediction only): (record, has_force)."""
    try:
        return read_records([path], args)[0], True
    except InputError as exc:  # only a file without a force column is a history
        if "(for F) not found" not in str(exc) and "expected a header such as t,d,F, found numbers" not in str(exc):
            raise
    hist = read_history(path)
    t = hist.t0 + np.arange(hist.n) * hist.dt
    d, v, a = hist.motion(t)
    return Record(t, d, np.zeros_like(t), v, a, name=os.path.splitext(os.path.basename(path))[0],
                  provenance={"file": os.path.abspath(path), "kind": "displacement history"}), False


def _check_units(cal, record, path: str) -> None:
    """Refuse a record whose peak force or stroke is far off the calibration
    record's (other units: records.validate.scale_mismatch)."""
    peaks = cal.record.peaks
    reference = {key: (peak, peak) for key, peak in (("F", peaks.F), ("d", peaks.d)) if peak}
    message = scale_mismatch(path, record.scales(), reference, f"{cal.path}'s calibration record")
    if message:
        raise InputError(message)


def run(args) -> int:
    from ..diagnose.where import analyse, summary_lines

    if len(args.files) < 2:
        raise InputError("compare needs at least one PARAMS.yaml and a RECORD")
    check_output(args.out, "dir", "--out")  # before any work: a bad path is one line, exit 2
    *param_files, record_path = args.files
    cals = [Calibration.load(f, plugins=args.plugin) for f in param_files]
    cals = [cal.for_test(args.test if cal.per_test else None) for cal in cals]  # per test: --test's
    record, has_force = _read(record_path, args)
    for cal in cals:
        _check_units(cal, record, record_path)
    if args.window and not has_force:  # a t,d history (a record is cut on reading)
        record = window(record, args.window)
    for line in dict.fromkeys(msg for cal in cals for msg in cal.beyond_tested(record)):
        print(f"warning: {line}", file=sys.stderr)
    rows = []
    for cal, path in zip(cals, param_files):
        F = cal.force(record)
        of = float(objective(record.F, F, record.t)) if has_force else float("nan")
        measures = force_measures(record.d, F)
        rows.append({"file": path, "model": cal.spec, "device": cal.record.name, "of": of,
                     "of_calibration": cal.of, "F": F, "measures": measures, "peak_force_kN": measures.peak,
                     "where": analyse(record, F) if has_force else None})
    rows.sort(key=lambda r: (r["of"] if has_force else 0.0, r["file"]))
    measured = force_measures(record.d, record.F) if has_force else None
    report = {"record": record_path,
              "models": [{"file": r["file"], "model": r["model"], "of": r["of"] if has_force else None,
                          "of_calibration": r["of_calibration"], "device": r["device"],
                          **r["measures"].as_dict()} for r in rows],
              "measured": measured.as_dict() if measured else None,
              "cycles": rows[0]["measures"].cycles if rows[0]["measures"].energy_per_cycle is not None else None,
              "prediction_only": not has_force}
    files = _write(args, record, rows, report, measured)
    if args.json:
        print(json.dumps({k: report[k] for k in ("record", "models", "measured", "cycles")}, indent=1))
        return 0
    w = max(len(r["file"]) for r in rows) + 2
    if has_force:
        print(f"models on {record.name} ({record.n} samples; OF eq. 18; best first):")
        print(f"  {'file':<{w}}{'model':<28}{'OF here':>10}{'OF calib.':>11}{'ratio':>8}")
        for r in rows:
            print(f"  {r['file']:<{w}}{r['model']:<28}{r['of']:>10.4g}{r['of_calibration']:>11.4g}"
                  f"{r['of'] / r['of_calibration'] if r['of_calibration'] else float('nan'):>8.2f}")
        print("\n" + "\n".join(measure_lines(rows, measured, w)))
        best = rows[0]
        print(f"\ngeneralises best: {best['model']} ({best['file']}), OF {best['of']:.4g}")
        for r in rows:
            print(f"\nwhere {r['model']} fails ({r['file']}):")
            print("\n".join(f"  {line}" for line in summary_lines(r["where"])))
    else:
        print(f"prediction on the displacement history {record.name} ({record.n} samples, no measured force):")
        ref = np.mean([r["peak_force_kN"] for r in rows])
        for r in rows:
            m = r["measures"]
            energy = (f"energy per cycle {rounded(m.energy_per_cycle)} kN mm" if m.energy_per_cycle is not None
                      else f"energy {rounded(m.energy)} kN mm (total: fewer than two reversals)")
            print(f"  {r['file']:<{w}}{r['model']:<28} peak force {r['peak_force_kN']:9.4g} kN "
                  f"({100 * (r['peak_force_kN'] / ref - 1):+.1f}% from the mean), {energy}")
    if files:
        print(f"\nwrote {', '.join(files)}")
    return 0


def measure_lines(rows, measured, w: int) -> list[str]:
    """The peak force max |F| [kN] and the energy per cycle [kN mm = J]
    (``records.cycles.force_measures``) of each model beside the measured
    ones, with model / measured; the total energy where the motion has no
    cycles to count."""
    per_cycle = measured.energy_per_cycle is not None
    what = (f"energy per cycle: integral F dd over the record / its {measured.cycles:.3g} "
            f"displacement cycles" if per_cycle else "energy: integral F dd over the record (d reverses fewer "
                                                         "than twice: no cycles to count)")
    head = "energy/cycle" if per_cycle else "energy"

    def energy(m):
        return m.energy_per_cycle if per_cycle else m.energy

    lines = [f"peak force and {'energy per cycle' if per_cycle else 'energy'}, model against measured "
             f"(kN; kN mm = J; {what}):",
             f"  {'':<{w}}{'model':<28}{'peak |F|':>10}{'ratio':>8}{head:>14}{'ratio':>8}",
             f"  {'(measured)':<{w}}{'':<28}{rounded(measured.peak):>10}{'':>8}{rounded(energy(measured)):>14}"]
    for r in rows:
        m = r["measures"]
        lines.append(f"  {r['file']:<{w}}{r['model']:<28}{rounded(m.peak):>10}"
                     f"{_ratio(m.peak, measured.peak):>8}{rounded(energy(m)):>14}"
                     f"{_ratio(energy(m), energy(measured)):>8}")
    return lines


def _in_short(m) -> str:
    """'peak 19.7 kN, 1230 kN mm/cycle': a legend's words for ``ForceMeasures`` m."""
    energy = (f"{rounded(m.energy_per_cycle, digits=3)} kN mm/cycle" if m.energy_per_cycle is not None
              else f"{rounded(m.energy, digits=3)} kN mm in all")
    return f"peak {rounded(m.peak, digits=3)} kN, {energy}"


def _ratio(x: float, ref: float) -> str:
    """x / ref to 3 significant digits; '-' when ref is 0."""
    return rounded(x / ref, digits=3) if ref else "-"


def _write(args, record, rows, report, measured) -> list:
    has_force = measured is not None
    base = safe_name(record.name)
    written = [f"{base}_compare.json"]
    with staged_dir(args.out) as stage:
        full = dict(report, where={r["file"]: r["where"].as_dict() for r in rows} if has_force else None)
        write_json(os.path.join(stage, written[0]), full)
        if not args.no_figures:
            from ..plots.compare import compare_figure

            compare_figure(record, [(f"{r['model']} ({os.path.basename(r['file'])}): {_in_short(r['measures'])}",
                                     r["F"]) for r in rows],
                           has_force, os.path.join(stage, f"{base}_compare.png"),
                           measured_label=f"measured: {_in_short(measured)}" if measured else "measured")
            written.append(f"{base}_compare.png")
        from ..report.page import build_report

        build_report(stage, shown_as=args.out, plugins=args.plugin)
        written.append("report.html")
    return [os.path.join(args.out, f) for f in written]
