"""The Python entry points a notebook user needs, each one call.

    import fvd_bridge as fb
    rec = fb.Record.from_arrays(t, d, F, units=("N", "m", "s"))   # or fb.read_record("dev1.csv")
    cal = fb.calibrate(rec, "2", runs=3, bounds={"alpha": (0.1, 1.0)})
    cal.params["C"].ci95; print(cal.report()); cal.plot()
    cal.to_opensees(tag=1, units=("kN", "m", "s")).apply(ops); cal.to_fmu("damper.fmu")
    diag = fb.diagnose(rec, "2"); better = diag.accept()        # the best effect's refit
    cal = fb.calibrate([test1, test2], "9", device="sn101", per_test=["beta"])   # tests of one device

Units inside: kN, mm, s.  Messages and warnings (``FitWarning``,
``RecordWarning``) name these functions' arguments.
"""

from __future__ import annotations

import warnings
from dataclasses import asdict

import numpy as np

from .api_words import api_errors, in_api_words
from .calibration import Calibration
from .campaign.checks import fit_warnings
from .catalog import catalog
from .diagnose import diagnose as run_diagnosis
from .errors import FitWarning, InputError
from .fit import DEFAULT_OPTIMIZER, fit_model, settings_for
from .fit.intervals import REPLICATES
from .fit.intervals import intervals as fit_intervals
from .fit.nested import nested_start
from .records.device import Device
from .records.record import Record


def as_tests(records, device: str | None = None):
    """One Record as it is; several (a list, tuple or Device) as the tests of
    one device named ``device`` (default: the first test's name)."""
    if isinstance(records, (Record, Device)):
        return records if device is None or isinstance(records, Device) else Device(device, [records])
    tests = list(records)
    if not tests or not all(isinstance(r, Record) for r in tests):
        raise InputError("records: give a Record, a Device or a list of Records")
    return tests[0] if len(tests) == 1 and device is None else Device(device or tests[0].name, tests)


def _model(model_or_spec, plugins=()):
    return catalog(plugins).model(model_or_spec) if isinstance(model_or_spec, str) else model_or_spec


def calibrate(records, model, runs: int = 1, seed: int = 0, optimizer: str = DEFAULT_OPTIMIZER,
              bounds="auto", device: str | None = None, per_test=(), start: Calibration | dict | None = None,
              intervals: int = REPLICATES, plugins=(), pop: int | None = None,
              gens: int | None = None, fixed: dict | None = None) -> Calibration:
    """Calibrate a model on one record or on the tests of one device.

    Parameters
    ----------
    records : Record, Device or list of Record
        One test, or several tests of one device (fitted together).
    model : str or Model
        A spec: a law number and its effects, e.g. ``"2"`` or ``"9+asymmetry"``.
    runs : int
        Seeded optimizer runs; the best is kept, the others give the run statistics.
    seed : int
        The first run's seed (the same seeds as ``fvd-bridge calibrate --seed``).
    optimizer : str
        ``"local"`` (default), ``"local+de"``, ``"de"``, ``"ga"`` (the paper's GA) or ``"ga+polish"``.
    bounds : str or dict
        ``"auto"`` (from the record's peaks), ``"paper"`` (Table 4), or
        ``{name: (lower, upper)}`` replacing the automatic bounds of those parameters.
    device : str, optional
        The device's name when ``records`` holds several tests.
    per_test : list of str
        Parameters fitted per test (e.g. ``["beta"]``); the others are shared.
    start : Calibration or dict, optional
        A calibration that ``model`` extends, to start from; or
        ``{name: value}``: start values of some parameters (lmfit's
        ``value=``), the data's start for the others.
    fixed : dict, optional
        ``{name: value}``: parameters held at a value, not fitted (lmfit's
        ``vary=False``); their interval is the value.
    intervals : int
        Bootstrap replicates of the 95% intervals (0: none).
    plugins : list of str
        Plugin files with effects of your own.
    pop, gens : int, optional
        Optimizer settings (None: the defaults).

    Returns
    -------
    Calibration
        The best run, its intervals and its warnings (also issued as ``FitWarning``).
    """
    with api_errors():
        m = _model(model, plugins)
        if int(runs) < 1:
            raise InputError(f"runs={runs}: must be at least 1")
        record = as_tests(records, device)
        mode, overrides = ("auto", dict(bounds)) if isinstance(bounds, dict) else (bounds, {})
        for name, value in (fixed or {}).items():
            if name not in m.names:
                raise InputError(f"fixed={{{name!r}: {value}}}: model {m.spec} has no parameter '{name}' "
                                 f"(has: {', '.join(m.names)})")
            overrides[name] = (float(value), float(value))
        settings = settings_for(optimizer, pop, gens)
        first = (start if start is None or isinstance(start, dict)
                 else nested_start(m, record, start.model.names, start.values, per_test))
        fits = [fit_model(m, record, bounds=mode, optimizer=optimizer, seed=[seed, 0, 0, r], settings=settings,
                          per_test=per_test, start=first, overrides=overrides) for r in range(int(runs))]
        best = min(fits, key=lambda f: f.of)
        P = np.array([f.params for f in fits])
        OF = np.array([f.of for f in fits])
        stats = {"of_mean": OF.mean(), "of_sigma": OF.std(), "p_mean": P.mean(axis=0), "p_sigma": P.std(axis=0)}
        settings_dict = {"runs": int(runs), "seed": seed, "optimizer": optimizer, "bounds": mode,
                         **({"bound": {k: list(v) for k, v in overrides.items()}} if overrides else {}),
                         "optimizer_settings": asdict(settings), "plugins": list(plugins),
                         "best_run_seed": list(np.atleast_1d(best.seed).tolist())}
        notes = [in_api_words(w["message"]) for w in fit_warnings(m, fits)]
        for note in notes:
            warnings.warn(note, FitWarning, stacklevel=3)
        ivals = None
        if intervals:
            ivals = fit_intervals(m, record, best.params, per_test, best.bounds, intervals, seed=[seed, 7],
                                  of=best.of)
        return Calibration.from_fit(m, best, record, settings_dict, notes, stats, ivals)


def diagnose(records, model, seed: int = 0, device: str | None = None, per_test=(), plugins=(), progress=None):
    """Fit ``model`` to ``records`` (one Record, or the tests of one device),
    find where it fails and refit it with each physical effect it lacks.

    Parameters
    ----------
    records : Record, Device or list of Record
        The test(s).
    model : str or Model
        The base model, e.g. ``"2"``.
    seed : int
        The fits' seed.
    device : str, optional
        The device's name when ``records`` holds several tests.
    per_test : list of str
        Parameters fitted per test (e.g. ``["beta"]``), the base and every
        candidate, as ``calibrate`` fits them; the others are shared.
        Without it, several tests are checked for one parameter that
        differs between them (``.advice``, and the verdict says so first).
    plugins : list of str
        Plugin files with effects of your own (candidates too).
    progress : callable, optional
        ``progress(message)`` receives one line per fit.

    Returns
    -------
    Diagnosis
        ``.candidates`` ranked, ``.best``, ``.advice`` (the parameter the
        tests disagree on, or None), ``.verdict()``, ``.accept(effect=None)``
        (the refit as a Calibration) and ``.ladder()``.
    """
    with api_errors():
        return run_diagnosis(as_tests(records, device), _model(model, plugins), seed, progress=progress,
                             catalog=catalog(plugins), per_test=tuple(per_test))
