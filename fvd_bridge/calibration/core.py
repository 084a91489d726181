"""A calibrated model: ``Calibration`` (its parameters, each a
``fit.parameter.FittedParameter``, where it holds, its force on a record,
its exports).  The file it is saved as is ``schema``'s; its text report
``text.calibration``'s; what reaches the exporters and plots ``reach``'s; its tested range ``tested``'s."""

from __future__ import annotations

import os
from dataclasses import dataclass, field, replace

import numpy as np
import yaml

from ..errors import InputError, option
from ..fit.layout import SEP, Layout
from ..fit.objective import objective
from ..fit.parameter import FittedParameter
from ..io.staging import atomic_file, num
from ..records.device import as_device, tested_range
from . import per_test as per_test_mod, schema, tested as tested_mod
from ..text import calibration as text
from .parts import BootstrapIntervals, RecordSource, RunStats, SolverStatus, TestFit
from .schema import record_provenance
from .tested import TESTED_MARGIN, data_key
from .zero import ForceZero
from ..text.calibration import REPORTED_CORRELATION
from .reach import Reach


@dataclass(frozen=True)
class Calibration(Reach):
    """A calibrated model: the Model, its parameter vector (model order) with
    bounds, the OF, where the record came from (its RecordSource), the
    settings and the fit warnings; ``tests``: a TestFit per test fitted,
    ``runs``: the RunStats over the seeded runs (None: not recorded).
    Frozen: a changed calibration is ``dataclasses.replace(cal, ...)``."""

    model: object  # fvd_bridge.model.Model
    values: np.ndarray  # the parameters in model order [the model's units]
    of: float
    bounds: np.ndarray | None = None
    record: RecordSource = RecordSource()  # the (first) test's record: file, samples, dt [s], peaks, ...
    settings: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)
    runs: RunStats | None = None  # of_mean, of_sigma, p_mean, p_sigma over runs (None: no runs recorded)
    path: str | None = None  # the file it was read from
    tests: tuple = ()  # TestFit per test: name, weight, of, range, record, parameters
    device: str = ""
    intervals: BootstrapIntervals | None = None  # the parameters' intervals (fit.intervals; None: none)
    solver: SolverStatus | None = None  # how the best run's search ended (None: not recorded)
    force_zero: ForceZero | None = None  # the tests' force zero fitted beside the model (never exported; None: not)
    records: list = field(default_factory=list, repr=False, compare=False)  # the Records fitted (not saved)

    def __post_init__(self):
        """Tests given as the file's blocks become TestFits, a record given as
        its block a RecordSource, run statistics given as a dict RunStats."""
        object.__setattr__(self, "tests", tuple(t if isinstance(t, TestFit) else TestFit.from_dict(t)
                                                for t in self.tests))
        if not isinstance(self.record, RecordSource):
            object.__setattr__(self, "record", RecordSource.from_dict(self.record))
        object.__setattr__(self, "runs", RunStats.from_dict(self.runs))
        object.__setattr__(self, "intervals", BootstrapIntervals.from_dict(self.intervals))
        object.__setattr__(self, "force_zero", ForceZero.from_dict(self.force_zero))

    def __repr__(self) -> str:
        return f"<Calibration {self.spec} of {self.device or self.record.name or '?'}: OF {self.of:.4g}>"

    @property
    def params(self) -> dict:
        """{name: FittedParameter}: value, unit, stderr, ci95, bounds, per-test
        values, fixed (by the caller: lower bound == upper bound), the
        caller's start value (``settings['start_values']``)."""
        bounds = self.bounds if self.bounds is not None else np.full((len(self.values), 2), np.nan)
        starts = {name: float(v) for spec, name, v in self.settings.get("start_values") or []
                  if spec in (None, self.spec)}
        out = {}
        for name, unit, value, (lo, hi) in zip(self.model.names, self.model.units, self.values, bounds):
            entry = self.intervals.of_parameter(name) if self.intervals else {}
            per_test = {t.name: t.parameters[name] for t in self.tests if name in t.parameters}
            out[name] = FittedParameter(name, float(value), unit, entry.get("stderr"),
                                        tuple(entry["ci95"]) if "ci95" in entry else None,
                                        (num(lo), num(hi)), per_test, fixed=bool(lo == hi), start=starts.get(name))
        return out

    @property
    def correlation(self) -> dict | None:
        """{a: {b: r}}: the parameters' correlation over the bootstrap replicates (None: no intervals)."""
        given = self.intervals.correlation if self.intervals else None
        if not given:
            return None
        names, matrix = given["names"], np.asarray(given["matrix"], dtype=float)
        return {a: {b: float(matrix[i, j]) for j, b in enumerate(names)} for i, a in enumerate(names)}

    def report(self, min_correlation: float = REPORTED_CORRELATION) -> str:
        """The fit report, as text (sections as lmfit's fit_report).

        Parameters
        ----------
        min_correlation : float
            Correlations of the parameters below this magnitude are left out.

        Returns
        -------
        str
            Model, fit statistics, variables with stderr and 95% intervals,
            derived quantities, correlations and warnings.
        """
        return text.report(self, min_correlation)

    @property
    def spec(self) -> str:
        """The model's spec: its law number and effects, e.g. '2+friction'."""
        return self.model.spec

    def named(self, test: str | None = None) -> dict:
        """{parameter name: value} in the model's units.

        Parameters
        ----------
        test : str, optional
            Take the parameters of this test (per-test parameters, ``params_for``); None: the shared ones.
        """
        return dict(zip(self.model.names, map(float, self.params_for(test))))

    def derived(self) -> dict:
        """{name: (value, unit)}: law 8's slip force mu*N [kN]."""
        return self.model.derived(self.values)

    @property
    def tested(self) -> dict:
        """The tested range: peak stroke d [mm], velocity v [mm/s], force F [kN]
        over every test, and the tests' frequencies f = (lowest, highest) in Hz (None: unknown)."""
        return tested_mod.tested(self)

    @property
    def fitted_on(self) -> frozenset:
        """The data its OF was computed on: (record file, else test name;
        samples; weight) of each test.  Two calibrations' OFs rank only when
        these are equal (``same_data``)."""
        return frozenset((*data_key(t), round(float(t.weight), 9)) for t in self.tests)

    def of_on(self, record) -> float:
        """The OF (eq. 18) of the model's force on a record, as ``compare`` computes it.

        Parameters
        ----------
        record : Record
            A test record (kN, mm, s); one of its own tests (same file or
            name, same samples) takes that test's parameters.

        Returns
        -------
        float
            The OF of the model's force against the record's.
        """
        key = ((record.provenance or {}).get("file") or record.name, record.n)
        own = next((t.name for t in self.tests if data_key(t) == key), None)
        F = self.force(record, test=self.test_named(own) if own else None)
        return float(objective(record.F, F, record.t))

    def beyond_tested(self, motion, margin: float = TESTED_MARGIN, what_of: str | None = None) -> list[str]:
        """What of a motion goes beyond the tested range: the model is there an extrapolation.

        Parameters
        ----------
        motion : Record or dict
            A record, or {d, v[, f]}: its peak stroke [mm], velocity [mm/s] and frequency [Hz].
        margin : float
            A peak counts as beyond from this share above the tests' (a
            frequency: outside their band by this share).
        what_of : str, optional
            The motion's name in the messages (a dict's).

        Returns
        -------
        list of str
            One line per quantity beyond the tested range; [] inside it.
        """
        return tested_mod.beyond_tested(self, motion, margin, what_of)

    def tested_text(self) -> str:
        """'tested up to 30 mm and 450 mm/s at 0.8-2.4 Hz (device sn101, 3 tests)': where the model holds."""
        return tested_mod.tested_text(self)

    def provenance_lines(self) -> list[str]:
        """What an export's header says of the calibration: its record and tested range."""
        return tested_mod.provenance_lines(self)

    @property
    def per_test(self) -> dict:
        """{name: {test: value}}: the parameters fitted per test and each
        test's value [the model's units]; {} when every one is shared (always with one test)."""
        if len(self.tests) < 2:
            return {}
        fitted = [name for name in self.model.names if any(name in t.parameters for t in self.tests)]
        return {name: {t.name: float(t.parameters[name]) for t in self.tests if name in t.parameters}
                for name in fitted}

    def for_test(self, test: str | None = None) -> "Calibration":
        """The calibration an export, a comparison or a frame takes.

        Parameters
        ----------
        test : str, optional
            A test's name.  With parameters fitted per test: that test's
            calibration (its values, OF, record, tested range and intervals;
            an export's header says "calibrated on device D, test B").
            Without: the calibration itself.  None with parameters fitted
            per test, or a name of no test, raises InputError naming the tests.

        Returns
        -------
        Calibration
            One parameter vector, no longer per test.
        """
        names = [t.name for t in self.tests]
        if test is not None and test not in names:
            raise InputError(f"{option('--test', test)}: {self.where()} has tests {', '.join(names)}")
        if not self.per_test:
            return self
        if test is None:
            raise InputError(per_test_mod.refusal(self))
        chosen = self.tests[names.index(test)]
        return replace(self, values=self.params_for(test), of=self.of if chosen.of is None else float(chosen.of),
                       record=chosen.record, tests=(chosen,), runs=None,
                       intervals=per_test_mod.intervals_on(self.intervals, test, names[0], tuple(self.per_test)),
                       records=[r for r in self.records if r.name == test])

    def where(self) -> str:
        """The calibration in messages: its file (relative to the working
        folder when inside it), else 'the calibration of device D'."""
        if not self.path:
            return f"the calibration of {self.device or self.record.name or 'its record'}"
        shown = os.path.relpath(self.path)
        return self.path if shown.startswith(os.pardir) else shown

    def test_named(self, name: str) -> str | None:
        """The test whose parameters a record takes.

        Parameters
        ----------
        name : str
            The record's name.

        Returns
        -------
        str or None
            That test when the calibration has several (a parameter fitted per
            test), else None (the shared values).
        """
        return name if len(self.tests) > 1 and name in [t.name for t in self.tests] else None

    def params_for(self, test: str | None = None) -> np.ndarray:
        """The parameter vector on one test.

        Parameters
        ----------
        test : str, optional
            A test's name (InputError for another); parameters fitted per
            test take that test's value.  None: the model's vector (a
            parameter fitted per test: the first test's value; ``for_test``
            refuses it instead).
        """
        if test is None:
            return self.values
        names = [t.name for t in self.tests]
        if test not in names:
            raise InputError(f"{option('--test', test)}: {self.where()} has tests {', '.join(names)}")
        values = {**dict(zip(self.model.names, self.values)), **self.tests[names.index(test)].parameters}
        return np.array([values[n] for n in self.model.names], dtype=float)

    def force(self, record, substeps: int = 1, test: str | None = None) -> np.ndarray:
        """The calibrated model's force on a record.

        Parameters
        ----------
        record : Record
            The motion (d, v, dt).
        substeps : int
            Integration sub-steps per sample (differential laws).
        test : str, optional
            Take the parameters of this test (per-test parameters); None: the shared ones.

        Returns
        -------
        numpy.ndarray
            The force [kN], one value per sample.
        """
        return self.model.force(record, self.params_for(test)[None, :], substeps)[0]

    @classmethod
    def from_fit(cls, model, fit, record, settings: dict | None = None, warnings=(), runs: dict | None = None,
                 intervals=None):
        """A calibration from a fit.

        The model's vector holds the first test's values; a parameter fitted
        per test keeps each test's value in ``tests``.

        Parameters
        ----------
        model : Model
            The fitted model.
        fit : FitResult
            Its fit.
        record : Record or Device
            What it was fitted on (a Device: its tests).
        settings : dict, optional
            The fit's settings, kept as provenance.
        warnings : sequence of str
            The fit's warnings (the tests' unit overrides, read from their
            provenance, follow them: ``records.readers.unit_overrides``).
        runs : RunStats or dict, optional
            Statistics over repeated runs: {of_mean, of_sigma, p_mean, p_sigma}
            (the parameter vectors may hold the per-test columns after the model's).
        intervals : Intervals, optional
            The parameters' intervals (``fit.intervals``; with the fit's
            force zero, the zero's too).
        """
        device = as_device(record)
        n = len(model.names)
        per_test = tuple(dict.fromkeys(name.split(SEP)[0] for name in fit.names[n:]))  # in the fit's column order
        layout = Layout(model, tuple(device.test_names), per_test)
        test_of = fit.test_of or [float(fit.of)]
        tests = []
        for k, (test, w) in enumerate(zip(device.tests, device.weights)):
            p = np.asarray(fit.values, dtype=float)[layout.columns(k)]
            tests.append(TestFit(test.name, float(w), float(test_of[k]), tested_range(test), record_provenance(test),
                                 {m: float(p[model.names.index(m)]) for m in layout.free}))
        return cls(model=model, values=np.asarray(fit.values, dtype=float)[:n], of=float(fit.of),
                   bounds=np.asarray(fit.bounds, dtype=float)[:n], record=tests[0].record,
                   settings=dict(settings or {}), runs=RunStats.from_dict(runs, n),
                   warnings=list(warnings) + [w for t in device.tests for w in t.provenance.get("unit_overrides", [])],
                   tests=tuple(tests),
                   device=device.name,
                   intervals=None if intervals is None else BootstrapIntervals.from_dict(intervals.as_dict()),
                   solver=SolverStatus(fit.optimizer, fit.stop, int(fit.evaluations)),
                   force_zero=ForceZero.of_fit(fit, device, intervals),
                   records=list(device.tests))

    @classmethod
    def from_runs(cls, model, fitted, record, *, settings: dict, warnings=(), intervals=None):
        """A calibration from its seeded runs: the best run, with the
        statistics over the runs asked and the record's noise floor.

        Parameters
        ----------
        model : Model
            The fitted model.
        fitted : FittedRuns
            Its runs on ``record`` (``calibration.runs.fit_runs``).
        record : Record or Device
            What it was fitted on.
        settings : dict
            The request's settings (``FitRequest.as_settings`` or a campaign's),
            kept as provenance with the runs made and the best run's seed.
        warnings : sequence of str
            The fit's warnings (``calibration.checks``).
        intervals : Intervals, optional
            The best run's intervals (``calibration.runs.fit_intervals``).
        """
        best, wider = fitted.best, fitted.wider_runs
        settings = {**settings, "runs_made": len(fitted.asked), **({"wider_runs": wider} if wider else {}),
                    "best_run_seed": list(np.atleast_1d(best.seed).tolist())}
        cal = cls.from_fit(model, best, record, settings, warnings, fitted.stats(), intervals)
        return replace(cal, solver=replace(cal.solver, floor=fitted.floor))

    def to_dict(self) -> dict:
        """The file's mapping (``schema``)."""
        return schema.to_dict(self)

    def interval_lines(self) -> list[str]:
        """'C = 39.87 kN/(mm/s)^alpha, 95% [39.9, 40.1] (stderr 0.05)' per
        parameter and derived quantity, then what is not identified; [] without intervals."""
        return text.interval_lines(self)

    def save(self, path: str) -> str:
        """Write the calibration file (YAML, schema 3) atomically.

        Parameters
        ----------
        path : str
            The file to write (its folder is made).

        Returns
        -------
        str
            ``path``.
        """
        with atomic_file(path) as fh:
            yaml.safe_dump(self.to_dict(), fh, sort_keys=False, width=100)
        return path

    @classmethod
    def load(cls, path: str, catalog=None, plugins=()) -> "Calibration":
        """Read and check a calibration file (schema 1, 2 or 3); it imports nothing.

        Parameters
        ----------
        path : str
            The calibration file.
        catalog : Catalog, optional
            Where plugin effects come from (its plugin files stand for ``plugins``).
        plugins : list of str
            The plugin files of a model with effects of your own; each must be
            the one the file records (same file name and sha256).

        Returns
        -------
        Calibration
            A malformed file raises InputError naming the file and key; a
            model whose plugin is not given, or differs, raises PluginNeeded
            naming it (file name and sha256).
        """
        return cls(**schema.read(path, catalog, plugins))

