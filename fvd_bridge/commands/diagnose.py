"""``fvd-bridge diagnose``: where a model fails, which effect is missing, the ladder."""

from __future__ import annotations

import json
import os
import sys
from dataclasses import asdict

import shlex

from ..diagnose.core import recommended
from ..diagnose.ladder import recommended_fits
from ..campaign.outputs import spec_file
from ..catalog import catalog
from ..errors import InputError
from .. import timing
from ..fit import DEFAULT_OPTIMIZER
from ..fit.intervals import REPLICATES, replicates
from ..io.staging import check_output, safe_name, staged_dir
from ..model import export_step, export_target
from ..records.device import Device
from .calibrate import unique_names
from .common import READING, add_record_options, read_records


def add_parser(sub):
    p = sub.add_parser(
        "diagnose", help="explain the misfit: where a model fails and which physical effect is missing",
        description="Fit a model (LAW or LAW+EFFECT+...) to one record (or to the tests of one device "
                    "together: --device), show where it fails (figures and numbers), refit it with every "
                    "effect it lacks and rank them, and compare what is left with the noise floor of the "
                    "record itself. An effect that can act as a force offset (a preload, an asymmetry) counts "
                    "only beyond the tests' force zero: an offset and drift per test, fitted as a nuisance and "
                    "never exported. --ladder adds the best effect and repeats while it helps beyond noise.")
    p.add_argument("record", metavar="RECORD", nargs="+",
                   help="CSV or .mat test record (with --device: the tests of that device)")
    p.add_argument("--device", metavar="NAME",
                   help="the records are tests of one device NAME: fitted together, effects judged by "
                        "leaving one test out")
    p.add_argument("--law", required=True, metavar="SPEC",
                   help="model to diagnose: a law (see `fvd-bridge laws`), optionally with effects, e.g. 2 or 2+friction")
    p.add_argument("--per-test", action="append", default=[], metavar="NAME",
                   help="with --device: fit this parameter per test (the rest shared), the base and every "
                        "candidate, as calibrate --per-test does, e.g. --per-test beta (repeatable). Without it, "
                        "diagnose checks whether one parameter differs between the tests and says which")
    p.add_argument("--target", metavar="TARGET",
                   help="where the model must go: opensees, fmu, sap2000 or etabs (default: anywhere). Only "
                        "what exports there is suggested; the best model it leaves out is named with its gain; "
                        "the next step is that target's export")
    p.add_argument("--ladder", action="store_true",
                   help="add the best effect, refit, repeat while it helps beyond noise; print the ladder")
    p.add_argument("--max-rungs", type=int, metavar="N", help="with --ladder: add at most N effects")
    p.add_argument("--json", action="store_true",
                   help="print a JSON report on stdout: {model, of, noise_floor_of, candidates: "
                        "[{effect, of, improvement}] best first, ...}")
    p.add_argument("--out", default=os.path.join("results", "diagnose"), metavar="DIR",
                   help="directory for the figures and the JSON report (default results/diagnose)")
    p.add_argument("--no-figures", action="store_true", help="write no figures")
    p.add_argument("--intervals", type=int, default=REPLICATES, metavar="N",
                   help=f"bootstrap replicates of the intervals of each calibration it writes, as calibrate's "
                        f"(default {REPLICATES}; 0: none, the fastest: a gap model's take most of the time)")
    p.add_argument("--seed", type=int, default=0, help="seed of every fit (default 0)")
    p.add_argument("--pop", type=int, help="DE population per parameter, for a model whose law or effect "
                                           "needs a global search (law 7, the gap; diagnose default 8)")
    p.add_argument("--gens", type=int, help="maximum DE generations of such a model (diagnose default 120)")
    p.add_argument("--plugin", action="append", default=[], metavar="FILE.py",
                   help="Python file defining extra effects (ranked like the built-in ones)")
    p.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    add_record_options(p)
    p.add_argument("--profile", action="store_true", help="print where the time went (time per stage)")
    p.set_defaults(func=run)



