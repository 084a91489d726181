"""Campaign outputs (schema_version 1): calibrated parameter files, tables, figures.

DIR/params/<device>/law<SPEC>.yaml  one calibrated parameter set per (device, model):
                                    what the exporters read (best run's parameters;
                                    fvd_bridge.calibration owns its schema)
DIR/table_A7.csv    mean and sigma over runs of OF and every parameter (Table A.7)
DIR/robustness.csv  Delta_mn, Delta_n per parameter and beta per model (eqs. 19-23);
                    a parameter whose mean over devices is near zero (stats.near_zero)
                    has empty deltas and the note "near-zero mean: not in beta"
DIR/pareto.csv      mean OF vs beta per model, non-dominated flag (Fig. 14)
DIR/summary.json    settings, devices, per-model summary (with the runs made:
                    calibration.runs.fit_runs), every run, warnings
DIR/figures/*.png   loops, OF bars, parameter dispersion, Pareto front
"""

from __future__ import annotations

import os

import numpy as np

from .. import timing
from .._version import __version__
from ..calibration import Calibration
from ..io.staging import num, staged_dir, write_csv_rows, write_json
from ..records.device import as_device
from . import stats
from ..calibration.checks import fit_warnings
from ..calibration.runs import FittedRuns
from ..report.page import build_report
from .executors import Processes, Serial

#: schema of table_A7.csv, robustness.csv, pareto.csv and summary.json
SCHEMA_VERSION = 1
#: from this many figures on, they are drawn in the campaign's processes
PARALLEL_FIGURES = 8


def spec_file(spec: str) -> str:
    """'2+friction' -> 'law2+friction.yaml'."""
    return f"law{spec}.yaml"


def summarize(records, results: dict, cs) -> dict:
    """Everything the outputs hold, computed once from the runs."""
    devices = [r.name for r in records]
    law1 = {dev: np.mean([x.of for x in results[(dev, "1")]]) for dev in devices if (dev, "1") in results}
    models = {}
    for spec in cs.specs:
        every = [FittedRuns(results[(dev, spec)]) for dev in devices]
        per_dev = [runs.asked for runs in every]  # the runs asked: their statistics
        names, units = per_dev[0][0].names, per_dev[0][0].units
        P = np.array([[r.values for r in runs] for runs in per_dev])      # (dev, run, par)
        OF = np.array([[r.of for r in runs] for runs in per_dev])          # (dev, run)
        p_mean, p_sigma = P.mean(axis=1), P.std(axis=1)
        # derived quantities (law 8's mu*N) per run, then over runs: not of the mean parameters
        model = cs.model(spec)
        derived = [[model.derived(p) for p in runs] for runs in P]          # (dev, run) of {name: (value, unit)}
        d_stats = [{name: (float(np.mean([r[name][0] for r in runs])), float(np.std([r[name][0] for r in runs])),
                           unit) for name, (_, unit) in runs[0].items()} for runs in derived]
        ranges = np.mean([runs[0].bounds for runs in per_dev], axis=0)      # (par, 2), over devices
        near_zero = stats.near_zero(p_mean, ranges, per_dev[0][0].log)
        delta = stats.deltas(p_mean, near_zero)
        delta_n, beta = stats.robustness(p_mean, near_zero)
        tests = [[r.test_of or [r.of] for r in runs] for runs in per_dev]  # (dev, run, test)
        models[spec] = {
            "test_names": [runs[0].tests or [dev] for dev, runs in zip(devices, per_dev)],
            "test_of": [(np.mean(t, axis=0), np.std(t, axis=0)) for t in tests],
            "names": names, "units": units, "near_zero": near_zero,
            "notes": [_near_zero_note(n, u, p_mean[:, j].mean(), ranges[j])
                      for j, (n, u) in enumerate(zip(names, units)) if near_zero[j]],
            "of_mean": OF.mean(axis=1), "of_sigma": OF.std(axis=1),
            "p_mean": p_mean, "p_sigma": p_sigma, "derived": d_stats, "delta": delta, "delta_n": delta_n, "beta": beta,
            "of_overall": float(OF.mean()), "runs_made": OF.shape[1], "wider_runs": every[0].wider_runs,
            "warnings": {dev: fit_warnings(cs.model(spec), runs, law1.get(dev)) for dev, runs in zip(devices, every)},
            "best": {dev: runs.best for dev, runs in zip(devices, every)},
            "floor": {dev: runs.floor for dev, runs in zip(devices, every)},
        }
    specs = list(cs.specs)
    front = stats.non_dominated(np.array([[models[s]["of_overall"], models[s]["beta"]] for s in specs]))
    for s, nd in zip(specs, front):
        models[s]["non_dominated"] = bool(nd)
    return {"devices": devices, "models": models, "runs": cs.runs}


