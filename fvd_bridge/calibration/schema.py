"""The calibration file's schema:  ``Calibration.save`` writes it,
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
    values_sha256: 3f1c0a9b27d4          # of the values above and the tests' as the fit wrote them (0.4)
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
    solver: {optimizer, stop, evaluations}   # how the best run's search ended (0.4: files before lack it)
    force_zero:                          # the tests' force zero, fitted beside the model (0.4; --force-zero
      equation, exported: false,         # per-test): never part of the model, never exported
      tests: {TEST: {F0: {value, unit: kN, stderr, ci95}, F1: {value, unit: kN/s, ...}, pinned_by}}
    settings: {...}                      # optimizer, bounds, seed, plugins: [{file, sha256}], ...
    warnings: [...]

A value edited by hand no longer matches ``values_sha256``: the file
loads (a value set on purpose is the user's to set) with a warning, kept
among its warnings, that its OF, runs and intervals describe the values
the fit wrote, not these.

A file never runs code: ``settings.plugins`` names the plugin files of the
model's effects (file name and sha256), and ``load`` imports a plugin only
when its caller gives it (``plugins=``, ``--plugin``) and it matches.
"""

from __future__ import annotations

import hashlib
import os
import warnings

import numpy as np
import yaml

from .._version import __version__
from ..catalog import catalog_for, plugin_files, recorded_plugins
from ..errors import FitWarning, InputError
from ..fit.layout import SEP
from ..io.staging import plain
from .parts import BootstrapIntervals, Peaks, RecordSource, RunStats, SolverStatus, TestFit
from .zero import ForceZero

SCHEMA_VERSION = 3
READABLE_SCHEMAS = (1, 2, 3)
KIND = "fvd_bridge.calibration"
UNITS = {"force": "kN", "displacement": "mm", "time": "s"}
#: the key of the digest of the parameter values as the fit wrote them (``values_digest``)
DIGEST_KEY = "values_sha256"


def values_digest(values, tests) -> str:
    """sha256 (12 hex digits) of the parameter values and of each test's
    (its per-test values), as floats in the file's order: what a hand edit
    of a value changes."""
    text = repr([float(v) for v in values]) + repr([[(k, float(v)) for k, v in t.parameters.items()] for t in tests])
    return hashlib.sha256(text.encode()).hexdigest()[:12]


def to_dict(cal) -> dict:
    """The file's mapping of a Calibration (the module docstring)."""
    law = cal.model.law
    runs = cal.runs or RunStats(float(cal.of), 0.0)
    p_mean = cal.values if runs.p_mean is None else runs.p_mean
    p_sigma = np.zeros(len(cal.values)) if runs.p_sigma is None else runs.p_sigma
    derived_info = {d.name: d.description for d in law.derived}
    return {
        "schema_version": SCHEMA_VERSION,
        "kind": KIND,
        "fvd_bridge_version": __version__,
        "model": cal.spec,
        "law": {"number": law.number, "name": law.name, "equation": law.equation, "source": law.source},
        "effects": [{"name": e.name, "equation": e.equation, "summary": e.summary} for e in cal.model.effects],
        "units": dict(UNITS),
        "parameters": {
            p.name: {"value": p.value, "unit": p.unit, "bounds": list(p.bounds),
                     "mean_over_runs": float(m), "sigma_over_runs": float(s),
                     **_interval_entry(cal, p.name),
                     **({"per_test": p.per_test} if p.per_test else {})}
            for p, m, s in zip(cal.params.values(), p_mean, p_sigma)},
        DIGEST_KEY: values_digest(cal.values, cal.tests),
        "derived": {name: {"value": value, "unit": unit, "description": derived_info[name],
                           **(cal.intervals.derived[name].as_dict()
                              if cal.intervals and name in cal.intervals.derived else {})}
                    for name, (value, unit) in cal.derived().items()},
        **({"intervals": {k: plain(getattr(cal.intervals, k)) for k in ("replicates", "method", "noise_of", "note",
                                                                            "not_identified")},
            "correlation": plain(cal.intervals.correlation)} if cal.intervals else {}),
        "of": float(cal.of),
        "of_mean_over_runs": float(runs.of_mean),
        "of_sigma_over_runs": float(runs.of_sigma),
        "device": cal.device or cal.record.name,
        "tests": plain([t.as_dict() for t in cal.tests]),
        "tested_range": plain(cal.tested),
        "record": plain(cal.record.as_dict()),
        **({"solver": plain(cal.solver.as_dict())} if cal.solver is not None else {}),
        **({"force_zero": plain(cal.force_zero.as_dict())} if cal.force_zero is not None else {}),
        "settings": plain({**cal.settings, "plugins": plugin_files(cal.model)}),
        "warnings": [str(w) for w in cal.warnings],
    }


