"""The typed parts between the stages: a fit is frozen, a calibration's
tests, record sources and run statistics are frozen records, and the
calibration file keeps its shape (files written before the parts were typed
load and save unchanged)."""

from dataclasses import FrozenInstanceError, replace
from pathlib import Path

import numpy as np
import pytest
import yaml

import fvd_bridge as fb
from fvd_bridge.calibration import Calibration
from fvd_bridge.calibration import BootstrapIntervals, Interval, Peaks, RecordSource, RunStats, TestFit
from fvd_bridge.calibration.schema import DIGEST_KEY, values_digest
from fvd_bridge.campaign.store import result_from_dict, result_to_dict
from fvd_bridge.catalog import catalog
from fvd_bridge.errors import InputError
from fvd_bridge.fit import fit_model
from fvd_bridge.records.device import tested_range as peaks_of
from fvd_bridge.rig import VirtualDamper, Noise, paper, simulate

FIXTURES = Path(__file__).resolve().parents[1] / "fixtures"
V3 = FIXTURES / "calibration_v3"


@pytest.fixture(scope="module")
def law2_record():
    return simulate(VirtualDamper(C=45.4, alpha=0.3), paper(cycles=2), Noise(force=0.5), seed=3)


@pytest.fixture(scope="module")
def law2_fit(law2_record):
    return fit_model(catalog().model("2"), law2_record, seed=0)


def test_a_fit_is_frozen_and_replace_gives_a_changed_copy(law2_fit):
    with pytest.raises(FrozenInstanceError):
        law2_fit.of = 0.0
    lower = replace(law2_fit, of=law2_fit.of / 2)
    assert lower.of == law2_fit.of / 2 and lower.values is law2_fit.values and law2_fit.of > lower.of
    # what fit_model adds after the search is in the fit it returns
    assert law2_fit.evaluations > 0 and law2_fit.wall_s > 0 and len(law2_fit.test_of) == 1
    assert law2_fit.test_of[0] == pytest.approx(law2_fit.of, rel=1e-12)


def test_a_stored_unit_reads_back_as_the_same_fit(law2_fit):
    back = result_from_dict(result_to_dict(law2_fit))
    assert back.as_dict() == law2_fit.as_dict() and back.names == law2_fit.names
    assert np.array_equal(back.values, law2_fit.values) and np.array_equal(back.bounds, law2_fit.bounds)


# ------------------------------------------------- the calibration's tests and runs
def shape(x):
    """The keys of a file's mapping all the way down (list items by position), not its numbers."""
    if isinstance(x, dict):
        return {k: shape(v) for k, v in x.items()}
    if isinstance(x, list):
        return [shape(v) for v in x]
    return type(x).__name__ if isinstance(x, (str, bool)) or x is None else "number"


@pytest.mark.parametrize("name", ["device_per_test.yaml", "law8_one_test.yaml"])
def test_files_written_before_the_typed_parts_load_and_save_unchanged(name, tmp_path):
    """The fixtures were written by fvd_bridge 0.3.0 (commit a8ef21b), when the tests were dicts."""
    cal = Calibration.load(str(V3 / name))
    assert isinstance(cal.tests, tuple) and all(isinstance(t, TestFit) for t in cal.tests)
    assert isinstance(cal.runs, RunStats) and len(cal.runs.p_mean) == len(cal.values)
    assert isinstance(cal.record, RecordSource) and all(isinstance(t.record, RecordSource) for t in cal.tests)
    with pytest.raises(FrozenInstanceError):
        cal.of = 0.0
    assert replace(cal, device="other").device == "other" and cal.device != "other"
    again = Calibration.load(cal.save(str(tmp_path / name)))
    written, given = (yaml.safe_load(path.read_text()) for path in (tmp_path / name, V3 / name))
    for entry in written["parameters"].values():  # 0.4 writes every test's interval, the first's (its ci95) too
        if "per_test_ci95" in entry:
            assert entry["per_test_ci95"].pop(cal.tests[0].name) == entry["ci95"]
    assert written.pop(DIGEST_KEY) == values_digest(cal.values, cal.tests)  # new in 0.4: the values' digest
    assert {**written, "fvd_bridge_version": None} == {**given, "fvd_bridge_version": None}
    assert again.tests == cal.tests and again.runs == cal.runs and np.array_equal(again.values, cal.values)
    assert again.record == cal.record and again.intervals == cal.intervals and again.settings == cal.settings
    assert cal.solver is None and again.solver is None  # written before the solver block: none is added
    if name == "device_per_test.yaml":  # intervals with a parameter fitted per test
        assert isinstance(cal.intervals, BootstrapIntervals) and cal.intervals.replicates > 0
        assert all(isinstance(i, Interval) for i in cal.intervals.parameters.values())
        assert cal.params["C"].ci95 == cal.intervals.parameters["C"].ci95


