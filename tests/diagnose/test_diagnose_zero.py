"""The tests' force zero (diagnose/zero.py): a load cell's offset and drift
are a nuisance of each test, fitted beside the base and never exported; an
effect that can act as an offset (a preload, an asymmetry) is credited only
beyond it.

Two lab-like tests of the rig's law-2 orifice (C 40, alpha 0.3; 20 mm at
250 mm/s and 30 mm at 450 mm/s, 3 cycles each; force noise 0.8 kN,
displacement noise 0.01 mm; velocity derived by the tool), as one device.
"""

from __future__ import annotations

import numpy as np
import pytest

from fvd_bridge.catalog import catalog
from fvd_bridge.diagnose import diagnose, diagnose_settings
from fvd_bridge.diagnose.zero import solve, zero_force
from fvd_bridge.records import device as devices
from fvd_bridge.records.velocity import rest_mask
from fvd_bridge.rig import VirtualDamper, paper, trace
from fvd_bridge.text.diagnosis import format_diagnosis
from lab import lab_from_forces

SETTINGS = diagnose_settings(8, 60)
#: the common offset of both tests, as a share of the peak force (a load-cell zero of one test day)
OFFSET = 0.08


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    return tmp_path_factory.mktemp("zero")


def two_tests(folder, tag, offset=0.0, rest=0.1, **params) -> tuple[devices.Device, float]:
    """(the device of two lab-like tests, the offset added to both [kN]): the
    rig's law-2 orifice with ``params``, ``rest`` [s] still at start and end,
    ``offset`` x the peak force added to the force before the CSV is written."""
    traces = [trace(VirtualDamper(C=40.0, alpha=0.3, **params),
                    paper(amplitude=amp, velocity=vel, cycles=3, dt=0.004, rest=rest))
              for amp, vel in ((20.0, 250.0), (30.0, 450.0))]
    F0 = offset * max(np.abs(tr["F"]).max() for tr in traces)
    tests = [lab_from_forces(tr["t"], tr["d"], tr["F"] + F0, 0.8, 0.01, 40 + k, folder, name=f"{tag}_{k}")
             for k, tr in enumerate(traces)]
    return devices.Device(tag, tests), F0


def test_the_zero_term_and_the_effects_it_judges():
    """F0 + F1 (t - t_mid) on the test's clock; the built-in effects that can act as an offset."""
    t = np.linspace(2.0, 6.0, 9)
    assert zero_force(3.0, 0.5, t) == pytest.approx(3.0 + 0.5 * (t - 4.0))
    # which built-in effects can act as an offset (module docstring of diagnose/zero.py)
    assert {e.name for e in catalog().effects.values() if e.offset_like} == {"parallel_stiffness", "asymmetry"}


def test_a_negative_parallel_stiffness_is_implausible():
    """A negative Kp is no damper's property (PHYSICS.md: a gas spring pushes
    back; a force falling with d is inertia); one the fit leaves at about zero
    is not flagged.  The friction damper's figures: 16 kN, 25.4 mm."""
    from fvd_bridge.effects.sizes import parallel_spring

    scales = {"F": 16.0, "d": 25.4}
    negative = parallel_spring({"Kp": -0.026, "F0": -2.1}, scales)
    assert not negative.plausible and "negative parallel stiffness" in negative.why
    assert parallel_spring({"Kp": -1e-4, "F0": 1.0}, scales).plausible
    assert parallel_spring({"Kp": 0.1, "F0": 1.0}, scales).plausible


@pytest.mark.parametrize("rest", [0.3, 0.0], ids=["rests", "no_rests"])
def test_a_common_force_offset_is_the_tests_zero_not_a_preload(folder, rest):
    """Both tests carry the same offset (8% of the peak force: one zeroing of
    the load cell), with and without 0.3 s rests at start and end: leaving one
    test out cannot see it, and without the zero a preload passes every other
    check; with it, neither a preload nor an asymmetry is credited, and the
    report shows each test's zero (its rests reading it too)."""
    device, F0 = two_tests(folder, f"offset_{rest:g}", OFFSET, rest)
    assert all(rest_mask(t).any() == (rest > 0) for t in device.tests)
    diag = diagnose(device, "2", seed=0, settings=SETTINGS)
    text = format_diagnosis(diag)
    assert diag.suggestions == [], text
    spring = diag.candidate("parallel_stiffness")
    assert spring.reason.startswith("explained by the tests' force zero"), text
    assert diag.zero is not None and "the tests' force zero (not exported" in text
    for name, (offset, drift) in diag.zero.values.items():
        assert offset == pytest.approx(F0, rel=0.05), text
        assert abs(drift) * 1.5 < 0.02 * F0, text  # no drift was planted: under 2% of the offset over the test
        reading = diag.zero.at_rest[name]
        assert (reading is None) == (rest == 0) and (reading is None or reading == pytest.approx(F0, rel=0.05))
    assert diag.zero.of <= diag.floor + diag.judge.margin, text  # the zero explains the misfit
    assert "once the tests' force zero is fitted" in diag.verdict()
    report = diag.as_dict()["force_zero"]
    assert report["exported"] is False and set(report["tests"]) == set(device.test_names)
    assert all("F0" not in n or n.startswith("parallel_stiffness.") for c in diag.candidates for n in c.fit.names)