def _interval_entry(cal, name: str) -> dict:
    """A parameter's intervals in the file: {stderr, ci95[, per_test_ci95:
    {TEST: ci95}, every test's, the first's being ci95]}; {} without intervals."""
    entry = cal.intervals.of_parameter(name) if cal.intervals else {}
    if "per_test_ci95" in entry:
        entry["per_test_ci95"] = {cal.tests[0].name: list(entry["ci95"]), **entry["per_test_ci95"]}
    return entry


def read(path: str, catalog=None, plugins=()) -> dict:
    """The checked content of a calibration file as ``Calibration``'s
    fields (``Calibration.load``; its tests TestFits, its run statistics
    RunStats); it imports nothing but the plugins given."""
    data = _read_yaml(path)
    if not isinstance(data, dict) or data.get("kind") != KIND:
        raise InputError(f"{path}: not an fvd_bridge calibration file (key 'kind')")
    if data.get("schema_version") not in READABLE_SCHEMAS:
        raise InputError(f"{path}: key 'schema_version': {data.get('schema_version')!r} is not supported "
                         f"(supported: {', '.join(map(str, READABLE_SCHEMAS))})")
    settings = data.get("settings") or {}
    if not isinstance(settings, dict):
        raise InputError(f"{path}: key 'settings' must be a mapping")
    model = _model(path, data.get("model", ""), recorded_plugins(path, settings.get("plugins") or []), plugins,
                   catalog)
    _agree(path, data, model)
    values, bounds, means, sigmas = _parameters(path, data.get("parameters"), model)
    of = _number(path, "of", data.get("of"))
    record = RecordSource.from_dict(data.get("record"))  # v1 kept no format, columns, units, reading or peaks
    tests = _tests(path, data.get("tests"), record, of, model)
    _per_test_agree(path, data["parameters"], tests, model)
    notes = list(data.get("warnings") or [])
    digest = data.get(DIGEST_KEY)
    if digest is not None and str(digest) != values_digest(values, tests):
        edited = (f"{path}: the parameter values are not those the fit wrote (key '{DIGEST_KEY}'): its OF, runs and "
                  f"intervals describe the fit's values, not these; calibrate again, or delete the key to take "
                  f"these values as given")
        warnings.warn(edited, FitWarning, stacklevel=3)
        notes = [n for n in notes if n != edited] + [edited]
    runs = RunStats(_number(path, "of_mean_over_runs", data.get("of_mean_over_runs", of)),
                    _number(path, "of_sigma_over_runs", data.get("of_sigma_over_runs", 0.0)),
                    tuple(map(float, means)), tuple(map(float, sigmas)))
    return {"model": model, "values": values, "of": of, "bounds": bounds, "record": record,
            "settings": dict(settings), "warnings": notes, "runs": runs,
            "path": os.path.abspath(path), "tests": tests,
            "device": str(data.get("device") or record.name or ""), "intervals": _intervals(data),
            "solver": SolverStatus.from_dict(data.get("solver")), "force_zero": _force_zero(path, data)}


