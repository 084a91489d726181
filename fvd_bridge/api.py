"""The Python entry points a notebook user needs, each one call.

    rec = read_record("dev1.csv")                 # fvd_bridge.records
    m = parse_model("2+friction")                  # law + effects
    cal = calibrate(rec, m, runs=3, seed=0)        # best of 3 seeded fits -> Calibration, with 95% intervals
    dev = Device("sn101", [read_record(p) for p in ("a.csv", "b.csv")])
    cal = calibrate(dev, "9", per_test=["beta"])   # tests of one device fitted together
    cal.save("law2+friction.yaml"); Calibration.load("law2+friction.yaml")
    diag = diagnose_record(rec, "2")               # where it fails, what is missing

Units: kN, mm, s.
"""

from __future__ import annotations

from dataclasses import asdict

import numpy as np

from .calibration import Calibration
from .campaign.checks import fit_warnings
from .catalog import catalog
from .diagnose import climb, diagnose
from .errors import InputError
from .fit import DEFAULT_OPTIMIZER, fit_model, settings_for
from .fit.intervals import REPLICATES
from .fit.intervals import intervals as fit_intervals
from .fit.nested import nested_start


def calibrate(record, model_or_spec, runs: int = 1, seed: int = 0, optimizer: str = DEFAULT_OPTIMIZER,
              bounds: str = "auto", plugins=(), pop: int | None = None, gens: int | None = None,
              per_test=(), start=None, intervals: int = REPLICATES) -> Calibration:
    """Fit one model to one record (or a Device: its tests together) ``runs``
    times, with the seeds `fvd-bridge calibrate RECORD --laws SPEC --runs N
    --seed S` gives its runs (campaign.tasks: (seed, device 0, model 0, run)),
    so both reach the same calibration; the best run as a Calibration with
    the post-fit warnings, the run statistics and ``intervals`` bootstrap
    replicates' 95% intervals (0: none; fit.intervals).  ``pop``, ``gens``:
    optimizer settings as `calibrate --pop --gens` (None: defaults);
    ``per_test``: parameters fitted per test; ``start``: a Calibration the
    model extends, to start from (`calibrate --start`)."""
    m = catalog(plugins).model(model_or_spec) if isinstance(model_or_spec, str) else model_or_spec
    if int(runs) < 1:
        raise InputError(f"runs {runs}: must be at least 1")
    settings = settings_for(optimizer, pop, gens)
    first = None if start is None else nested_start(m, record, start.model.names, start.params, per_test)
    fits = [fit_model(m, record, bounds=bounds, optimizer=optimizer, seed=[seed, 0, 0, r], settings=settings,
                      per_test=per_test, start=first) for r in range(int(runs))]
    best = min(fits, key=lambda f: f.of)
    P = np.array([f.params for f in fits])
    OF = np.array([f.of for f in fits])
    stats = {"of_mean": OF.mean(), "of_sigma": OF.std(), "p_mean": P.mean(axis=0), "p_sigma": P.std(axis=0)}
    settings_dict = {"runs": int(runs), "seed": seed, "optimizer": optimizer, "bounds": bounds,
                     "optimizer_settings": asdict(settings), "plugins": list(plugins),
                     "best_run_seed": list(np.atleast_1d(best.seed).tolist())}
    warnings = [w["message"] for w in fit_warnings(m, fits)]
    ivals = None
    if intervals:
        ivals = fit_intervals(m, record, best.params, per_test, best.bounds, intervals, seed=[seed, 7], of=best.of)
    return Calibration.from_fit(m, best, record, settings_dict, warnings, stats, ivals)


def diagnose_record(record, model_or_spec, seed: int = 0, ladder: bool = False, plugins=(), progress=None):
    """The ``diagnose`` verb: fit, where it fails, the ranked missing effects
    (a Diagnosis); with ``ladder=True`` the ladder (a Ladder)."""
    cat = catalog(plugins)
    if ladder:
        return climb(record, model_or_spec, seed, progress=progress, catalog=cat)
    return diagnose(record, model_or_spec, seed, progress=progress, catalog=cat)
