"""The Python entry points a notebook user needs, each one call.

    rec = read_record("dev1.csv")                 # fvd_bridge.records
    m = parse_model("2+friction")                  # law + effects
    cal = calibrate(rec, m, runs=3, seed=0)        # best of 3 seeded fits -> Calibration
    cal.save("law2+friction.yaml"); Calibration.load("law2+friction.yaml")
    diag = diagnose_record(rec, "2")               # where it fails, what is missing

Units: kN, mm, s.
"""

from __future__ import annotations

import numpy as np

from .calibration import Calibration
from .campaign.checks import fit_warnings
from .catalog import catalog
from .diagnose import climb, diagnose
from .errors import InputError
from .fit import fit_model, settings_for


def calibrate(record, model_or_spec, runs: int = 1, seed: int = 0, optimizer: str = "de",
              bounds: str = "auto", plugins=(), pop: int | None = None, gens: int | None = None) -> Calibration:
    """Fit one model to one record ``runs`` times, with the seeds `fvd-bridge
    calibrate RECORD --laws SPEC --runs N --seed S` gives its runs (campaign.tasks:
    (seed, device 0, model 0, run)), so both reach the same calibration; the best
    run as a Calibration with the post-fit warnings and the run statistics.
    ``pop``, ``gens``: optimizer settings as `calibrate --pop --gens` (None: defaults)."""
    m = catalog(plugins).model(model_or_spec) if isinstance(model_or_spec, str) else model_or_spec
    if int(runs) < 1:
        raise InputError(f"runs {runs}: must be at least 1")
    settings = settings_for(optimizer, pop, gens)
    fits = [fit_model(m, record, bounds=bounds, optimizer=optimizer, seed=[seed, 0, 0, r], settings=settings)
            for r in range(int(runs))]
    best = min(fits, key=lambda f: f.of)
    P = np.array([f.params for f in fits])
    OF = np.array([f.of for f in fits])
    stats = {"of_mean": OF.mean(), "of_sigma": OF.std(), "p_mean": P.mean(axis=0), "p_sigma": P.std(axis=0)}
    settings_dict = {"runs": int(runs), "seed": seed, "optimizer": optimizer, "bounds": bounds,
                     "optimizer_settings": vars(settings), "plugins": list(plugins),
                     "best_run_seed": list(np.atleast_1d(best.seed).tolist())}
    warnings = [w["message"] for w in fit_warnings(m, fits)]
    return Calibration.from_fit(m, best, record, settings_dict, warnings, stats)


def diagnose_record(record, model_or_spec, seed: int = 0, ladder: bool = False, plugins=(), progress=None):
    """The ``diagnose`` verb: fit, where it fails, the ranked missing effects
    (a Diagnosis); with ``ladder=True`` the ladder (a Ladder)."""
    cat = catalog(plugins)
    if ladder:
        return climb(record, model_or_spec, seed, progress=progress, catalog=cat)
    return diagnose(record, model_or_spec, seed, progress=progress, catalog=cat)
