"""``fvd-bridge campaign CAMPAIGN.yaml``: a production-scale calibration campaign,
parallel (local processes or a Dask cluster) and resumable after a kill.

The campaign file (YAML; relative paths are relative to the file):

    records: [lab/dev*.csv, extra/dev9.csv]     # paths or globs, one record per device; or:
    devices: {SN101: [lab/SN101_*.csv], SN102: [lab/SN102_*.csv]}  # several tests per device; or:
    rig: {devices: 200, nominal: {C: 45.4, alpha: 0.3}, scatter: {C: 0.05},
          protocol: paper, noise: {force: 1.0, displacement: 0.005}, seed: 0}   # -> OUT/records
    models: 2,6,9                              # laws and LAW+EFFECT specs (a list works too)
    runs: 5
    seed: 0
    out: series_out
    acceptance: {velocity: 500, nominal_force: 300, tolerance: 0.15}   # all optional
    outliers: {k: 3.5}
    bounds: {spec: 0.15, statistic: extremes}  # upper/lower-bound factors (campaign.property_bounds)
    executor: local                            # or dask; --executor wins
    scheduler: tcp://host:8786                 # dask only; --scheduler wins

plus every option of ``calibrate`` under its own name (optimizer, bounds,
bound, pop, gens, stall, jobs, plugin, no_figures, columns, units, mat_var,
dt, sg_window, sg_order), read by calibrate's own parser.  An unknown key is
refused with one line naming the file and the key.
"""

from __future__ import annotations

import argparse
import contextlib
import glob
import os
import shutil
import sys

import yaml

from ..campaign import acceptance, production, property_bounds as bounds
from ..campaign.acceptance import Acceptance
from ..campaign.executors import Dask, Processes
from ..campaign.outputs import write_outputs
from ..campaign.resume import Resumable
from ..campaign.engine import run_calibrations
from ..campaign.sources import expand_records, rig_rating, rig_records, rig_spec
from ..campaign.stats import OUTLIER_K
from ..campaign.store import UnitStore
from ..effects.plugins import file_sha256
from ..errors import InputError
from ..io.staging import check_output
from ..records.device import Device
from ..text.campaign import format_report, format_series
from ..text.production import format_production
from ..text.property_bounds import format_bounds
from .calibrate import campaign_settings, option_parser, parse_option, unique_names
from .common import read_records

#: keys only a campaign file has (calibrate's options are the rest)
CAMPAIGN_KEYS = ("records", "devices", "rig", "models", "acceptance", "outliers", "bounds", "executor", "scheduler")
#: calibrate options a campaign file does not take: (key, why)
NOT_IN_FILE = {"laws": "use 'models'", "config": "the campaign file is the config", "quiet": "a command-line flag",
               "design_velocity": "use 'acceptance: {velocity: V}'"}
EXECUTORS = ("local", "dask")


def add_parser(sub):
    p = sub.add_parser(
        "campaign", help="a production-scale calibration campaign from a YAML file (parallel, resumable)",
        description="Calibrate models on every device of a series (record files or a virtual rig series) over "
                    "several runs, in parallel on local cores or a Dask cluster; every finished unit (device, "
                    "model, run) is stored at once in OUT/.units, so a killed campaign started again resumes "
                    "where it stopped. Writes calibrate's outputs plus production statistics (distributions, "
                    "outliers, acceptance at the design velocity).")
    p.add_argument("campaign", metavar="CAMPAIGN.yaml",
                   help="the campaign file: records or rig, models, runs, seed, out, acceptance, outliers and "
                        "any calibrate option (see the README, section Campaigns)")
    p.add_argument("--executor", choices=EXECUTORS, help="local processes (default) or dask")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="Dask scheduler address, e.g. tcp://10.0.0.5:8786 (default: a LocalCluster on this machine)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=run)