def _near_zero_note(name, unit, mean, rng) -> str:
    """The one-line report of a parameter kept out of beta (stats.near_zero)."""
    unit = "" if unit == "-" else f" {unit}"
    return (f"{name}: mean over devices {mean:.4g}{unit} is near zero (|mean| < {stats.NEAR_ZERO:.0%} of its "
            f"search range [{rng[0]:.4g}, {rng[1]:.4g}]): no relative scatter, kept out of beta")


def calibration(rec, spec, results: dict, summary_model, cs, intervals=None) -> Calibration:
    """The calibrated parameter set of one (device, model): its best run
    (with its intervals), built as one calibration builds it
    (``Calibration.from_runs``), with the campaign's settings."""
    return Calibration.from_runs(cs.model(spec), results[(rec.name, spec)], rec, settings=cs.as_dict(),
                                 warnings=[w["message"] for w in summary_model["warnings"][rec.name]],
                                 intervals=intervals)


def write_outputs(out: str, records, results: dict, cs, figures: bool = True, extra=None, intervals=None,
                  executor=None) -> dict:
    """Write every output into ``out`` (all or nothing); returns the summary.
    ``intervals``: {(device, spec): Intervals} (calibration.runs.fit_intervals);
    ``executor``: the one that draws the figures (default: a process pool of
    ``cs.jobs``; the campaign's own, when its pool is still open).

    ``extra(stage, summary)``, when given, writes further files into the same
    staging directory (e.g. the production statistics of ``fvd-bridge campaign``).
    """
    summary = summarize(records, results, cs)
    summary["intervals"] = {}
    intervals = intervals or {}
    with staged_dir(out) as stage:
        for rec in records:
            for spec in cs.specs:
                cal = calibration(rec, spec, results, summary["models"][spec], cs, intervals.get((rec.name, spec)))
                cal.save(os.path.join(stage, "params", rec.name, spec_file(spec)))
                if cal.intervals:
                    summary["intervals"][(rec.name, spec)] = cal.interval_lines()
        _tables(stage, summary, cs)
        write_json(os.path.join(stage, "summary.json"), _summary_json(records, results, summary, cs))
        if figures:
            with timing.stage("  figures"):
                _figures(stage, records, summary, cs, executor)
        if extra is not None:
            extra(stage, summary)
        with timing.stage("  report.html"):
            build_report(stage, shown_as=out, plugins=cs.plugins)
    return summary


