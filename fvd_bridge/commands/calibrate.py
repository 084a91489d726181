"""``fvd-bridge calibrate``: fit laws to every record (device) over several runs."""

from __future__ import annotations

import argparse
import sys

import numpy as np
import yaml

from ..campaign import property_bounds as series_bounds
from ..campaign.acceptance import Acceptance, series_motion
from ..campaign.outputs import write_outputs
from ..calibration import Calibration
from ..campaign.engine import run_calibrations
from ..campaign.executors import Processes
from ..calibration.request import Extends
from ..campaign.runner import BoundOption, CampaignSettings, PerTestOption, ValueOption
from ..catalog import catalog as load_catalog
from ..errors import InputError
from .. import timing
from ..fit import DEFAULT_OPTIMIZER, OPTIMIZERS
from ..fit.intervals import REPLICATES
from ..fit.zero import FORCE_ZERO
from ..io.staging import check_output
from ..laws import BOUND_MODES, LAWS, PAPER_SPEC, parse_law_list
from ..records.device import Device
from ..text.campaign import format_report
from ..text.property_bounds import format_bounds
from .common import add_record_options, read_records


def add_parser(sub):
    p = sub.add_parser("calibrate", help="fit laws to test records (one record per device, or tests of one device)",
                       description="Fit laws or models (LAW+EFFECT...) to every record, one record per device "
                                   "(or every record a test of one device: --device), over several seeded runs; "
                                   "write the calibrated parameter files (the exporters' input), Table A.7, the "
                                   "robustness index, the Pareto front, figures and the series' upper and lower "
                                   "bounds (bounds.json, as campaign writes it: what frame --bounds reads) into "
                                   "--out.")
    p.add_argument("records", nargs="+", metavar="RECORD",
                   help="CSV or .mat test records, one per device (with --device: the tests of that device)")
    p.add_argument("--device", metavar="NAME",
                   help="the records are tests of one device NAME: one parameter set fitted to all of them, "
                        "the objective the mean of the tests' OFs")
    p.add_argument("--test-weights", metavar="W1,W2,..",
                   help="with --device: the tests' weights in the objective (default equal)")
    add_campaign_options(p)
    add_series_options(p)
    add_record_options(p)
    p.set_defaults(func=run, _defaults={a.dest: a.default for a in p._actions})


def add_series_options(p):
    """calibrate's options of the series' bounds (a campaign file says them in its acceptance block)."""
    p.add_argument("--design-velocity", type=float, default=Acceptance.velocity, metavar="V",
                   help=f"design velocity [mm/s] of the series' upper and lower bounds (bounds.json, as a "
                        f"campaign's acceptance.velocity; default {Acceptance.velocity:g})")