def run(args) -> int:
    from ..diagnose import climb, diagnose, diagnose_settings
    from ..text.diagnosis import format_diagnosis, format_ladder

    check_output(args.out, "dir", "--out")  # before any work: a bad path is one line, exit 2
    export_target(args.target)  # before any work
    replicates(args.intervals)
    for name in ("pop", "gens", "max_rungs"):
        value = getattr(args, name)
        if value is not None and value < 1:
            raise InputError(f"--{name.replace('_', '-')} {value}: must be at least 1")
    cat = catalog(args.plugin)
    model = cat.model(args.law)  # refuse a bad spec before reading anything
    per_test = tuple(_per_test(text, model) for text in args.per_test)
    if per_test and not args.device:
        raise InputError("--per-test needs --device NAME (the records as tests of one device)")
    settings = diagnose_settings(args.pop, args.gens)
    records = read_records(args.record, args)
    if len(records) > 1 and not args.device:
        raise InputError(f"{len(records)} records: give --device NAME (they are the tests of one device), "
                         f"or diagnose one record at a time")
    record = Device(args.device, unique_names(records)) if args.device else records[0]
    label = " ".join(args.record)

    def progress(msg):
        if not args.quiet:
            print(msg, file=sys.stderr, flush=True)

    lad = None
    with timing.stage("ladder" if args.ladder else "diagnose"):
        if args.ladder:
            lad = climb(record, model, seed=args.seed, settings=settings, max_rungs=args.max_rungs, progress=progress,
                        catalog=cat, per_test=per_test,
                        target=args.target)
            diag = lad.final
        else:
            diag = diagnose(record, model, seed=args.seed, settings=settings, progress=progress, catalog=cat, per_test=per_test,
                            target=args.target)
    report = diag.as_dict()
    report["settings"] = {"seed": args.seed, "optimizer": DEFAULT_OPTIMIZER, **asdict(settings),
                          **({"per_test": list(per_test)} if per_test else {})}
    if lad is not None:
        report["ladder"] = lad.as_dict()
    fits = _refits(diag, lad)
    names = {spec: os.path.join("params", safe_name(record.name), spec_file(spec)) for spec in fits}
    paths = {spec: os.path.join(args.out, name) for spec, name in names.items()}
    _hand_over(report, paths)
    with timing.stage("outputs, figures"):
        files, saved = _write(args, record, diag, lad, report, {names[spec]: fit for spec, fit in fits.items()})
    if args.json:
        print(json.dumps(report, indent=1))
    else:
        if lad is not None:
            print(format_diagnosis(lad.diagnoses[0], label))
            print()
            print(format_ladder(lad))
        else:
            print(format_diagnosis(diag, label, _next_lines(args, diag, paths)))
        if saved:
            print("\ncalibration files (each refitted as calibrate fits, with its intervals):")
            for path, (of, zero) in saved.items():
                beside = ", beside the tests' force zero, which no export carries" if zero else ""
                print(f"  {path}: OF {of:.4g}{beside}")
        if files:
            print(f"\nwrote {', '.join(files)}")
    return 0


def _per_test(text: str, model) -> str:
    """'[SPEC:]NAME' (calibrate's form; SPEC must be --law's) -> NAME, a parameter of ``model``."""
    spec, _, name = str(text).rpartition(":")
    if spec and spec != model.spec:
        raise InputError(f"--per-test {text}: law {spec} is not the model diagnosed ({model.spec})")
    return model.known_parameter(name, f"--per-test {text}")


def _refits(diag, lad) -> dict:
    """{spec: (model, fit, zero)} of what diagnose found worth keeping: every
    candidate that passed its checks, and with the ladder every rung
    (``zero``: refitted beside the tests' force zero; ``recommended_fits``)."""
    return recommended_fits(diag, lad)


def _hand_over(report: dict, paths: dict) -> None:
    """Each candidate and rung of the report names its calibration file
    (``calibration``: the path calibrate would write, in OUT/params/)."""
    rows = report["candidates"] + report["all_candidates"] + (report.get("ladder") or {}).get("rungs", [])
    for row in rows:
        spec = row.get("spec") or row.get("model") or f"{report['model']}+{row['effect']}"
        if spec in paths:
            row["calibration"] = paths[spec]
    report["calibrations"] = paths


