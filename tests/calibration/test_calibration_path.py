"""One calibration is its own typed path: ``fb.calibrate`` builds a
FitRequest, runs ``calibration.runs`` and builds the Calibration, and no
code of ``campaign/`` runs on the way (followed with a profiler hook, so
an import or a call that wanders into the campaign fails here).  The
campaign's loop over the same path gives the same calibration."""

from __future__ import annotations

import sys
import warnings

import numpy as np
import pytest

import fvd_bridge as fb
from fvd_bridge.calibration.engine import calibrate
from fvd_bridge.calibration.request import FitRequest
from fvd_bridge.calibration.runs import FittedRuns, fit_runs
from fvd_bridge.campaign.executors import Serial
from fvd_bridge.campaign.outputs import calibration, summarize
from fvd_bridge.campaign.runner import CampaignSettings, run_campaign
from fvd_bridge.rig import Noise, VirtualDamper, paper, simulate


@pytest.fixture(scope="module")
def rec():
    return simulate(VirtualDamper(C=45.0, alpha=0.3, name="sn045"), paper(cycles=2), Noise(1.0, 0.005), seed=0)


def test_a_calibration_never_enters_the_campaign(rec):
    entered = set()

    def follow(frame, event, arg):
        if event == "call" and "/fvd_bridge/campaign/" in frame.f_code.co_filename.replace("\\", "/"):
            entered.add(f"{frame.f_code.co_filename}:{frame.f_code.co_name}")

    sys.setprofile(follow)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            cal = fb.calibrate(rec, "2", runs=3, intervals=4, bounds={"alpha": (0.05, 1.0)}, start={"C": 40.0})
    finally:
        sys.setprofile(None)
    assert entered == set()
    assert cal.intervals is not None and cal.settings["runs_made"] >= 2  # runs and intervals were made on the way


def test_the_follower_sees_the_campaign_when_it_runs(rec):
    """The check itself: a campaign's run is seen entering campaign/."""
    entered = []

    def follow(frame, event, arg):
        if event == "call" and "/fvd_bridge/campaign/" in frame.f_code.co_filename.replace("\\", "/"):
            entered.append(frame.f_code.co_name)

    sys.setprofile(follow)
    try:
        run_campaign([rec], CampaignSettings(specs=("1",), runs=1), progress=False, executor=Serial())
    finally:
        sys.setprofile(None)
    assert "run_campaign" in entered


def test_the_campaign_builds_the_calibration_the_path_builds(rec):
    """A campaign of one model on one record and the path's own calibrate
    agree to the bit: the same runs (FittedRuns), the same best values, OF and run statistics."""
    request = FitRequest(spec="2", runs=3).check()
    direct = calibrate(rec, request)
    cs = CampaignSettings(specs=("2",), runs=3, jobs=1)
    results = run_campaign([rec], cs, progress=False, executor=Serial())
    fitted = results[(rec.name, "2")]
    assert isinstance(fitted, FittedRuns) and len(fitted.asked) == direct.settings["runs_made"]
    via = calibration(rec, "2", results, summarize([rec], results, cs)["models"]["2"], cs)
    assert np.array_equal(via.values, direct.values) and via.of == direct.of
    assert np.array_equal(via.runs.p_mean, direct.runs.p_mean) and via.runs.of_sigma == direct.runs.of_sigma
    assert via.solver.floor == direct.solver.floor


def test_fitted_runs_keep_the_runs_asked_apart_from_the_wider_rounds(rec):
    """On a record law 2 cannot describe (a stiff oil column behind it), the
    first runs end far above the noise floor and the wider search adds its
    rounds after the runs asked; the run statistics are the asked runs'."""
    column = simulate(VirtualDamper(C=45.0, alpha=0.3, Ks=150.0, name="sn150"), paper(cycles=2),
                      Noise(1.0, 0.005), seed=0)
    fitted = fit_runs([column], [FitRequest(spec="2", runs=2).check()])[(column.name, "2")]
    assert fitted.wider_runs >= 1 and len(fitted.asked) == 2 and len(fitted) == 2 + fitted.wider_runs
    assert fitted.best.of <= min(r.of for r in fitted.asked)
    assert fitted.stats()["of_mean"] == pytest.approx(np.mean([r.of for r in fitted.asked]))