def add_campaign_options(p):
    p.add_argument("--laws", default=PAPER_SPEC,
                   help=f"laws or model specs: '1-{max(LAWS)}', '2,6,9' or '2+friction,9' (default: the "
                        f"paper's nine, {PAPER_SPEC})")
    p.add_argument("--runs", type=int, default=20,
                   help="independent runs per device and law (default 20); after the first 2, only for the "
                        "models whose first runs did not end on one optimum (see --all-runs)")
    p.add_argument("--all-runs", action="store_true",
                   help="make every run, also where the first 2 ended on one optimum (e.g. to time them all)")
    p.add_argument("--out", help="output directory (required, here or in --config)")
    p.add_argument("--config", help="YAML file with any of these options as keys (laws, runs, out, bounds, "
                                    "bound: [..], seed, optimizer, pop, gens, stall, jobs, plugin: [..]); "
                                    "options given on the command line win")
    p.add_argument("--bounds", default="auto", choices=BOUND_MODES,
                   help="'auto' (from the record's scales, default) or 'paper' (Table 4)")
    p.add_argument("--bound", action="append", default=[], metavar="[LAW:]NAME=LO,HI",
                   help="override one parameter's bounds, for every law that has it or for one "
                        "law/spec, e.g. --bound 9:alpha=0,50 (repeatable)")
    p.add_argument("--fix", action="append", default=[], metavar="[LAW:]NAME=VALUE",
                   help="hold one parameter at a value (not fitted; its interval is the value), for every law "
                        "that has it or for one law/spec, e.g. --fix 9:beta=1.6 (repeatable)")
    p.add_argument("--seed", type=int, default=0, help="base seed; the same seed gives the same results")
    p.add_argument("--optimizer", default=DEFAULT_OPTIMIZER, choices=OPTIMIZERS,
                   help="'local' (default: least squares on eq. 18 from the data's start and a sample's; "
                        "law 7 and the gap: DE), 'local+de' (then a DE check), 'de' (differential evolution "
                        "+ polish), 'ga' (the paper's GA, Table 3), 'ga+polish'")
    p.add_argument("--pop", type=int, help="population (GA: individuals, default 200; DE: per parameter, 15; "
                                           "the DE of local and local+de: 8)")
    p.add_argument("--gens", type=int, help="maximum generations (default GA 200, DE 300)")
    p.add_argument("--stall", type=int, help="GA: stop after this many generations without improvement (20)")
    p.add_argument("--jobs", type=int, default=0, help="processes (default: one per core)")
    p.add_argument("--plugin", action="append", default=[], help="Python file defining extra effects")
    p.add_argument("--per-test", action="append", default=[], metavar="[LAW:]NAME",
                   help="with several tests of a device: fit this parameter per test (the rest shared), "
                        "e.g. --per-test 9:beta or --per-test friction.Ff (repeatable)")
    p.add_argument("--intervals", type=int, default=REPLICATES, metavar="N",
                   help=f"bootstrap replicates of each calibration's parameter intervals (default {REPLICATES}; "
                        f"0: none)")
    p.add_argument("--force-zero", default="none", choices=FORCE_ZERO,
                   help="'per-test': fit each test's force zero (offset F0 and drift F1, pinned by its rests "
                        "where it has them) beside the model as a nuisance of the measurement; kept in the "
                        "calibration file's force_zero block, never exported (default: none)")
    p.add_argument("--start", metavar="CALIBRATION.yaml",
                   help="start every model that extends this calibration's model (same law, its effects "
                        "among the model's) from its parameters; the fit ends no worse than them")
    p.add_argument("--start-value", action="append", default=[], metavar="[LAW:]NAME=VALUE",
                   help="start one parameter at a value (still fitted; the data's start for the others), for "
                        "every law that has it or for one law/spec, e.g. --start-value C=40 (repeatable)")
    p.add_argument("--no-figures", action="store_true", help="skip the PNG figures")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--profile", action="store_true", help="print where the time went (time per stage)")


def parse_specs(text: str, catalog) -> tuple:
    """'1-9' / '2,6,9' / '2+friction,9' -> model specs (validated)."""
    specs = []
    for part in text.split(","):
        part = part.strip()
        if "+" in part:
            specs.append(catalog.model(part).spec)
        else:
            specs.extend(law.key for law in parse_law_list(part))
    return tuple(dict.fromkeys(specs))


def parse_bound(text: str) -> tuple:
    """'[SPEC:]NAME=LO,HI' -> (spec or None, name, lo, hi), checked before any work."""
    head, sep, rng = str(text).partition("=")
    spec, _, name = head.rpartition(":")
    try:
        lo, hi = (float(x) for x in rng.split(","))
    except ValueError:
        raise InputError(f"--bound '{text}': expected [LAW:]NAME=LO,HI, e.g. 9:alpha=0,50") from None
    if not sep or not name:
        raise InputError(f"--bound '{text}': expected [LAW:]NAME=LO,HI, e.g. 9:alpha=0,50")
    if not lo < hi:
        raise InputError(f"--bound '{text}': the lower bound must be below the upper")
    return BoundOption(spec or None, name, lo, hi)


def parse_value(text: str, flag: str = "--fix") -> tuple:
    """'[SPEC:]NAME=VALUE' -> (spec or None, name, value)."""
    head, sep, value = str(text).partition("=")
    spec, _, name = head.rpartition(":")
    try:
        x = float(value)
    except ValueError:
        raise InputError(f"{flag} '{text}': expected [LAW:]NAME=VALUE, e.g. 9:beta=1.6") from None
    if not sep or not name or not np.isfinite(x):
        raise InputError(f"{flag} '{text}': expected [LAW:]NAME=VALUE with a finite value, e.g. 9:beta=1.6")
    return ValueOption(spec or None, name, x)


def parse_fix(text: str) -> tuple:
    """'[SPEC:]NAME=VALUE' -> (spec or None, name, value, value): a bound of one value."""
    spec, name, x = parse_value(text, "--fix")
    return BoundOption(spec, name, x, x)


def option_parser() -> argparse.ArgumentParser:
    """calibrate's options (for --config and campaign files), without exiting on a bad value."""
    p = argparse.ArgumentParser(prog="calibrate", add_help=False, exit_on_error=False)
    add_campaign_options(p)
    add_series_options(p)
    add_record_options(p)
    return p