# ------------------------------------------------------------------ the campaign file
def read_campaign_file(path: str) -> tuple[dict, argparse.Namespace]:
    """(campaign-only keys, calibrate's options as a Namespace) of a campaign file."""
    try:
        with open(path) as fh:
            data = yaml.safe_load(fh) or {}
    except OSError as exc:
        raise InputError(f"{path}: cannot read ({exc.strerror or exc})") from None
    except yaml.YAMLError as exc:
        raise InputError(f"{path}: not valid YAML ({' '.join(str(exc).split())})") from None
    if not isinstance(data, dict):
        raise InputError(f"{path}: expected a mapping of keys to values")
    parser = option_parser()
    actions = {a.dest: a for a in parser._actions if a.option_strings}
    args = parser.parse_args([])
    own = {}
    for key, value in data.items():
        key = str(key)
        dest = "laws" if key == "models" else key.replace("-", "_")
        if key in NOT_IN_FILE:
            raise InputError(f"{path}: unknown key '{key}' ({NOT_IN_FILE[key]})")
        if key in CAMPAIGN_KEYS and key != "models":
            own[key] = value
            continue
        if dest not in actions:
            raise InputError(f"{path}: unknown key '{key}' (campaign keys: {', '.join(CAMPAIGN_KEYS)}, "
                             f"or a calibrate option: {', '.join(sorted(k for k in actions if k not in NOT_IN_FILE))})")
        if value is None:
            continue
        parse_option(parser, actions[dest], value, args, f"{path}: key '{key}'")
    return own, args


def plan(path: str) -> dict:
    """Everything a campaign file says, checked before any work: settings, sources,
    out, executor, acceptance, outlier k, the effective settings of the fingerprint."""
    own, args = read_campaign_file(path)
    base = os.path.dirname(os.path.abspath(path))
    if not args.out:
        raise InputError(f"{path}: key 'out' is required (the output directory)")
    if sum(key in own for key in ("records", "devices", "rig")) != 1:
        raise InputError(f"{path}: give exactly one of 'records' (paths or globs), 'devices' (name: the tests' "
                         f"paths or globs) and 'rig' (a virtual series)")
    if "devices" in own and (not isinstance(own["devices"], dict) or not own["devices"]):
        raise InputError(f"{path}: key 'devices': expected a mapping of device names to paths or globs")
    args.out = os.path.join(base, os.path.expanduser(str(args.out)))
    try:
        check_output(args.out, "dir")  # before any work: a bad path is one line, exit 2
    except InputError as exc:
        raise InputError(f"{path}: key 'out': {exc}") from None
    args.plugin = [os.path.join(base, os.path.expanduser(p)) for p in args.plugin]
    if args.jobs is not None and args.jobs < 0:
        raise InputError(f"{path}: key 'jobs': {args.jobs} must be >= 0 (0: one per core)")
    try:
        cs = campaign_settings(args)
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from None
    rig = rig_spec(own["rig"], path) if "rig" in own else None
    outliers = own.get("outliers") or {}
    if not isinstance(outliers, dict) or any(k != "k" for k in outliers):
        raise InputError(f"{path}: key 'outliers': expected {{k: NUMBER}} (robust standard deviations)")
    try:
        k = float(outliers.get("k", OUTLIER_K))
    except (TypeError, ValueError):
        raise InputError(f"{path}: key 'outliers.k': '{outliers.get('k')}' is not a number") from None
    if not k > 0:
        raise InputError(f"{path}: key 'outliers.k': {k:g} must be > 0")
    executor = own.get("executor", "local")
    if executor not in EXECUTORS:
        raise InputError(f"{path}: key 'executor': '{executor}' (expected {' or '.join(EXECUTORS)})")
    settings = {**cs.as_dict(),
                "plugins": [{"file": os.path.basename(p), "sha256": file_sha256(p)} for p in cs.plugins],
                "source": {"rig": rig} if rig else "records"}
    return {"cs": cs, "args": args, "base": base, "out": args.out, "rig": rig, "records": own.get("records"),
            "devices": own.get("devices"),
            "acceptance": Acceptance.from_dict(own.get("acceptance"), path), "k": k, "executor": executor,
            "bounds": bounds.BoundSettings.from_dict(own.get("bounds"), path),
            "scheduler": own.get("scheduler"), "settings": settings}