def _model(path: str, spec, recorded: dict, plugins, catalog):
    """The Model of the file's key 'model', from the registry with the
    plugins the caller gives for the effects the file names (``catalog_for``:
    an effect neither built in nor given is PluginNeeded, naming it)."""
    catalog = catalog_for(path, spec, recorded, plugins, catalog)
    try:
        return catalog.model(spec)
    except InputError as exc:
        raise InputError(f"{path}: key 'model': '{spec}': {exc}") from None


def _agree(path: str, data: dict, model) -> None:
    """The blocks that restate the model line agree with it: key 'law' is
    its law, key 'effects' its effects, key 'units' kN, mm, s, key
    'derived' the law's derived quantities; else one line naming the key."""
    spec, law = data.get("model"), data.get("law")
    if not isinstance(law, dict) or str(law.get("number")) != str(model.law.number):
        given = law.get("number") if isinstance(law, dict) else law
        raise InputError(f"{path}: key 'law.number': {given!r} is not the law of key 'model' '{spec}' "
                         f"(law {model.law.number}); edit both or neither")
    effects = data.get("effects")
    listed = [e.get("name") if isinstance(e, dict) else e for e in effects] if isinstance(effects, list) else effects
    if not isinstance(listed, list) or sorted(map(str, listed)) != sorted(model.effect_names):
        raise InputError(f"{path}: key 'effects' lists {_names(listed)}, key 'model' '{spec}' has "
                         f"{_names(model.effect_names)}; edit both or neither")
    if data.get("units") != UNITS:
        raise InputError(f"{path}: key 'units': {data.get('units')!r}, expected {UNITS} (a calibration file "
                         f"holds kN, mm, s; an export converts)")
    derived = data.get("derived") or {}
    extra = sorted(set(derived) - {d.name for d in model.law.derived}) if isinstance(derived, dict) else ["?"]
    if extra:
        raise InputError(f"{path}: key 'derived.{extra[0]}' is not a derived quantity of law {model.law.number}")


def _names(names) -> str:
    """'friction, gap', or 'none'."""
    return ", ".join(map(str, names)) if isinstance(names, list) and names else "none"


def _tests(path: str, given, record: RecordSource, of: float, model) -> tuple:
    """The file's tests as TestFits, each test's parameters of the model's
    and numbers; a file without tests (schema 1) has one, its record's, with
    the record's peak stroke [mm] and velocity [mm/s]."""
    if not given:
        return (TestFit(record.name, 1.0, of, {"d": record.peaks.d, "v": record.peaks.v}, record),)
    if not isinstance(given, list) or not all(isinstance(t, dict) and "name" in t for t in given):
        raise InputError(f"{path}: key 'tests' must be a list of mappings with a 'name'")
    names = [t["name"] for t in given]
    if len(set(names)) < len(names):
        raise InputError(f"{path}: key 'tests' names a test twice ({', '.join(map(str, names))})")
    for t in given:
        parameters = t.get("parameters") or {}
        for name, value in (parameters.items() if isinstance(parameters, dict) else [("?", None)]):
            where = f"tests[{t['name']}].parameters.{name}"
            if name not in model.names:
                raise InputError(f"{path}: key '{where}' is not a parameter of model {model.spec}")
            _number(path, where, value)
    return tuple(TestFit.from_dict(t) for t in given)


