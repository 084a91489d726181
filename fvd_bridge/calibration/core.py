"""The calibration file: one calibrated model of one device, the contract
between identification and every exporter (OpenSees, FMU, frames, compare).

This module owns the schema: ``Calibration.save`` writes it,
``Calibration.load`` reads it (schema_version 3; 2, and 1 as written by
fvd_bridge 0.1) and refuses a malformed file with a one-line message naming
the file and key.  Schema 3 (YAML; kN, mm, s)::

    schema_version: 3
    kind: fvd_bridge.calibration
    fvd_bridge_version: '0.2.0'
    model: 2+friction                    # the spec: law number + effects
    law: {number, name, equation, source}
    effects: [{name, equation, summary}, ...] (summary: what the effect is and, for a
             spring, where it sits: series_stiffness or oil_column)
    units: {force: kN, displacement: mm, time: s}
    parameters:                          # model order: the law's, then 'effect.param'
      C: {value, unit, bounds: [lo, hi], mean_over_runs, sigma_over_runs,
          stderr, ci95: [lo, hi],          # bootstrap intervals (fit.intervals), when computed
          per_test: {TEST: value}, per_test_ci95: {TEST: [lo, hi]}}   # a parameter fitted per test
    derived:                             # quantities of the parameters (law 8: mu*N)
      mu*N: {value, unit, description, stderr, ci95}
    intervals: {replicates, method, not_identified: [...]}   # when computed
    correlation: {names: [...], matrix: [[...]]}
    of: 0.0123                           # eq. 18 (a device's tests: their weighted mean)
    of_mean_over_runs, of_sigma_over_runs
    device: NAME                         # the device the tests belong to
    tests:                               # every test fitted (one for a single record)
      - {name, weight, of, range: {d [mm], v [mm/s], f [Hz]}, record: {...as below}}
    tested_range: {d [mm], v [mm/s], F [kN], f: [lo, hi] [Hz]}   # envelope of the tests
    record:                              # provenance of the (first) calibration record
      name, file, format, samples, dt [s], columns {t, d, F[, v]}, window,
      source_units {t, d, F[, v]}, velocity {method, ...}, peaks {F [kN], v [mm/s], d [mm]}
    settings: {...}                      # optimizer, bounds, seed, plugins: [{file, sha256}], ...
    warnings: [...]

A file never runs code: ``settings.plugins`` names the plugin files of the
model's effects (file name and sha256), and ``load`` imports a plugin only
when its caller gives it (``plugins=``, ``--plugin``) and it matches.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field

import numpy as np
import yaml

from ._version import __version__
from .catalog import catalog_for, plugin_files, recorded_plugins
from .errors import InputError, option
from .fit.layout import SEP, Layout
from .fit.objective import objective
from .io.staging import atomic_file
from .records.device import as_device, tested_range

SCHEMA_VERSION = 3
READABLE_SCHEMAS = (1, 2, 3)
KIND = "fvd_bridge.calibration"
UNITS = {"force": "kN", "displacement": "mm", "time": "s"}


#: a motion counts as beyond the tested range from this share above its peaks
TESTED_MARGIN = 0.05
#: the report lists correlations of at least this magnitude (lmfit's default)
REPORTED_CORRELATION = 0.1


@dataclass(frozen=True)
class FittedParameter:
    """One calibrated parameter: ``value`` [``unit``]; ``stderr`` and the 95%
    interval ``ci95`` (lower, upper) of the bootstrap (``fit.intervals``;
    None: not computed); the search ``bounds`` (lower, upper; None where
    unknown); ``per_test``: {test: value} of a parameter fitted per test."""

    name: str
    value: float
    unit: str
    stderr: float | None = None
    ci95: tuple | None = None
    bounds: tuple = (None, None)
    per_test: dict = field(default_factory=dict)

    def __float__(self) -> float:
        return float(self.value)

    def text(self) -> str:
        """'C = 45.06 +/- 0.05 (0.11%) kN/(mm/s)^alpha, 95% [44.96, 45.16]'."""
        out = f"{self.name} = {self.value:.6g}"
        if self.stderr is not None:
            rel = f" ({abs(self.stderr / self.value):.2%})" if self.value else ""
            out += f" +/- {self.stderr:.2g}{rel}"
        out += f" {self.unit}" if self.unit != "-" else ""
        if self.ci95 is not None:
            out += f", 95% [{self.ci95[0]:.6g}, {self.ci95[1]:.6g}]"
        return out

    def __repr__(self) -> str:
        return f"<FittedParameter {self.text()}>"


@dataclass
class Calibration:
    """A calibrated model: the Model, its parameter vector (model order) with
    bounds and run statistics, the OF, where the record came from, the settings
    and the fit warnings."""

    model: object  # fvd_bridge.model.Model
    values: np.ndarray  # the parameters in model order [the model's units]
    of: float
    bounds: np.ndarray | None = None
    record: dict = field(default_factory=dict)
    settings: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)
    runs: dict = field(default_factory=dict)  # of_mean, of_sigma, p_mean, p_sigma over runs
    path: str | None = None  # the file it was read from
    tests: list = field(default_factory=list)  # per test: name, weight, of, range, record, parameters
    device: str = ""
    intervals: dict = field(default_factory=dict)  # fit.intervals.Intervals.as_dict() ({} : none)
    records: list = field(default_factory=list, repr=False, compare=False)  # the Records fitted (not saved)

    def __repr__(self) -> str:
        return f"<Calibration {self.spec} of {self.device or self.record.get('name', '?')}: OF {self.of:.4g}>"

    @property
    def params(self) -> dict:
        """{name: FittedParameter}: value, unit, stderr, ci95, bounds, per-test values."""
        bounds = self.bounds if self.bounds is not None else np.full((len(self.values), 2), np.nan)
        out = {}
        for name, unit, value, (lo, hi) in zip(self.model.names, self.model.units, self.values, bounds):
            entry = self._interval(name)
            per_test = {t["name"]: t["parameters"][name] for t in self.tests if name in (t.get("parameters") or {})}
            out[name] = FittedParameter(name, float(value), unit, entry.get("stderr"),
                                        tuple(entry["ci95"]) if "ci95" in entry else None,
                                        (_num(lo), _num(hi)), per_test)
        return out

    @property
    def correlation(self) -> dict | None:
        """{a: {b: r}}: the parameters' correlation over the bootstrap replicates (None: no intervals)."""
        given = self.intervals.get("correlation") if self.intervals else None
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
        law = self.model.law
        n = sum((t.get("record") or {}).get("samples") or 0 for t in self.tests) or self.record.get("samples")
        lines = ["[[Model]]", f"    {self.spec}: law {law.key} ({law.name}), {law.equation}"]
        lines += [f"    + {e.name}: {e.equation}" for e in self.model.effects]
        lines += ["[[Fit Statistics]]",
                  f"    device:        {self.device or self.record.get('name')} ({len(self.tests) or 1} test(s), "
                  f"{n} samples)",
                  f"    OF (eq. 18):   {self.of:.6g}"]
        lines += [f"    OF {t['name']}: {t['of']:.6g}" for t in self.tests if len(self.tests) > 1]
        if self.runs.get("of_sigma") is not None and self.settings.get("runs", 1) > 1:
            lines.append(f"    runs:          {self.settings['runs']} (OF mean {self.runs['of_mean']:.6g}, "
                         f"sigma {self.runs['of_sigma']:.2g})")
        if self.settings.get("optimizer"):
            lines.append(f"    optimizer:     {self.settings['optimizer']}, seed {self.settings.get('seed')}")
        lines += [f"    {self.tested_text()}", "[[Variables]]"]
        for p in self.params.values():
            bounds = "" if None in p.bounds else f"  (bounds [{p.bounds[0]:.4g}, {p.bounds[1]:.4g}])"
            lines.append(f"    {p.text()}{bounds}")
            lines += [f"        {test}: {v:.6g}" for test, v in p.per_test.items()]
        if self.derived():
            lines.append("[[Derived]]")
            lines += [f"    {name} = {value:.6g} {unit}" for name, (value, unit) in self.derived().items()]
        if not self.intervals:
            lines.append("    (no intervals: calibrate with intervals > 0)")
        lines += [f"    not identified: {line}" for line in self.intervals.get("not_identified") or []]
        corr = self.correlation
        if corr:
            names = list(corr)
            pairs = sorted(((corr[a][b], a, b) for i, a in enumerate(names) for b in names[i + 1:]
                            if abs(corr[a][b]) >= min_correlation), key=lambda x: -abs(x[0]))
            lines.append(f"[[Correlations]] (unreported correlations are < {min_correlation:.3f})")
            lines += [f"    C({a}, {b}) = {r:+.4f}" for r, a, b in pairs]
        if self.warnings:
            lines.append("[[Warnings]]")
            lines += [f"    {w}" for w in self.warnings]
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        """The fit report as an HTML table (a notebook shows it)."""
        from .report.html import calibration_table

        return calibration_table(self)

    def plot(self, ax=None, record=None, x: str = "d"):
        """Measured and model force of a test.

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Where to draw; None: a new figure.
        record : Record, optional
            The test; default the first test fitted (a loaded calibration has none: give it).
        x : {'d', 'v', 't'}
            Against displacement, velocity or time.

        Returns
        -------
        matplotlib Axes
            The Axes drawn on, left open.
        """
        from .plots.record import loop

        if record is None and not self.records:
            raise InputError("Calibration.plot: give record= (a loaded calibration keeps no record)")
        record = record if record is not None else self.records[0]
        return loop(record, self.force(record, test=self.test_named(record.name)), ax=ax, x=x,
                    title=f"{self.spec} on {record.name}")

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
        ranges = [t.get("range") or {} for t in self.tests]
        peaks = (self.record or {}).get("peaks") or {}
        out = {k: max([r[k] for r in ranges if r.get(k)] + [peaks.get(k) or 0.0]) or None for k in ("d", "v")}
        out["F"] = max([(t.get("record") or {}).get("peaks", {}).get("F") or 0.0 for t in self.tests]
                       + [peaks.get("F") or 0.0]) or None
        f = [r["f"] for r in ranges if r.get("f")]
        out["f"] = [min(f), max(f)] if f else None
        return out

    @property
    def fitted_on(self) -> frozenset:
        """The data its OF was computed on: (record file, else test name;
        samples; weight) of each test.  Two calibrations' OFs rank only when
        these are equal (``same_data``)."""
        return frozenset((*data_key(t), round(float(t.get("weight", 1.0)), 9)) for t in self.tests)

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
        own = next((t["name"] for t in self.tests if data_key(t) == key), None)
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
        if isinstance(motion, dict):
            name, mine = what_of or "the motion", motion
        else:
            name, mine = motion.name, tested_range(motion)
        ref, where = self.tested, self.device or (self.record or {}).get("name", "its record")
        out = []
        for key, what, unit in (("d", "stroke", "mm"), ("v", "velocity", "mm/s")):
            if ref.get(key) and mine.get(key) and mine[key] > (1.0 + margin) * ref[key]:
                out.append(f"{name}: peak {what} {mine[key]:.4g} {unit} is beyond the {ref[key]:.4g} {unit} "
                           f"the model was calibrated on ({where}): an extrapolation")
        f, (lo, hi) = mine.get("f"), ref.get("f") or (None, None)
        if f and lo and not (1.0 - margin) * lo <= f <= (1.0 + margin) * hi:
            out.append(f"{name}: dominant frequency {f:.3g} Hz is outside the {_band(lo, hi)} the model was "
                       f"calibrated on ({where}): an extrapolation")
        return out

    def tested_text(self) -> str:
        """'tested up to 30 mm and 450 mm/s at 0.8-2.4 Hz (device sn101, 3 tests)': where the model holds."""
        r = self.tested
        parts = [f"{r[k]:.4g} {u}" for k, u in (("d", "mm"), ("v", "mm/s")) if r.get(k)]
        freq = f" at {_band(*r['f'])}" if r.get("f") else ""
        n = len(self.tests) or 1
        where = f"device {self.device or (self.record or {}).get('name', '?')}, {n} test{'s' if n > 1 else ''}"
        return f"tested up to {' and '.join(parts)}{freq} ({where}); beyond it the model extrapolates"

    def provenance_lines(self) -> list[str]:
        """What an export's header says of the calibration: its record and tested range."""
        name = (self.record or {}).get("name")
        return [*([f"calibrated on record {name}"] if name else []), self.tested_text()]

    def solving(self, export):
        """The OpenSees export as a frame analysis runs it.

        A power-law dashpot that defeats Newton goes behind a spring that
        deflects 0.5% of the tested stroke (``export.opensees.solving_springs``).

        Parameters
        ----------
        export : Export
            The calibration's OpenSees export (``export.opensees.opensees_export``).
        """
        from .export.opensees import solving_springs

        return solving_springs(export, self.tested.get("d"), self.tested.get("v"))

    def export_lines(self, export) -> list[str]:
        """An OpenSees script's header lines of this calibration.

        Its record, tested range and, where a frame analysis runs it
        otherwise, how.

        Parameters
        ----------
        export : Export
            The calibration's OpenSees export.
        """
        from .export.opensees import solving_advice

        return self.provenance_lines() + solving_advice(export, self.solving(export))

    def to_opensees(self, tag: int = 1, units=None):
        """The damper as OpenSees commands.

        Parameters
        ----------
        tag : int
            The damper's uniaxial material tag.
        units : str or tuple, optional
            The OpenSees model's FORCE,LENGTH,TIME, e.g. ``"kN,m,s"`` or
            ``("kN", "m", "s")``; None: kN, mm, s.

        Returns
        -------
        OpenSeesCommands
            A list of (ops function, *args) with ``.apply(ops)`` and
            ``.to_script('py' | 'tcl')`` (the script ``fvd-bridge export
            opensees`` writes).
        """
        from .export.opensees import OpenSeesCommands, opensees_export

        export = opensees_export(self.model, self.named(), tag, units=units)
        return OpenSeesCommands(export, self.export_lines(export))

    def to_fmu(self, path, h_max: float | None = None) -> str:
        """Write the damper as an FMI 3.0 co-simulation FMU (``export.fmu.build_fmu``).

        Parameters
        ----------
        path : str or path-like
            The .fmu file to write (atomically: nothing is left on failure).
        h_max : float, optional
            The largest integration sub-step [s]; default the calibration record's dt.

        Returns
        -------
        str
            The path written.
        """
        from .export.fmu import build_fmu

        return build_fmu(self, path, h_max)

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
        return name if len(self.tests) > 1 and name in [t["name"] for t in self.tests] else None

    def params_for(self, test: str | None = None) -> np.ndarray:
        """The parameter vector on one test.

        Parameters
        ----------
        test : str, optional
            A test's name (InputError for another); parameters fitted per
            test take that test's value.  None: the shared values.
        """
        if test is None:
            return self.values
        names = [t["name"] for t in self.tests]
        if test not in names:
            raise InputError(f"{option('--test', test)}: the calibration has tests {', '.join(names)}")
        values = {**dict(zip(self.model.names, self.values)), **(self.tests[names.index(test)].get("parameters") or {})}
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
            The fit's warnings.
        runs : dict, optional
            Statistics over repeated runs (p_mean, p_sigma, ...).
        intervals : Intervals, optional
            The parameters' intervals (``fit.intervals``).
        """
        device = as_device(record)
        n = len(model.names)
        per_test = tuple(dict.fromkeys(name.split(SEP)[0] for name in fit.names[n:]))  # in the fit's column order
        layout = Layout(model, tuple(device.test_names), per_test)
        test_of = fit.test_of or [float(fit.of)]
        tests = []
        for k, (test, w) in enumerate(zip(device.tests, device.weights)):
            p = np.asarray(fit.params, dtype=float)[layout.columns(k)]
            tests.append({"name": test.name, "weight": float(w), "of": float(test_of[k]),
                          "range": tested_range(test), "record": record_provenance(test),
                          "parameters": {m: float(p[model.names.index(m)]) for m in layout.free}})
        runs = dict(runs or {})
        for key in ("p_mean", "p_sigma"):
            if key in runs:
                runs[key] = np.asarray(runs[key])[:n]
        return cls(model, np.asarray(fit.params, dtype=float)[:n], float(fit.of),
                   np.asarray(fit.bounds, dtype=float)[:n], record_provenance(device.tests[0]),
                   dict(settings or {}), list(warnings), runs, None, tests, device.name,
                   intervals.as_dict() if intervals is not None else {}, list(device.tests))

    def to_dict(self) -> dict:
        """The schema-2 mapping (see the module docstring)."""
        law = self.model.law
        p_mean = self.runs.get("p_mean", self.values)
        p_sigma = self.runs.get("p_sigma", np.zeros(len(self.values)))
        derived_info = {d.name: d.description for d in law.derived}
        return {
            "schema_version": SCHEMA_VERSION,
            "kind": KIND,
            "fvd_bridge_version": __version__,
            "model": self.spec,
            "law": {"number": law.number, "name": law.name, "equation": law.equation, "source": law.source},
            "effects": [{"name": e.name, "equation": e.equation, "summary": e.summary} for e in self.model.effects],
            "units": dict(UNITS),
            "parameters": {
                p.name: {"value": p.value, "unit": p.unit, "bounds": list(p.bounds),
                         "mean_over_runs": float(m), "sigma_over_runs": float(s),
                         **self._interval(p.name), **({"per_test": p.per_test} if p.per_test else {})}
                for p, m, s in zip(self.params.values(), p_mean, p_sigma)},
            "derived": {name: {"value": value, "unit": unit, "description": derived_info[name],
                               **{k: v for k, v in (self.intervals.get("derived") or {}).get(name, {}).items()
                                  if k in ("stderr", "ci95")}}
                        for name, (value, unit) in self.derived().items()},
            **({"intervals": {k: _plain(self.intervals.get(k)) for k in ("replicates", "method", "noise_of", "note",
                                                                           "not_identified")},
                "correlation": _plain(self.intervals["correlation"])} if self.intervals else {}),
            "of": float(self.of),
            "of_mean_over_runs": float(self.runs.get("of_mean", self.of)),
            "of_sigma_over_runs": float(self.runs.get("of_sigma", 0.0)),
            "device": self.device or self.record.get("name"),
            "tests": _plain(self.tests),
            "tested_range": _plain(self.tested),
            "record": _plain(self.record),
            "settings": _plain({**self.settings, "plugins": plugin_files(self.model)}),
            "warnings": [str(w) for w in self.warnings],
        }

    def _interval(self, name: str) -> dict:
        """{stderr, ci95} of one parameter (with its per-test columns' ci95), or {}."""
        given = (self.intervals.get("parameters") or {})
        if name not in given:
            return {}
        out = {"stderr": given[name]["stderr"], "ci95": given[name]["ci95"]}
        per = {n.split(SEP)[1]: v["ci95"] for n, v in given.items() if n.startswith(name + SEP)}
        if per:
            out["per_test_ci95"] = per
        return out

    def interval_lines(self) -> list[str]:
        """'C = 39.87 kN/(mm/s)^alpha, 95% [39.9, 40.1] (stderr 0.05)' per
        parameter and derived quantity, then what is not identified; [] without intervals."""
        if not self.intervals:
            return []
        given = self.intervals["parameters"]
        values = {**self.named(), **{f"{n}{SEP}{t['name']}": v for t in self.tests
                                     for n, v in (t.get("parameters") or {}).items()}}
        units = dict(zip(self.model.names, self.model.units))
        from .report.numbers import interval, rounded  # numbers for people: rounded to the stderr

        def unit(name):
            return "" if units.get(name.split(SEP)[0], "-") == "-" else f" {units[name.split(SEP)[0]]}"

        out = [f"{n} = {rounded(values[n])}{unit(n)} (fixed by the caller)"
               if e["ci95"][0] == e["ci95"][1] else
               f"{n} = {rounded(values[n], e.get('stderr'))}{unit(n)}, 95% {interval(*e['ci95'], e.get('stderr'))}"
               + (f" (stderr {rounded(e['stderr'], digits=2)})" if e.get("stderr") is not None else "")
               for n, e in given.items() if n in values]
        out += [f"{n} = {rounded(d['value'], d['stderr'])} {d['unit']}, 95% {interval(*d['ci95'], d['stderr'])} "
                f"(stderr {rounded(d['stderr'], digits=2)})" for n, d in (self.intervals.get("derived") or {}).items()]
        out += [f"not identified: {line}" for line in self.intervals.get("not_identified") or []]
        return out + ([f"note: {self.intervals['note']}"] if self.intervals.get("note") else [])

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
        data = _read_yaml(path)
        if not isinstance(data, dict) or data.get("kind") != KIND:
            raise InputError(f"{path}: not an fvd_bridge calibration file (key 'kind')")
        if data.get("schema_version") not in READABLE_SCHEMAS:
            raise InputError(f"{path}: key 'schema_version': {data.get('schema_version')!r} is not supported "
                             f"(supported: {', '.join(map(str, READABLE_SCHEMAS))})")
        settings = data.get("settings") or {}
        if not isinstance(settings, dict):
            raise InputError(f"{path}: key 'settings' must be a mapping")
        catalog = catalog_for(path, data.get("model", ""), recorded_plugins(path, settings.get("plugins") or []),
                              plugins, catalog)
        try:
            model = catalog.model(data.get("model", ""))
        except InputError as exc:
            raise InputError(f"{path}: key 'model': {exc}") from None
        values, bounds, means, sigmas = _parameters(path, data.get("parameters"), model)
        of = _number(path, "of", data.get("of"))
        record = dict(data.get("record") or {})
        if data["schema_version"] == 1:  # v1 kept no column mapping or source units
            record.setdefault("columns", None)
            record.setdefault("source_units", None)
        runs = {"of_mean": data.get("of_mean_over_runs", of), "of_sigma": data.get("of_sigma_over_runs", 0.0),
                "p_mean": means, "p_sigma": sigmas}
        tests = data.get("tests") or [{"name": record.get("name"), "weight": 1.0, "of": of, "record": record,
                                       "range": {k: (record.get("peaks") or {}).get(k) for k in ("d", "v")},
                                       "parameters": {}}]
        if not isinstance(tests, list) or not all(isinstance(t, dict) and "name" in t for t in tests):
            raise InputError(f"{path}: key 'tests' must be a list of mappings with a 'name'")
        return cls(model, values, of, bounds, record, dict(settings), list(data.get("warnings") or []), runs,
                   os.path.abspath(path), tests, str(data.get("device") or record.get("name") or ""),
                   _intervals(data))


def record_provenance(record) -> dict:
    """The calibration file's 'record' block from a Record's provenance."""
    prov = record.provenance
    scales = record.scales()
    return {"name": record.name, "file": prov.get("file"), "format": prov.get("format"),
            "samples": record.n, "dt": record.dt, "columns": prov.get("columns"), "window": prov.get("window"),
            "source_units": prov.get("units"), "reading": prov.get("reading"), "velocity": prov.get("velocity"),
            "peaks": {"F": scales["F"], "v": scales["v"], "d": scales["d"]}}


def data_key(test: dict) -> tuple:
    """What a test of a calibration holds: (its record file, else its name; its samples)."""
    block = test.get("record") or {}
    return (block.get("file") or test.get("name"), block.get("samples"))


def same_data(calibrations) -> bool:
    """Whether every calibration's OF was computed on the same tests (files
    or names, samples, weights): only then do their OFs rank."""
    return len({c.fitted_on for c in calibrations}) <= 1


def common_tests(calibrations) -> list[dict]:
    """The tests (as the first calibration holds them) every calibration was fitted on."""
    calibrations = list(calibrations)
    if not calibrations:
        return []
    shared = set.intersection(*({data_key(t) for t in c.tests} for c in calibrations))
    return [t for t in calibrations[0].tests if data_key(t) in shared]


def _band(lo: float, hi: float) -> str:
    """'0.8-2.4 Hz', or '2 Hz' when both ends read alike."""
    a, b = f"{lo:.3g}", f"{hi:.3g}"
    return f"{a} Hz" if a == b else f"{a}-{b} Hz"


def _intervals(data: dict) -> dict:
    """The intervals of a loaded file, in Intervals.as_dict()'s form ({}: none)."""
    if not data.get("intervals"):
        return {}
    params = {n: {"stderr": e["stderr"], "ci95": e["ci95"]} for n, e in data["parameters"].items() if "ci95" in e}
    for n, e in data["parameters"].items():
        for test, ci in (e.get("per_test_ci95") or {}).items():
            params[f"{n}{SEP}{test}"] = {"stderr": None, "ci95": ci}
    derived = {n: d for n, d in (data.get("derived") or {}).items() if "ci95" in d}
    return {**data["intervals"], "parameters": params, "derived": derived, "correlation": data.get("correlation")}


def _read_yaml(path: str):
    try:
        with open(path) as fh:
            return yaml.safe_load(fh)
    except OSError as exc:
        raise InputError(f"{path}: cannot read ({exc.strerror})") from None
    except yaml.YAMLError as exc:
        raise InputError(f"{path}: not valid YAML ({str(exc).splitlines()[0]})") from None


def _number(path: str, key: str, value) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{path}: key '{key}': {value!r} is not a number") from None
    if not np.isfinite(x):
        raise InputError(f"{path}: key '{key}' is not finite")
    return x


def _parameters(path: str, given, model):
    """Values, bounds, run means and sigmas of the model's parameters, checked."""
    if not isinstance(given, dict):
        raise InputError(f"{path}: key 'parameters' must be a mapping")
    values, bounds, means, sigmas = [], [], [], []
    for name, unit in zip(model.names, model.units):
        entry = given.get(name)
        if not isinstance(entry, dict) or "value" not in entry:
            raise InputError(f"{path}: key 'parameters.{name}' is missing (model {model.spec})")
        if entry.get("unit") != unit:
            raise InputError(f"{path}: key 'parameters.{name}.unit': '{entry.get('unit')}', expected '{unit}'")
        value = _number(path, f"parameters.{name}.value", entry["value"])
        values.append(value)
        b = entry.get("bounds")
        bounds.append([float(x) if x is not None else np.nan for x in b] if isinstance(b, list) and len(b) == 2
                      else [np.nan, np.nan])
        means.append(float(entry.get("mean_over_runs", value)))
        sigmas.append(float(entry.get("sigma_over_runs", 0.0)))
    extra = sorted(set(given) - set(model.names))
    if extra:
        raise InputError(f"{path}: key 'parameters.{extra[0]}' is not a parameter of model {model.spec}")
    return np.array(values), np.array(bounds, dtype=float).reshape(-1, 2), np.array(means), np.array(sigmas)


def _num(x):
    x = float(x)
    return None if not np.isfinite(x) else x


def _plain(x):
    """Numpy scalars and arrays, tuples -> plain YAML types."""
    if isinstance(x, dict):
        return {str(k): _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, np.ndarray):
        return [_plain(v) for v in x.tolist()]
    if isinstance(x, np.generic):
        return x.item()
    return x