def test_the_rests_pin_the_zero(folder):
    """A test with rests at both ends: its zero is what the rests read beyond
    the model's force at rest (they stay in eq. 18), and the model with it
    fits the rests to the force noise."""
    device, F0 = two_tests(folder, "pinned", OFFSET, 0.3)
    test = device.tests[0]
    model = catalog().model("2")
    from fvd_bridge.fit import fit_model

    base = fit_model(model, test, seed=0)
    fit = solve(model, base.values, test)
    assert fit.of < 0.2 * base.of
    (offset, drift), = fit.values.values()
    assert fit.model_at_rest == {test.name: 0.0}  # law 2 at v = 0
    still, residual = rest_mask(test), fit.residual
    assert offset == pytest.approx(F0, rel=0.02) and abs(drift) < 0.02 * F0
    assert abs(np.median(residual[still])) < 0.3 and np.std(residual[still]) < 1.2  # force noise 0.8 kN


@pytest.mark.parametrize("params", [dict(Kp=1.5, preload=8.0), dict(Kp=1.5)], ids=["spring_preload", "spring"])
def test_a_real_parallel_spring_is_still_credited(folder, params):
    """An accumulator (1.5 kN/mm, with or without an 8 kN preload) and no
    offset: the spring grows with d, which no zero follows: credited beyond
    the tests' zero, near its size."""
    device, _ = two_tests(folder, f"spring_{len(params)}", **params)
    diag = diagnose(device, "2", seed=0, settings=SETTINGS)
    text = format_diagnosis(diag)
    best = diag.best
    assert best is not None and best.effect == "parallel_stiffness", text
    assert "beyond the tests' force zero too" in best.reason, text
    assert best.fit.values[best.model.names.index("parallel_stiffness.Kp")] == pytest.approx(1.5, rel=0.1)
    assert diag.zero is not None and next(b for b in diag.zero.effects if b.effect == best.effect).significant


def test_an_asymmetry_the_rests_do_not_read_is_credited(folder):
    """A real asymmetry (12%) with 0.3 s rests at both ends: it shifts the
    force in motion, the rests read zero: credited beyond the tests' zero."""
    device, _ = two_tests(folder, "asym", rest=0.3, asymmetry=0.12)
    diag = diagnose(device, "2", seed=0, settings=SETTINGS)
    text = format_diagnosis(diag)
    best = diag.best
    assert best is not None and best.effect == "asymmetry", text
    assert "beyond the tests' force zero too" in best.reason, text
    assert all(abs(F0) < 1.0 for F0, _ in diag.zero.values.values()), text


def test_an_effect_free_device_gets_nothing(folder):
    """No effect, no offset: nothing credited, and the zero does not make one up."""
    device, _ = two_tests(folder, "plain")
    diag = diagnose(device, "2", seed=0, settings=SETTINGS)
    text = format_diagnosis(diag)
    assert diag.suggestions == [], text
    assert diag.zero is None or all(abs(F0) < 1.0 for F0, _ in diag.zero.values.values()), text


@pytest.mark.slow
def test_shared_friction_damper_credits_no_preload(shared_dir, tmp_path):
    """The shared friction damper's two tests (one day's load-cell zero),
    read as the CLI reads them: diagnose --device brfd --law 9 recommends no
    parallel_stiffness, and whatever offset-like effect it judges it judges
    beyond the tests' force zero."""
    import json

    from fvd_bridge import cli

    files = [shared_dir / "devices" / f for f in ("arts_brfd_0.5Hz_25lb.csv", "arts_brfd_1Hz_35lb.csv")]
    if not all(f.is_file() for f in files):
        pytest.skip("../shared/devices lacks the friction-damper records")
    assert cli.main(["diagnose", *map(str, files), "--device", "brfd", "--law", "9", "--out", str(tmp_path),
                     "--quiet", "--no-figures"]) == 0
    report = json.loads((tmp_path / "brfd_diagnose.json").read_text())
    assert "parallel_stiffness" not in [c["effect"] for c in report["candidates"]], report["verdict"]
    zero = report["force_zero"]
    if zero is not None:
        assert zero["exported"] is False and set(zero["tests"]) == {"arts_brfd_0.5Hz_25lb", "arts_brfd_1Hz_35lb"}
        judged = {b["effect"] for b in zero["effects"]}
        for c in report["all_candidates"]:
            if c["effect"] in ("parallel_stiffness", "asymmetry") and c["significant"]:
                assert c["effect"] in judged and "beyond the tests' force zero too" in c["reason"]


def test_the_zero_fit_searches_a_gaps_clearance_along_its_line(folder):
    """A gap's clearance moves the OF in steps (``Effect.stepped``): the
    zero's least squares alone stop on the first step.  Started 0.3 mm
    from a 2 mm gap, with the tests' offset planted, the zero fit reaches
    the clearance within 0.02 mm and the offset within 5%."""
    device, F0 = two_tests(folder, "gapped", OFFSET, 0.3, gap=2.0)
    model = catalog().model("2+gap")
    start = np.array([40.0, 0.3, 2.3])
    assert model.names == ["C", "alpha", "gap.g"]
    fit = solve(model, start, device)
    assert fit.params[2] == pytest.approx(2.0, abs=0.02)
    assert all(offset == pytest.approx(F0, rel=0.05) for offset, _ in fit.values.values())


def test_a_parameter_fitted_on_a_test_alone_searches_a_gaps_clearance(folder):
    """The held-out check fits per-test parameters on the test left out
    (``heldout.fit_own``); a gap's clearance among them is searched along
    its line too: from 2.3 mm it reaches the 2 mm gap within 0.02 mm."""
    from fvd_bridge.diagnose.heldout import fit_own

    device, _ = two_tests(folder, "gapped_alone", gap=2.0)
    model = catalog().model("2+gap")
    own = fit_own(model, device.tests[1], [40.0, 0.3, 2.3], ["gap.g"], device.scales())
    assert own[2] == pytest.approx(2.0, abs=0.02)
