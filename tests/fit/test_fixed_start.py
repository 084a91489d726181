"""Fixing a parameter and giving start values (lmfit's vary=False and value=)."""

from __future__ import annotations

import numpy as np
import pytest

import fvd_bridge as fb
from fvd_bridge.golden import REFERENCE
from lab import lab_from_forces
from fvd_bridge.catalog import catalog
from fvd_bridge.rig import paper
from fvd_bridge.records import Record


@pytest.fixture(scope="module")
def law9_record(tmp_path_factory):
    """A lab-like record of law 9 at its reference parameters (1 kN, 0.005 mm noise)."""
    model = catalog().model("9")
    rig = paper(cycles=3, dt=0.004)
    t = rig.times()
    d, v, a = rig.motion(t)
    F = model.force(Record(t, d, np.zeros_like(t), v, a), np.asarray(REFERENCE[9], dtype=float)[None, :])[0]
    return lab_from_forces(t, d, F, 1.0, 0.005, seed=3, tmp_path=tmp_path_factory.mktemp("fix"), name="law9")


def test_a_fixed_parameter_stays_and_the_others_are_fitted(law9_record):
    """beta held at 1.1x its truth: it ends exactly there with a zero-width
    interval and no bound warning; C and alpha move to make up for it, so
    the OF is above the free fit's; at the free fit's own beta the OF is
    the free fit's to within the local search's L1 tolerance."""
    from fvd_bridge.fit.local import L1_TOLERANCE

    truth = dict(zip(catalog().model("9").names, REFERENCE[9]))
    free = fb.calibrate(law9_record, "9", intervals=0)
    off = fb.calibrate(law9_record, "9", fixed={"beta": 1.1 * truth["beta"]}, intervals=8)
    assert off.params["beta"].value == 1.1 * truth["beta"]
    assert off.intervals.parameters["beta"].ci95 == (1.1 * truth["beta"],) * 2
    assert not any("beta" in line for line in off.intervals.not_identified)
    assert "beta = " in "\n".join(off.interval_lines()) and "(fixed by the caller)" in "\n".join(off.interval_lines())
    assert off.of > free.of * 1.01
    at_free = fb.calibrate(law9_record, "9", fixed={"beta": free.params["beta"].value}, intervals=0)
    assert at_free.of == pytest.approx(free.of, rel=2 * L1_TOLERANCE)
    lo, hi = off.intervals.parameters["C"].ci95
    assert lo < off.params["C"].value < hi


def test_start_values_and_names_that_do_not_exist(law9_record, tmp_path):
    """A start far from the data's (C 3x, alpha 0.5x the free fit's) ends
    on the free fit's optimum; a name the model lacks is a ValueError in
    Python's words."""
    from fvd_bridge.fit.local import L1_TOLERANCE

    free = fb.calibrate(law9_record, "9", intervals=0)
    far = fb.calibrate(law9_record, "9", intervals=0,
                       start={"C": 3.0 * free.params["C"].value, "alpha": 0.5 * free.params["alpha"].value})
    assert far.of == pytest.approx(free.of, rel=2 * L1_TOLERANCE)
    # each parameter says where the caller started it (None: the data's start), also once saved and read
    assert far.params["C"].start == 3.0 * free.params["C"].value and far.params["beta"].start is None
    assert free.params["C"].start is None
    back = fb.Calibration.load(far.save(str(tmp_path / "far.yaml")))
    assert back.params["alpha"].start == 0.5 * free.params["alpha"].value
    with pytest.raises(ValueError, match=r"^start=\{'K': 1\.0\}: model 9 has no parameter 'K'"):
        fb.calibrate(law9_record, "9", intervals=0, start={"K": 1.0})
    with pytest.raises(ValueError, match=r"^fixed=\{'K': 1\.0\}: model 9 has no parameter 'K'"):
        fb.calibrate(law9_record, "9", intervals=0, fixed={"K": 1.0})


def test_every_parameter_fixed_is_refused_in_one_line(law9_record, tmp_path):
    """Nothing left to fit: one line naming the fixed parameters and compare as the way, from
    Python and from the command line (exit 2, nothing written), before any fit runs."""
    with pytest.raises(fb.InputError, match=r"every parameter of model 1 is fixed \(C\): nothing to fit"):
        fb.calibrate(law9_record, "1", fixed={"C": 0.5}, intervals=0)
    path = tmp_path / "r.csv"
    np.savetxt(path, np.column_stack([law9_record.t, law9_record.d, law9_record.F]), delimiter=",",
               header="t,d,F", comments="")
    from fvd_bridge import cli

    assert cli.main(["calibrate", str(path), "--laws", "1", "--fix", "1:C=0.5", "--out", str(tmp_path / "o"),
                     "--quiet"]) == 2
    assert not (tmp_path / "o").exists()
