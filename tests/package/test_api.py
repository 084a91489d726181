"""The notebook API (``import fvd_bridge as fb``) against independent truth:
a lab-like record of a known law given as arrays in N, m, s."""

from __future__ import annotations

import warnings

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import fvd_bridge as fb  # noqa: E402
from fvd_bridge.rig import VirtualDamper as VirtualDamper  # noqa: E402
from fvd_bridge.rig import Noise, paper, simulate  # noqa: E402

#: the device: law 2 (C 45, alpha 0.3) behind a 150 kN/mm oil column
TRUE_C, TRUE_ALPHA, TRUE_KS = 45.0, 0.3, 150.0


@pytest.fixture(scope="module")
def arrays():
    """t [s], d [m], F [N] of a lab-like test (noise on force and displacement)."""
    sim = simulate(VirtualDamper(C=TRUE_C, alpha=TRUE_ALPHA, Ks=TRUE_KS), paper(cycles=3), Noise(1.0, 0.005), seed=0)
    return sim.t, sim.d / 1000.0, sim.F * 1000.0


@pytest.fixture(scope="module")
def rec(arrays):
    return fb.Record.from_arrays(*arrays, units=("N", "m", "s"), name="sn150")


def test_from_arrays_converts_and_derives_the_velocity(arrays, rec):
    t, d, F = arrays
    assert rec.d == pytest.approx(d * 1000.0) and rec.F == pytest.approx(F / 1000.0)
    v_true = np.gradient(d * 1000.0, t)  # a second differentiator, on the same noisy d
    assert np.median(np.abs(rec.v - v_true)) < 0.02 * np.abs(v_true).max()
    assert rec.d_noise == pytest.approx(0.005, rel=0.3)  # the displacement noise put in
    assert rec.provenance["format"] == "arrays" and rec.provenance["units"]["F"] == "N"


def test_from_arrays_refuses_bad_input_in_one_line(arrays):
    t, d, F = arrays
    with pytest.raises(fb.InputError, match="t, d, F need one length"):
        fb.Record.from_arrays(t, d[:-1], F)
    bad = F.copy()
    bad[7] = np.nan
    with pytest.raises(fb.InputError, match="row 8"):
        fb.Record.from_arrays(t, d, bad, units="N,m,s")
    with pytest.raises(fb.InputError, match="furlong"):
        fb.Record.from_arrays(t, d, F, units=("N", "furlong", "s"))


def test_calibrate_with_bounds_gives_parameters_with_intervals(rec):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        cal = fb.calibrate(rec, "2", runs=2, bounds={"alpha": (0.05, 0.28)}, intervals=20)
    messages = [str(w.message) for w in caught if issubclass(w.category, fb.FitWarning)]
    assert any("bounds={'alpha': (0.05," in m for m in messages) and not any("--bound" in m for m in messages)
    alpha = cal.params["alpha"]
    assert alpha.value == pytest.approx(0.28, abs=1e-6) and alpha.bounds == (0.05, 0.28)
    C = cal.params["C"]
    assert C.unit == "kN/(mm/s)^alpha" and C.stderr > 0 and C.ci95[0] <= C.value <= C.ci95[1]
    assert cal.correlation["C"]["alpha"] < -0.9  # C and alpha trade off along the valley
    text = cal.report()
    for section in ("[[Model]]", "[[Fit Statistics]]", "[[Variables]]", "[[Correlations]]", "[[Warnings]]"):
        assert section in text
    assert "<table" in cal._repr_html_() and len(repr(cal)) < 100
    _, ax = plt.subplots()
    assert cal.plot(ax=ax) is ax and len(ax.lines) == 2
    plt.close("all")


def test_a_bound_on_a_missing_parameter_names_the_argument(rec):
    with pytest.raises(fb.InputError, match=r"bounds=\{'K': [^}]*\}: model 2 has no parameter 'K'"):
        fb.calibrate(rec, "2", bounds={"K": (0.0, 1.0)}, intervals=0)


def test_diagnose_accept_hands_over_the_better_model(rec):
    base = fb.calibrate(rec, "2", intervals=0)
    diag = fb.diagnose(rec, "2")
    assert diag.best.effect == "series_stiffness"
    better = diag.accept()
    assert isinstance(better, fb.Calibration) and better.spec == "2+series_stiffness"
    assert better.of < 0.2 * base.of
    assert better.params["series_stiffness.Ks"].value == pytest.approx(TRUE_KS, rel=0.1)
    assert "<table" in diag._repr_html_()
    # printed, a candidate is one line that says what it is, not its fields
    assert repr(diag.best).startswith("<Candidate 2+series_stiffness: OF ") and len(repr(diag.best)) < 120
    with pytest.raises(fb.InputError, match="not a candidate"):
        diag.accept("no_such_effect")


def test_to_opensees_in_metres_applies_and_writes_the_cli_script(rec, tmp_path):
    cal = fb.calibrate(rec, "2", intervals=0)
    cmds = cal.to_opensees(tag=3, units=("kN", "m", "s"))
    kind, name, tag, C, alpha = cmds[0]
    assert (kind, name, tag) == ("uniaxialMaterial", "Viscous", 3)
    assert C == pytest.approx(cal.params["C"].value * 1000.0 ** alpha)  # kN/(mm/s)^a -> kN/(m/s)^a
    import openseespy.opensees as ops

    ops.wipe()
    ops.model("basic", "-ndm", 1, "-ndf", 1)
    assert cmds.apply(ops) == 3
    ops.wipe()
    path = tmp_path / "c.yaml"
    cal.save(str(path))
    again = fb.Calibration.load(str(path))
    assert again.to_opensees(3, units="kN,m,s").to_script("tcl") == cmds.to_script("tcl")
    assert again.params["C"].value == pytest.approx(cal.params["C"].value)


def test_dir_shows_the_public_api():
    names = dir(fb)
    assert {"calibrate", "diagnose", "Record", "Calibration", "Diagnosis", "read_record"} <= set(names)
    assert not [n for n in names if n.startswith("_") and n != "__version__"]
    assert callable(fb.diagnose)


def test_errors_are_value_errors_in_the_callers_words(tmp_path):
    """From Python a bad argument raises a ValueError naming the Python
    argument; the command line names its option for the same mistake."""
    import subprocess

    from conftest import CLI, cli_env

    t = np.arange(0.0, 2.0, 0.01)
    rec = fb.Record.from_arrays(t, 10.0 * np.sin(6.0 * t), 5.0 * np.cos(6.0 * t))
    with pytest.raises(ValueError, match=r"^plugins=\['nope\.py'\]: no such file"):
        fb.calibrate(rec, "2", intervals=0, plugins=["nope.py"])
    with pytest.raises(ValueError, match=r"^bounds='papr': expected one of auto, paper"):
        fb.calibrate(rec, "2", intervals=0, bounds="papr")
    cal = fb.calibrate(rec, "2", intervals=0)
    with pytest.raises(ValueError, match=r"^test='x': the calibration of \S+ has tests"):
        cal.params_for("x")
    path = tmp_path / "r.csv"
    np.savetxt(path, np.column_stack([t, 10.0 * np.sin(6.0 * t), 5.0 * np.cos(6.0 * t)]), delimiter=",",
               header="t,d,F", comments="")
    out = subprocess.run([*CLI, "calibrate", str(path), "--laws", "2", "--plugin", "nope.py", "--out",
                          str(tmp_path / "o")], capture_output=True, text=True, env=cli_env())
    assert out.returncode == 2 and out.stderr.strip().endswith("--plugin nope.py: no such file"), out.stderr