@pytest.mark.parametrize("given, words", [
    (dict(search_bounds={"K": (0.0, 1.0)}), "bounds={'K': (0, 1)}: model 2 has no parameter 'K'"),
    (dict(fixed={"K": 1.0}), "fixed={'K': 1.0}: model 2 has no parameter 'K'"),
    (dict(start_values={"K": 1.0}), "start={'K': 1.0}: model 2 has no parameter 'K'"),
    (dict(per_test=("K",)), "per_test=['K']: model 2 has no parameter 'K'"),
    (dict(search_bounds={"C": (2.0, 1.0)}), "bounds={'C': (2, 1)}: the lower bound must be below the upper"),
    (dict(fixed={"C": 1.0, "alpha": 0.5}), "every parameter of model 2 is fixed"),
    (dict(runs=0), "runs=0: must be at least 1"),
    (dict(pop=0), "pop=0: must be at least 1"),
    (dict(intervals=1), "intervals=1: 0 (none) or at least 2 replicates"),
])
def test_a_request_is_checked_once_by_parameter_name(given, words):
    with pytest.raises(fb.InputError) as exc:
        FitRequest(spec="2", **given).check()
    assert words in str(exc.value) and "\n" not in str(exc.value)


def test_a_one_model_campaign_keeps_the_settings_its_request_gives():
    """The settings dict is built in one place (``request.settings_dict``):
    a campaign of one model with options naming no model writes what its
    FitRequest gives (the same keys in the same order, the same values);
    options naming a model keep it in the campaign's."""
    import json

    from fvd_bridge.calibration.request import Extends

    given = dict(runs=3, seed=4, intervals=5, all_runs=True, force_zero="per-test",
                 bound_overrides=((None, "C", 10.0, 80.0), (None, "alpha", 0.3, 0.3)), per_test=((None, "C"),),
                 start_values=((None, "C", 44.0),), start=Extends("2", ("C", "alpha"), (45.0, 0.3)))
    cs = CampaignSettings(specs=("2",), **given)
    one = cs.request("2").as_settings()
    assert json.dumps(cs.as_dict()) == json.dumps(one)
    assert list(one) == ["specs", "runs", "bounds", "optimizer", "seed", "optimizer_settings", "plugins",
                         "bound_overrides", "per_test", "intervals", "all_runs", "start_values", "force_zero", "start"]
    assert one["bound_overrides"] == [[None, "C", 10.0, 80.0], [None, "alpha", 0.3, 0.3]]
    assert one["start"] == {"model": "2", "values": {"C": 45.0, "alpha": 0.3}}
    assert "force_zero" not in FitRequest(spec="2").as_settings()  # written only when per-test, as before
    named = CampaignSettings(specs=("2", "9"), bound_overrides=(("9", "beta", 40.0, 40.0),)).as_dict()
    assert named["bound_overrides"] == [["9", "beta", 40.0, 40.0]] and named["specs"] == ["2", "9"]


def test_a_unit_that_contradicts_the_sidecar_is_in_the_calibrations_warnings(rec, tmp_path):
    """A file in kN whose sidecar wrongly says kip, read with units F=kN: the
    reading follows the caller (C comes out near the rig's 45, not 45/4.448),
    and the contradiction, warned of on reading, is one of the calibration's
    warnings, in the file it saves too (where the result is read)."""
    from fvd_bridge.records import read_record
    from fvd_bridge.records.options import ReadOptions
    from fvd_bridge.records.writers import write_csv

    path = tmp_path / "sn045.csv"
    write_csv(rec, str(path))
    (tmp_path / "sn045.yaml").write_text("units: {F: kip}\n")
    with pytest.warns(fb.RecordWarning, match="read in kN"):
        read = read_record(str(path), ReadOptions(units={"F": "kN"}))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = fb.calibrate(read, "2", runs=1, intervals=0)
    assert cal.named()["C"] == pytest.approx(45.0, rel=0.05)
    noted = [w for w in cal.warnings if "where its sidecar sn045.yaml says kip, a factor 4.448 apart" in w]
    assert len(noted) == 1
    assert noted[0] in fb.Calibration.load(cal.save(str(tmp_path / "cal.yaml"))).warnings
