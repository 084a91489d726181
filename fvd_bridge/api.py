"""The Python entry points a notebook user needs, each one call.

    import fvd_bridge as fb
    rec = fb.Record.from_arrays(t, d, F, units=("N", "m", "s"))   # or fb.read_record("dev1.csv")
    cal = fb.calibrate(rec, "2", runs=3, bounds={"alpha": (0.1, 1.0)})
    cal.params["C"].ci95; print(cal.report()); cal.plot()
    cal.to_opensees(tag=1, units=("kN", "m", "s")).apply(ops); cal.to_fmu("damper.fmu")
    diag = fb.diagnose(rec, "2"); better = diag.accept()        # the best effect's refit
    cal = fb.calibrate([test1, test2], "9", device="sn101", per_test=["beta"])   # tests of one device

Units inside: kN, mm, s.  Messages and warnings (``FitWarning``,
``RecordWarning``) name these functions' arguments, never a command-line
option (``errors.option``: each message is written once, in the words of
whoever called).
"""

from __future__ import annotations

import warnings

from .calibration import Calibration
from .calibration.engine import calibrate as run_calibration
from .calibration.request import Extends, FitRequest
from .catalog import catalog
from .diagnose import diagnose as run_diagnosis
from .errors import FitWarning, InputError
from .fit import DEFAULT_OPTIMIZER
from .fit.intervals import REPLICATES, replicates
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


def calibrate(records, model, *, runs: int = 1, seed: int = 0, optimizer: str = DEFAULT_OPTIMIZER,
              bounds="auto", device: str | None = None, per_test=(), start: Calibration | dict | None = None,
              intervals: int = REPLICATES, plugins=(), pop: int | None = None,
              gens: int | None = None, fixed: dict | None = None, all_runs: bool = False,
              force_zero: str = "none") -> Calibration:
    """Calibrate a model on one record or on the tests of one device.

    Parameters
    ----------
    records : Record, Device or list of Record
        One test, or several tests of one device (fitted together).
    model : str or Model
        A spec: a law number and its effects, e.g. ``"2"`` or ``"9+asymmetry"``.
    runs : int
        Seeded optimizer runs; the best is kept, the others give the run
        statistics.  After the first 2, only when they did not end on one
        optimum (``fvd-bridge calibrate``'s rule; ``.settings['runs_made']``;
        ``all_runs=True`` makes them all).
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
    all_runs : bool
        Make every run, also when the first 2 ended on one optimum.
    force_zero : {"none", "per-test"}
        ``"per-test"``: fit each test's force zero (an offset F0 [kN] and a
        drift F1 [kN/s], ``fit.zero``) beside the model as a nuisance of the
        measurement: never part of the model, never exported
        (``.force_zero``, with intervals).

    Returns
    -------
    Calibration
        The best run, its intervals and its warnings (also issued as ``FitWarning``).
    """
    m = _model(model, plugins)
    mode, search_bounds = ("auto", dict(bounds)) if isinstance(bounds, dict) else (bounds, {})
    request = FitRequest(
        spec=m.spec, plugins=tuple(plugins), bounds=mode,
        search_bounds={name: (float(lo), float(hi)) for name, (lo, hi) in search_bounds.items()},
        fixed={name: float(v) for name, v in (fixed or {}).items()}, per_test=tuple(per_test),
        start_values={name: float(v) for name, v in start.items()} if isinstance(start, dict) else {},
        extends=Extends.of(start) if isinstance(start, Calibration) else None,
        optimizer=optimizer, pop=pop, gens=gens, seed=seed, runs=int(runs), all_runs=bool(all_runs),
        intervals=replicates(intervals), force_zero=force_zero)
    if request.model.names != m.names:
        raise InputError(f"model {m.spec}: give it as a spec (with plugins= for effects of your own)")
    cal = run_calibration(as_tests(records, device), request.check())
    for note in cal.warnings:
        warnings.warn(note, FitWarning, stacklevel=2)
    return cal


def diagnose(records, model, seed: int = 0, device: str | None = None, per_test=(), plugins=(), progress=None,
             target: str | None = None):
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
    target : str, optional
        Where the model must go: 'opensees', 'fmu', 'sap2000' or 'etabs';
        only what exports there is suggested (``.left_out``: the best
        candidate it leaves out).  None: anywhere.

    Returns
    -------
    Diagnosis
        ``.candidates`` ranked, ``.best``, ``.advice`` (the parameter the
        tests disagree on, or None), ``.verdict()``, ``.accept(effect=None)``
        (the refit as a Calibration) and ``.ladder()``.
    """
    return run_diagnosis(as_tests(records, device), _model(model, plugins), seed=seed, progress=progress,
                         catalog=catalog(plugins), per_test=tuple(per_test), target=target)
