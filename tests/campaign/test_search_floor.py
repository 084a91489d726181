"""A calibration's search is judged by the record's noise floor: runs that end
far above it look wider, and what still ends far above it says so
(calibration.runs: the wider search; calibration.checks.floor_warnings).

The trap: a law-2 device behind a stiff oil column (C 35, alpha 0.4, Ks 150
kN/mm) under the five-level acceptance protocol; a local search whose starts
both lie where the spring is rigid (Ks of tens of thousands) ends there, on
a plateau of law 2 alone, at 10-20x the floor.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import fvd_bridge as fb
from fvd_bridge.calibration import Calibration
from fvd_bridge.fit.floor import device_force_floor
from fvd_bridge.fit.objective import NEAR_FLOOR
from fvd_bridge.records.device import as_device
from fvd_bridge.rig import VirtualDamper, acceptance, paper

from lab import lab_record

KS = 150.0


def _oil(tmp_path, seed=11, **device):
    return lab_record(VirtualDamper(**{"C": 35.0, "alpha": 0.4, "Ks": KS, **device}), acceptance(), 1.5, 0.02,
                      seed=seed, tmp_path=tmp_path, name=f"oil{seed}")


def _calibrate(rec, spec, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fb.calibrate(rec, spec, intervals=0, **kw)


def _ks_found_or_said(cal) -> bool:
    """Within 5% of the true Ks, or the calibration says it is far above the floor."""
    ks = cal.named()["series_stiffness.Ks"]
    return abs(ks / KS - 1.0) < 0.05 or any("noise allows" in w for w in cal.warnings)


@pytest.mark.parametrize("seed", [1, pytest.param(0, marks=pytest.mark.slow), pytest.param(2, marks=pytest.mark.slow)])
def test_the_true_model_reaches_the_floor_from_these_seeds(tmp_path, seed):
    """On the record whose runs from seed 1 stopped in the rigid-spring basin
    (OF 0.151, 20x the floor), seed 1 (and, in the slow suite, its
    neighbours) ends on the true Ks, near the floor, and says where it
    stands against it."""
    cal = _calibrate(_oil(tmp_path), "2+series_stiffness", seed=seed)
    assert abs(cal.named()["series_stiffness.Ks"] / KS - 1.0) < 0.05
    assert cal.solver.floor is None or cal.of < NEAR_FLOOR * cal.solver.floor
    assert "FAR ABOVE" not in cal.report() and not any("noise allows" in w for w in cal.warnings)


def test_a_model_that_misses_the_record_says_so_everywhere(tmp_path):
    """Law 1 on the same record: the search looks wider once (one more fit,
    no better) and the OF's distance to the floor is in the warnings, beside
    the OF in report(), and in the file, which loads it back."""
    cal = _calibrate(_oil(tmp_path), "1", seed=0)
    assert cal.settings["runs_made"] == 1 and cal.settings["wider_runs"] == 1  # the run asked for, then one round
    ratio = cal.of / cal.solver.floor
    assert ratio > NEAR_FLOOR
    said = [w for w in cal.warnings if "what the record's noise allows" in w]
    assert len(said) == 1 and f"{ratio:.0f}x" in said[0] and "after a wider search" in said[0]
    assert "FAR ABOVE IT" in cal.report().split("[[Variables]]")[0]
    path = tmp_path / "law1.yaml"
    cal.save(str(path))
    back = Calibration.load(str(path))
    assert back.solver.floor == pytest.approx(cal.solver.floor)
    assert "FAR ABOVE IT" in back.report()


def test_a_record_near_its_floor_makes_no_wider_search(tmp_path):
    """The usual case costs what it did: the true model of a plain orifice
    ends within 3x of the force noise's floor alone (a lower bound of the
    floor), so neither the floor's propagation nor a wider round is made."""
    rec = lab_record(VirtualDamper(C=45.0, alpha=0.3), paper(cycles=3), 1.0, 0.005, seed=3, tmp_path=tmp_path, name="plain")
    cal = _calibrate(rec, "2", seed=0)
    assert cal.settings["runs_made"] == 1 and "wider_runs" not in cal.settings
    assert cal.of < NEAR_FLOOR * device_force_floor(as_device(rec))
    assert cal.solver.floor is None


def test_a_force_the_model_explains_little_of_is_flagged(tmp_path):
    """A force that is not the displacement's damper force (here: a sine at
    another frequency) gives an OF beyond 0.5: flagged beside the OF and in
    the warnings, whatever the floor."""
    rec = lab_record(VirtualDamper(C=45.0, alpha=0.3), paper(cycles=3), 1.0, 0.005, seed=4, tmp_path=tmp_path, name="a")
    other = fb.Record.from_arrays(rec.t, rec.d, 40.0 * np.sin(2 * np.pi * 3.1 * rec.t) + rec.F * 0.05,
                                  units=("kN", "mm", "s"), name="b")
    cal = _calibrate(other, "2", seed=0)
    assert cal.of > 0.5
    assert any("explains little" in w for w in cal.warnings)
    assert "EXPLAINS LITTLE" in cal.report()


@pytest.mark.slow
@pytest.mark.parametrize("noise_seed", [21, 22])
def test_twenty_seeds_land_on_ks_or_say_they_are_far(tmp_path, noise_seed):
    """The issue's acceptance on records made apart from the one the wider
    rounds were tuned on (other noise draws): twenty API seeds, and the
    command line's default (20 runs asked) on each, land within 5% of the
    true Ks or say they are far above the floor."""
    rec = _oil(tmp_path, seed=noise_seed)
    for seed in range(20):
        assert _ks_found_or_said(_calibrate(rec, "2+series_stiffness", seed=seed)), seed
    assert _ks_found_or_said(_calibrate(rec, "2+series_stiffness", seed=0, runs=20))
