"""The typed parts between the stages: a fit is frozen, a calibration's
tests and run statistics are frozen records, and the calibration file keeps
its shape (files written before the parts were typed load and save unchanged)."""

from dataclasses import FrozenInstanceError, replace
from pathlib import Path

import numpy as np
import pytest

from fvd_bridge.campaign.store import result_from_dict, result_to_dict
from fvd_bridge.catalog import catalog
from fvd_bridge.fit import fit_model
from fvd_bridge.rig import Device, Noise, paper, simulate

V3 = Path(__file__).resolve().parent / "fixtures" / "calibration_v3"


@pytest.fixture(scope="module")
def law2_fit():
    rec = simulate(Device(C=45.4, alpha=0.3), paper(cycles=2), Noise(force=0.5), seed=3)
    return fit_model(catalog().model("2"), rec, seed=0)


def test_a_fit_is_frozen_and_replace_gives_a_changed_copy(law2_fit):
    with pytest.raises(FrozenInstanceError):
        law2_fit.of = 0.0
    lower = replace(law2_fit, of=law2_fit.of / 2)
    assert lower.of == law2_fit.of / 2 and lower.params is law2_fit.params and law2_fit.of > lower.of
    # what fit_model adds after the search is in the fit it returns
    assert law2_fit.evaluations > 0 and law2_fit.wall_s > 0 and len(law2_fit.test_of) == 1
    assert law2_fit.test_of[0] == pytest.approx(law2_fit.of, rel=1e-12)


def test_a_stored_unit_reads_back_as_the_same_fit(law2_fit):
    back = result_from_dict(result_to_dict(law2_fit))
    assert back.as_dict() == law2_fit.as_dict() and back.names == law2_fit.names
    assert np.array_equal(back.params, law2_fit.params) and np.array_equal(back.bounds, law2_fit.bounds)