def test_a_fresh_device_calibration_has_typed_parts_and_the_file_shape_of_before(tmp_path):
    dev = VirtualDamper(C=45.4, alpha=0.3, friction=2.0)
    noise = Noise(force=0.5, displacement=0.005)
    slow = simulate(dev, paper(cycles=2), noise, seed=1, name="sn7_slow")
    fast = simulate(dev, paper(amplitude=15.0, velocity=300.0, cycles=2), noise, seed=2, name="sn7_fast")
    cal = fb.calibrate([slow, fast], "2+friction", runs=3, seed=4, device="sn7", per_test=["C"], intervals=20,
                       all_runs=True)
    assert [t.name for t in cal.tests] == ["sn7_slow", "sn7_fast"] and [t.weight for t in cal.tests] == [0.5, 0.5]
    with pytest.raises(FrozenInstanceError):
        cal.tests[0].of = 0.0
    # each test's OF is eq. 18 of the model with that test's parameters on it
    for test, rec in zip(cal.tests, (slow, fast)):
        assert test.of == pytest.approx(cal.of_on(rec), rel=1e-12) and set(test.parameters) == {"C"}
        assert test.record.samples == rec.n and test.range == peaks_of(rec)
    assert cal.params["C"].per_test == {t.name: t.parameters["C"] for t in cal.tests}
    # the run statistics hold the model's parameters only (not the per-test column)
    assert len(cal.runs.p_mean) == len(cal.runs.p_sigma) == 3 and cal.runs.of_mean >= cal.of
    written = cal.to_dict()
    before = yaml.safe_load((V3 / "device_per_test.yaml").read_text())
    # the settings are provenance that follows the optimizer's settings (a new one adds a key there)
    assert list(written["settings"]) == list(before["settings"])
    # the file of before, and the block of how the best run's search ended (new in 0.4)
    solver = written.pop("solver")
    assert written.pop(DIGEST_KEY) == values_digest(cal.values, cal.tests)  # new in 0.4 too
    C = written["parameters"]["C"]  # and every test's interval, the first's (its ci95) too (new in 0.4)
    assert list(C["per_test_ci95"]) == ["sn7_slow", "sn7_fast"] and C["per_test_ci95"].pop("sn7_slow") == C["ci95"]
    assert shape({**written, "settings": {}}) == shape({**before, "settings": {}}) and list(written) == list(before)
    assert solver == cal.solver.as_dict() and cal.solver.optimizer == "local" and cal.solver.stop.startswith("local: ")
    assert cal.solver.evaluations > 0 and f"search:        {cal.solver.evaluations} evaluations" in cal.report()
    assert isinstance(cal.intervals, BootstrapIntervals) and cal.intervals.replicates == 20
    assert set(cal.intervals.parameters) == {"C", "alpha", "friction.Ff", "C@sn7_fast"}
    back = Calibration.load(cal.save(str(tmp_path / "sn7.yaml")))
    assert back.solver == cal.solver and back.intervals.parameters["C@sn7_fast"].ci95 == pytest.approx(
        cal.intervals.parameters["C@sn7_fast"].ci95)
    assert written["tests"] == [t.as_dict() for t in cal.tests]
    assert written["of_mean_over_runs"] == cal.runs.of_mean and written["of_sigma_over_runs"] == cal.runs.of_sigma