def _tables(stage, summary, cs):
    rows, rob, par = [], [], []
    devices = summary["devices"]
    for spec, m in summary["models"].items():
        for k, dev in enumerate(devices):
            rows.append([spec, dev, "OF", "-", m["of_mean"][k], m["of_sigma"][k]])
            for j, (n, u) in enumerate(zip(m["names"], m["units"])):
                rows.append([spec, dev, n, u, m["p_mean"][k][j], m["p_sigma"][k][j]])
            for name, (mean, sigma, unit) in m["derived"][k].items():
                rows.append([spec, dev, name, unit, mean, sigma])
        for j, n in enumerate(m["names"]):
            note = "near-zero mean: not in beta" if m["near_zero"][j] else ""
            for k, dev in enumerate(devices):
                rob.append([spec, n, dev, num(m["delta"][k][j]), num(m["delta_n"][j]), num(m["beta"]), note])
        par.append([spec, m["of_overall"], num(m["beta"]), int(m["non_dominated"])])
    write_csv_rows(os.path.join(stage, "table_A7.csv"), ["model", "device", "quantity", "unit", "mean", "sigma"], rows)
    write_csv_rows(os.path.join(stage, "robustness.csv"),
                   ["model", "parameter", "device", "delta_mn", "Delta_n", "beta", "note"], rob)
    write_csv_rows(os.path.join(stage, "pareto.csv"), ["model", "of_mean", "beta", "non_dominated"], par)


def _summary_json(records, results, summary, cs) -> dict:
    return {
        "schema_version": SCHEMA_VERSION,
        "fvd_bridge_version": __version__,
        "settings": cs.as_dict(),
        "devices": [{"name": dev.name, "tests": [{"name": r.name, "file": r.provenance.get("file"), "samples": r.n,
                                                  "dt": r.dt, "peak_force_kN": float(np.max(np.abs(r.F)))}
                                                 for r in as_device(dev).tests]} for dev in records],
        "models": {spec: {"of_mean": m["of_overall"], "beta": num(m["beta"]), "runs_made": m["runs_made"],
                          "non_dominated": m["non_dominated"], "notes": m["notes"],
                          "warnings": {d: m["warnings"][d] for d in summary["devices"]}}
                   for spec, m in summary["models"].items()},
        "runs": [{"device": dev, "model": spec, "run": i, "of": r.of,
                  "params": r.named(), "evaluations": r.evaluations,
                  "wall_s": round(r.wall_s, 3), "seed": list(np.atleast_1d(r.seed).tolist()), "stop": r.stop}
                 for (dev, spec), runs in results.items() for i, r in enumerate(runs)],
    }


def _figures(stage, records, summary, cs, executor=None):
    from ..plots import campaign as plots  # lazily: matplotlib (about 1 s), not needed with --no-figures

    fig_dir = os.path.join(stage, "figures")
    os.makedirs(fig_dir, exist_ok=True)
    specs, devices = list(cs.specs), summary["devices"]
    figures = []  # (plotting function, its arguments)
    for dev in records:
        tests = as_device(dev).tests
        for spec in specs:
            best = summary["models"][spec]["best"][dev.name]
            cal = Calibration.from_fit(cs.model(spec), best, dev)
            for k, rec in enumerate(tests):
                name = rec.name if len(tests) == 1 else f"{dev.name}_{rec.name}"
                figures.append((plots.loops, rec, cal.force(rec, test=rec.name),
                                f"{name}, law {spec}: OF {cal.tests[k].of:.4f}",
                                os.path.join(fig_dir, f"loops_{name}_law{spec}.png")))
    M = summary["models"]
    figures.append((plots.of_bars, specs, devices, np.array([M[s]["of_mean"] for s in specs]),
                    np.array([M[s]["of_sigma"] for s in specs]), os.path.join(fig_dir, "of_bars.png")))
    figures += [(plots.dispersion, spec, M[spec]["names"], devices, M[spec]["p_mean"], M[spec]["p_sigma"],
                 os.path.join(fig_dir, f"dispersion_law{spec}.png")) for spec in specs]
    figures.append((plots.pareto, specs, [M[s]["of_overall"] for s in specs], [M[s]["beta"] for s in specs],
                    [M[s]["non_dominated"] for s in specs], os.path.join(fig_dir, "pareto.png")))
    # a figure takes 0.1-0.3 s: dozens of them go to the campaign's processes
    for _ in ((executor or Processes(cs.jobs)) if len(figures) >= PARALLEL_FIGURES else Serial()).run(_draw, figures):
        pass


def _draw(plot, *args):
    """One figure: ``plot(*args)`` (a task of the campaign's processes)."""
    return plot(*args)