def option_tokens(action, value) -> list[str]:
    """A YAML value of an option as the command-line tokens argparse checks."""
    flag = action.option_strings[-1]
    if isinstance(action, argparse._StoreTrueAction):
        return [flag] if value else []
    values = value if isinstance(value, list) and isinstance(action, argparse._AppendAction) else [value]
    if isinstance(value, list) and not isinstance(action, argparse._AppendAction):
        values = [",".join(str(v) for v in value)]
    return [f"{flag}={v}" for v in values]


def parse_option(parser, action, value, namespace, where: str) -> None:
    """Parse one YAML option value into ``namespace`` as its command-line form
    would be (same types and choices); a bad value: one line naming ``where``."""
    try:
        parser.parse_args(option_tokens(action, value), namespace=namespace)
    except argparse.ArgumentError as exc:
        raise InputError(f"{where}: {exc.message}") from None


def apply_config(args) -> None:
    """Fill options left at their defaults from the --config YAML file, each
    value checked as the command line checks it."""
    if args.config:
        try:
            with open(args.config) as fh:
                cfg = yaml.safe_load(fh) or {}
        except (OSError, yaml.YAMLError) as exc:
            raise InputError(f"{args.config}: cannot read ({str(exc).splitlines()[0]})") from None
        if not isinstance(cfg, dict):
            raise InputError(f"{args.config}: expected a mapping of option names to values")
        parser = option_parser()
        actions = {a.dest: a for a in parser._actions if a.option_strings}
        for key, value in cfg.items():
            dest = str(key).replace("-", "_")
            if dest not in actions or dest == "config":
                raise InputError(f"{args.config}: unknown option '{key}'")
            if value is None or getattr(args, dest) != args._defaults[dest]:
                continue  # the command line wins
            parsed = parser.parse_args([])
            parse_option(parser, actions[dest], value, parsed, f"{args.config}: option '{key}'")
            setattr(args, dest, getattr(parsed, dest))
    if not args.out:
        raise InputError("--out DIR is required (on the command line or in --config)")


def campaign_settings(args) -> CampaignSettings:
    cat = load_catalog(args.plugin)
    specs = parse_specs(str(args.laws), cat)
    overrides = tuple(parse_bound(b) for b in args.bound) + tuple(parse_fix(f) for f in args.fix)
    start_values = tuple(parse_value(text, "--start-value") for text in args.start_value)
    for flag, spec, name in ([("--fix" if lo == hi else "--bound", spec, name) for spec, name, lo, hi in overrides]
                             + [("--start-value", spec, name) for spec, name, _ in start_values]):
        targets = [spec] if spec else list(specs)
        given = f"{flag} '{spec + ':' if spec else ''}{name}=...'"
        if spec and spec not in specs:
            raise InputError(f"{given}: law {spec} is not among --laws {args.laws}")
        if not any(name in cat.model(t).names for t in targets):
            raise InputError(f"{given}: {_none_has(name, targets, cat)}")
    per_test = tuple(parse_per_test(text, specs, cat) for text in args.per_test)
    start = None
    if args.start:
        given = Calibration.load(args.start, cat)
        start = Extends.of(given)
        if not any(cat.model(s).law is given.model.law and set(given.model.effect_names) <= set(cat.model(s).effect_names)
                   for s in specs):
            raise InputError(f"--start {args.start}: no model of --laws {args.laws} extends its model {given.spec} "
                             f"(same law, its effects among the model's)")
    cs = CampaignSettings(specs=specs, runs=args.runs, bounds=args.bounds,
                          optimizer=args.optimizer, seed=args.seed, pop=args.pop, gens=args.gens,
                          stall=args.stall, jobs=args.jobs, plugins=tuple(args.plugin),
                          bound_overrides=overrides, per_test=per_test, start=start, intervals=args.intervals,
                          start_values=start_values, all_runs=args.all_runs, force_zero=args.force_zero)
    for request in cs.requests():  # each model's request, checked as fb.calibrate checks its one
        request.check()
    return cs


def parse_per_test(text: str, specs, catalog) -> tuple:
    """'[SPEC:]NAME' -> (spec or None, name), checked against the models."""
    spec, _, name = str(text).rpartition(":")
    spec = spec or None
    if spec and spec not in specs:
        raise InputError(f"--per-test {text}: law {spec} is not among the models ({', '.join(specs)})")
    targets = [spec] if spec else list(specs)
    if not name or not any(name in catalog.model(t).names for t in targets):
        raise InputError(f"--per-test {text}: {_none_has(name, targets, catalog)}")
    return PerTestOption(spec, name)