def _next_lines(args, diag, paths: dict) -> list:
    """Commands that run as printed: where the tests disagree on a parameter
    (``Diagnosis.advice``), calibrate and diagnose again with it per test;
    else export the best candidate's calibration file (to --target, else
    to OpenSees where it exports there, else to an FMU), and diagnose it
    further on the same record read the same way (with the same --per-test
    and --target)."""
    best = diag.best
    advice = diag.advice
    if advice is None and (best is None or best.spec not in paths):
        return []
    reading = [f"--{name.replace('_', '-')} {shlex.quote(str(getattr(args, name)))}"
               for name in READING if getattr(args, name, None) is not None]
    plugins = [f"--plugin {shlex.quote(p)}" for p in args.plugin]
    device = [f"--device {shlex.quote(args.device)}"] if args.device else []
    records = [*map(shlex.quote, args.record), *device, *reading, *plugins]
    flags = [f"--per-test {shlex.quote(n)}" for n in (*diag.per_test, *([advice.name] if advice else []))]
    beside = os.path.dirname(os.path.normpath(args.out)) or "."  # each next command writes beside this one's
    if advice is not None:
        out = shlex.quote(os.path.join(beside, "calibrate"))
        again_out = shlex.quote(os.path.join(beside, f"diagnose_per_test_{safe_name(advice.name)}"))
        zero = ["--force-zero per-test"] if diag.zero is not None else []  # the nuisance its checks were made beside
        return [" ".join(["fvd-bridge calibrate", *records, f"--laws {diag.spec}", *flags, *zero, f"--out {out}"]),
                " ".join(["fvd-bridge diagnose", *records, f"--law {diag.spec}", *flags, f"--out {again_out}"])]
    again_out = shlex.quote(os.path.join(beside, f"diagnose_{safe_name(best.spec)}"))
    target = [f"--target {args.target}"] if args.target else []
    again = ["fvd-bridge diagnose", *records, f"--law {best.spec}", *flags, *target, f"--out {again_out}"]
    return [export_step(best.exports, shlex.quote(paths[best.spec]), args.target), " ".join(again)]


def _write(args, record, diag, lad, report, fits: dict) -> tuple[list[str], dict]:
    """The calibration files of what diagnose found ({file name in OUT:
    (model, fit, zero)}, ``_refits``), figures and the JSON report, all or nothing
    (a staging directory): (the paths written, {calibration file: (its OF, fitted
    beside the tests' force zero)})."""
    base = safe_name(record.name)
    written, saved = [], {}
    settings = {"source": "diagnose", **report["settings"]}
    with staged_dir(args.out) as stage:
        for name, (model, fit, zero) in fits.items():  # with intervals; beside the force zero where it was fitted
            cal = recommended(model, fit, record, settings, zero=zero, per_test=diag.per_test,
                              seed=args.seed, replicates=args.intervals)
            cal.save(os.path.join(stage, name))
            written.append(name)
            saved[os.path.join(args.out, name)] = (cal.of, zero)
        with open(os.path.join(stage, f"{base}_diagnose.json"), "w") as fh:
            json.dump(report, fh, indent=1)
        written.append(f"{base}_diagnose.json")
        if not args.no_figures:
            from ..plots import diagnose as figs

            first = lad.diagnoses[0] if lad is not None else diag
            figs.where(first.focus, first, os.path.join(stage, f"{base}_where.png"))
            written.append(f"{base}_where.png")
            if lad is not None:
                figs.where(diag.focus, diag, os.path.join(stage, f"{base}_where_final.png"))
                figs.ladder(lad, os.path.join(stage, f"{base}_ladder.png"))
                written += [f"{base}_where_final.png", f"{base}_ladder.png"]
        from ..report.page import build_report

        build_report(stage, shown_as=args.out, plugins=args.plugin)
        written.append("report.html")
    return [os.path.join(args.out, f) for f in written], saved