def load_records(p: dict, path: str):
    """The campaign's devices, in order, with unique names: records (one per
    device), Devices (several tests each), or a rig series (simulated once
    into OUT/records)."""
    if p["devices"] is not None:
        return [Device(str(name), unique_names(read_records(expand_records(tests, p["base"], path, f"devices.{name}"),
                                                            p["args"])))
                for name, tests in p["devices"].items()]
    if p["rig"] is not None:
        paths = rig_records(p["rig"], p["out"], path)
    else:
        paths = expand_records(p["records"], p["base"], path)
    return unique_names(read_records(paths, p["args"]))


def make_executor(p: dict, args):
    """The executor the campaign file and the command line ask for."""
    scheduler = args.scheduler or p["scheduler"]
    kind = args.executor or ("dask" if args.scheduler else p["executor"])
    if scheduler and kind != "dask":
        raise InputError(f"--scheduler {scheduler}: needs --executor dask (or executor: dask in the campaign file)")
    if kind == "dask":
        try:
            import distributed  # noqa: F401
        except ImportError:
            raise InputError("--executor dask needs the 'distributed' package (pip install distributed)") from None
        return Dask(scheduler, workers=p["cs"].jobs), kind
    return Processes(p["cs"].jobs), kind


def _remove_stale_staging(out: str) -> None:
    """Staging directories of OUT's outputs that a killed run left (the store's lock is held)."""
    out = os.path.abspath(out)
    for stage in glob.glob(os.path.join(os.path.dirname(out), f".{glob.escape(os.path.basename(out))}.partial-*")):
        shutil.rmtree(stage, ignore_errors=True)


# ------------------------------------------------------------------------- the verb
def run(args) -> int:
    p = plan(args.campaign)
    cs = p["cs"]
    store = UnitStore(p["out"], source=args.campaign)
    store.check(p["settings"])  # a changed campaign is refused before anything is written
    records = load_records(p, args.campaign)
    executor, kind = make_executor(p, args)
    store.open(p["settings"], records)
    _remove_stale_staging(p["out"])
    own_pool = executor if kind == "local" else None  # one local pool for the fits, intervals and figures
    try:
        with own_pool or contextlib.nullcontext():
            where = (f"dask scheduler {executor.scheduler}" if kind == "dask" and executor.scheduler else
                     f"dask LocalCluster, {executor.workers} workers" if kind == "dask" else
                     f"local, {executor.jobs} process(es)")
            print(f"campaign: {len(records)} device(s) x {len(cs.specs)} model(s) x {cs.runs} run(s), optimizer "
                  f"{cs.optimizer}, bounds {cs.bounds}; executor {where}", file=sys.stderr)
            resumable = Resumable(executor, store, progress=not args.quiet)
            results, intervals = run_calibrations(records, cs, executor, progress=not args.quiet,
                                                  fits_executor=resumable)
            figures = not p["args"].no_figures
            made = {}

            def extra(stage, summary):
                made["prod"] = production.analyse(summary, cs, p["k"])
                rating = rig_rating(p["rig"]) if p["rig"] is not None else None  # a virtual series: its nominal's
                made["accept"] = acceptance.evaluate(summary, records, cs, p["acceptance"], rating=rating)
                production.write(stage, made["prod"], made["accept"], figures)
                made["bounds"] = bounds.compute(summary, records, cs, p["acceptance"], p["bounds"])
                bounds.write(stage, made["bounds"])

            summary = write_outputs(p["out"], records, results, cs, figures=figures, extra=extra, intervals=intervals,
                                    executor=own_pool)
    finally:
        store.close()
    print(format_report(summary) if len(records) <= 6 else format_series(summary))
    print(format_production(made["prod"], made["accept"]))
    print(format_bounds(made["bounds"]))
    print(f"\nunits: {resumable.total} ({resumable.resumed} resumed from {store.root}, {store.computed} computed "
          f"now{f', {len(store.corrupt)} corrupt redone' if store.corrupt else ''})")
    print(f"wrote {p['out']}/ (params/, table_A7.csv, robustness.csv, pareto.csv, summary.json, production.csv, "
          f"outliers.csv{', acceptance.csv' if made['accept']['models'] else ''}, production.json, bounds.csv, bounds.json"
          f"{', figures/' if figures else ''})")
    return 0