def _none_has(name: str, specs: list, catalog) -> str:
    """'model 9 has no parameter ...' (one model) or 'none of the models 2, 9
    has a parameter ...', with the parameters they have."""
    if len(specs) == 1:
        return f"model {specs[0]} has no parameter '{name}' (has: {', '.join(catalog.model(specs[0]).names)})"
    have = "; ".join(f"{s}: {', '.join(catalog.model(s).names)}" for s in specs)
    return f"none of the models {', '.join(specs)} has a parameter '{name}' ({have})"


def group_device(records, args):
    """--device NAME: the records as the tests of one device (weights from
    --test-weights); without it, each record its own device."""
    if not args.device:
        if args.test_weights or args.per_test:
            raise InputError(f"{'--test-weights' if args.test_weights else '--per-test'} needs --device NAME "
                             f"(the records as tests of one device)")
        return records
    weights = None
    if args.test_weights:
        try:
            weights = [float(w) for w in str(args.test_weights).split(",")]
        except ValueError:
            raise InputError(f"--test-weights {args.test_weights}: expected numbers separated by commas") from None
        if len(weights) != len(records):
            raise InputError(f"--test-weights {args.test_weights}: {len(weights)} weights for {len(records)} tests")
    return [Device(args.device, list(records), weights)]


def unique_names(records):
    seen = {}
    for r in records:
        if r.name in seen:
            seen[r.name] += 1
            r.name = f"{r.name}_{seen[r.name]}"
        else:
            seen[r.name] = 1
    return records


def design_acceptance(args) -> Acceptance:
    """The design motion of the series' bounds: --design-velocity, the rest a campaign's defaults."""
    v = args.design_velocity
    if not (np.isfinite(v) and v > 0):
        raise InputError(f"--design-velocity {v:g}: must be > 0 (mm/s)")
    return Acceptance(velocity=float(v))


def bounds_text(bounds: dict, devices: int) -> str:
    """The series' bounds as campaign prints them (text.property_bounds.format_bounds);
    with one device, one line saying what bounds.json holds (and one per model without bounds)."""
    if devices >= 2:
        return format_bounds(bounds)
    spec = bounds["settings"]["spec"]
    lines = [f"bounds.json: one device, so no scatter measured (lambda_test = 1): the factors on the force at "
             f"{bounds['velocity']:g} mm/s are the specification's {1 - spec:g} and {1 + spec:g} alone "
             f"(ASCE 7-16 18.2.4.5); calibrate the series' devices together for their scatter"]
    lines = lines if bounds["models"] else []
    return "\n" + "\n".join(lines + [f"bounds.json: {why}" for why in bounds.get("skipped", {}).values()])


def run(args) -> int:
    apply_config(args)
    check_output(args.out, "dir", "--out")  # before any work: a bad path is one line, exit 2
    cs = campaign_settings(args)
    acc = design_acceptance(args)
    records = unique_names(read_records(args.records, args))
    records = group_device(records, args)
    series_motion(acc, records)  # the bounds' design motion, refused before the fits rather than after
    tests = f" ({len(records[0].tests)} tests)" if args.device else ""
    print(f"calibrating {len(cs.specs)} model(s) x {len(records)} device(s){tests} x {cs.runs} run(s), "
          f"optimizer {cs.optimizer}, bounds {cs.bounds}", file=sys.stderr)
    made = {}

    def bounds(stage, summary):  # the series' upper and lower bounds, as a campaign writes them
        made["bounds"] = series_bounds.compute(summary, records, cs, acc, series_bounds.BoundSettings())
        series_bounds.write(stage, made["bounds"])

    with Processes(cs.jobs) as executor:  # one pool for the fits, the intervals and the figures
        results, intervals = run_calibrations(records, cs, executor, progress=not args.quiet)
        with timing.stage("outputs, figures"):
            summary = write_outputs(args.out, records, results, cs, figures=not args.no_figures,
                                    intervals=intervals, executor=executor, extra=bounds)
    print(format_report(summary))
    print(bounds_text(made["bounds"], len(records)))
    print(f"\nwrote {args.out}/ (params/, table_A7.csv, robustness.csv, pareto.csv, summary.json, bounds.csv, "
          f"bounds.json{', figures/' if not args.no_figures else ''})")
    return 0