def test_run_statistics_from_a_dict_and_without_runs(law2_fit):
    rec = simulate(VirtualDamper(C=45.4, alpha=0.3), paper(cycles=2), Noise(force=0.5), seed=3)
    model = catalog().model("2")
    alone = Calibration.from_fit(model, law2_fit, rec)
    assert alone.runs is None
    d = alone.to_dict()
    assert (d["of_mean_over_runs"], d["of_sigma_over_runs"]) == (alone.of, 0.0)
    assert [p["mean_over_runs"] for p in d["parameters"].values()] == list(alone.values)
    runs = {"of_mean": 0.2, "of_sigma": 0.01, "p_mean": np.array([45.0, 0.3, 9.0]), "p_sigma": np.array([1, 0, 9])}
    kept = Calibration.from_fit(model, law2_fit, rec, runs=runs)
    assert kept.runs == RunStats(0.2, 0.01, (45.0, 0.3), (1.0, 0.0))
    with pytest.raises(InputError, match="of_mean, of_sigma"):
        RunStats.from_dict({"of_mean": 0.2, "of_sd": 0.01})


# ------------------------------------------------- the record's source
def test_a_record_source_round_trips_through_its_file_block():
    block = yaml.safe_load((V3 / "law8_one_test.yaml").read_text())["record"]
    source = RecordSource.from_dict(block)
    assert source.name == "sn7_slow" and source.samples == 854 and source.dt == 0.002 and source.file is None
    assert source.velocity == {"method": "exact (rig protocol)"} and source.peaks.F == block["peaks"]["F"]
    assert source.as_dict() == block and list(source.as_dict()) == list(block)
    assert RecordSource.from_dict(source.as_dict()) == source
    with pytest.raises(FrozenInstanceError):
        source.peaks.F = 0.0
    assert RecordSource.from_dict(None) == RecordSource.from_dict({}) == RecordSource()
    assert RecordSource().peaks == Peaks() and not hasattr(RecordSource(), "get")


def test_a_fitted_calibration_keeps_its_records_own_peaks(law2_record, law2_fit):
    rec = law2_record
    cal = Calibration.from_fit(catalog().model("2"), law2_fit, rec)
    assert isinstance(cal.record, RecordSource) and cal.record == cal.tests[0].record
    assert cal.record.peaks.F == float(np.max(np.abs(rec.F))) and cal.record.samples == rec.n
    assert cal.record.name == rec.name and cal.record.dt == rec.dt
    assert cal.to_dict()["record"]["peaks"]["F"] == cal.record.peaks.F


def test_a_file_without_some_record_keys_loads(tmp_path):
    """A schema 1 file keeps no format, columns, units, reading or peaks; an unknown key is left out."""
    raw = yaml.safe_load((FIXTURES / "calibration_v1" / "law8.yaml").read_text())
    raw["record"]["rig_operator"] = "someone"
    (tmp_path / "old.yaml").write_text(yaml.safe_dump(raw, sort_keys=False))
    cal = Calibration.load(str(tmp_path / "old.yaml"))
    assert cal.record.name == "device_01" and cal.record.file == "device_01.csv" and cal.record.samples == 2865
    assert cal.record.columns is None and cal.record.source_units is None and cal.record.peaks == Peaks()
    assert cal.tests[0].record == cal.record and cal.tests[0].range == {"d": None, "v": None}
    assert cal.tested["F"] is None and "device_01" in cal.report()
    assert "rig_operator" not in cal.to_dict()["record"]