def _per_test_agree(path: str, given: dict, tests: tuple, model) -> None:
    """A parameter's 'per_test' values are its tests' (their blocks are what
    loads), the first test's its 'value', its 'per_test_ci95' of those tests."""
    names = [t.name for t in tests]
    for name in model.names:
        entry = given[name]
        held = {t.name: float(t.parameters[name]) for t in tests if name in t.parameters}
        listed = entry.get("per_test") or {}
        if not isinstance(listed, dict) or set(listed) != set(held):
            raise InputError(f"{path}: key 'parameters.{name}.per_test' names tests {_names(list(listed))}, "
                             f"key 'tests' fits {name} per test on {_names(list(held))}")
        for test, value in held.items():
            if not np.isclose(_number(path, f"parameters.{name}.per_test.{test}", listed[test]), value, rtol=1e-12):
                raise InputError(f"{path}: key 'parameters.{name}.per_test.{test}': {listed[test]!r}, but key "
                                 f"'tests' ({test}) holds {value!r}; edit both or neither")
        if names[0] in held and not np.isclose(float(entry["value"]), held[names[0]], rtol=1e-12):
            raise InputError(f"{path}: key 'parameters.{name}.value': {entry['value']!r} is not the first test's "
                             f"({names[0]}: {held[names[0]]!r}), which the model's vector holds")
        unknown = sorted(set(entry.get("per_test_ci95") or {}) - set(held))
        if unknown:
            raise InputError(f"{path}: key 'parameters.{name}.per_test_ci95.{unknown[0]}': {name} was not fitted "
                             f"per test on {unknown[0]}")


def record_provenance(record) -> RecordSource:
    """The RecordSource of a Record (the calibration file's 'record' block), from its provenance."""
    prov = record.provenance
    scales = record.scales()
    return RecordSource(name=record.name, file=prov.get("file"), format=prov.get("format"), samples=record.n,
                        dt=record.dt, columns=prov.get("columns"), window=prov.get("window"),
                        source_units=prov.get("units"), reading=prov.get("reading"), velocity=prov.get("velocity"),
                        peaks=Peaks(scales["F"], scales["v"], scales["d"]))


def _intervals(data: dict) -> BootstrapIntervals | None:
    """The intervals of a loaded file (None: none)."""
    if not data.get("intervals"):
        return None
    params = {n: {"stderr": e["stderr"], "ci95": e["ci95"]} for n, e in data["parameters"].items() if "ci95" in e}
    first = (data.get("tests") or [{}])[0].get("name")  # its interval is the parameter's ci95 (0.4 writes it twice)
    for n, e in data["parameters"].items():
        for test, ci in (e.get("per_test_ci95") or {}).items():
            if test != first:
                params[f"{n}{SEP}{test}"] = {"stderr": None, "ci95": ci}
    derived = {n: d for n, d in (data.get("derived") or {}).items() if "ci95" in d}
    return BootstrapIntervals.from_dict({**data["intervals"], "parameters": params, "derived": derived,
                                         "correlation": data.get("correlation")})


def _read_yaml(path: str):
    try:
        with open(path) as fh:
            return yaml.safe_load(fh)
    except OSError as exc:
        raise InputError(f"{path}: cannot read ({exc.strerror})") from None
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark else ""
        raise InputError(f"{path}: {where}not valid YAML: {exc.problem or exc.context} (an indentation or a ':' "
                         f"out of place?)") from None
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
            raise InputError(f"{path}: key 'parameters.{name}' is missing (model {model.spec} has "
                             f"{', '.join(model.names)}; the file {', '.join(map(str, given)) or 'none'})")
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


def _force_zero(path: str, data: dict):
    """The file's tests' force zero (None: not fitted): per test, F0 and F1 with a numeric value."""
    block = data.get("force_zero")
    if not block:
        return None
    tests = block.get("tests") if isinstance(block, dict) else None
    if not isinstance(tests, dict):
        raise InputError(f"{path}: key 'force_zero.tests' must be a mapping of test names")
    for test, zero in tests.items():
        for name in ("F0", "F1"):
            entry = zero.get(name) if isinstance(zero, dict) else None
            if not isinstance(entry, dict):
                raise InputError(f"{path}: key 'force_zero.tests.{test}.{name}' is missing")
            _number(path, f"force_zero.tests.{test}.{name}.value", entry.get("value"))
    return ForceZero.from_dict(block)
