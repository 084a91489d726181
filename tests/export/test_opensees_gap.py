"""A pin gap reaches OpenSees: ViscousDamper's LGap behind laws 1, 2 and 7
(beta 1), a stiff contact spring where no series spring is fitted.

Checked against the model's own gap (effects/connection.py) on sines,
where the bound of ``Export.bound`` must hold and the gap's effect must be
kept, and end to end on a lab-like record of a damper with a 2 mm pin gap:
``diagnose --target opensees`` recommends a gap model, ``export opensees
--check`` accepts it, and the exported material, driven in a zeroLength
element by an OpenSees script written here, keeps at least three quarters
of the gap's gain over the base law on the measured force."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from fvd_bridge.catalog import parse_model
from fvd_bridge.errors import InputError
from fvd_bridge.export.opensees import CONTACT_DEFLECTION, opensees_export
from fvd_bridge.export.opensees_check import check, quiet_opensees
from fvd_bridge.fit.objective import objective


def sine(amp: float, freq: float, dt: float = 0.002, cycles: float = 3.0):
    """d = amp sin(2 pi f t) [mm] at times t [s]: exact, as the check compares two models on one motion."""
    t = np.arange(int(round(cycles / freq / dt)) + 1) * dt
    return t, amp * np.sin(2.0 * math.pi * freq * t)


CASES = [  # spec, parameters (kN, mm, s)
    ("2+gap+series_stiffness", {"C": 45.4, "alpha": 0.3, "gap.g": 2.0, "series_stiffness.Ks": 150.0}),
    ("2+gap", {"C": 45.4, "alpha": 0.3, "gap.g": 2.0}),
    ("1+gap", {"C": 2.0, "gap.g": 1.0}),
    ("7+gap", {"K": 30.0, "C": 45.4, "alpha": 0.3, "beta": 1.0, "gap.g": 2.0}),
]


@pytest.mark.parametrize("spec,params", CASES, ids=[c[0] for c in CASES])
@pytest.mark.parametrize("amp,freq", [(40.0, 0.5), (10.0, 1.0)])
def test_lgap_follows_the_model_gap_within_its_bound(spec, params, amp, freq):
    """OpenSees' force against the model with the gap: within the export's
    bound, and far closer than the same law without its gap (what the gap
    adds is kept: the error left is below a fifth of the gap's effect)."""
    quiet_opensees()
    t, d = sine(amp, freq)
    model = parse_model(spec)
    res = check(model, params, t, d, substeps=8)
    assert res.of <= res.bound, (res.of, res.bound)
    no_gap = {k: v for k, v in params.items() if k != "gap.g"}
    base = parse_model(spec.replace("+gap", ""))
    F_base = check(base, no_gap, t, d, substeps=8).F_model
    assert res.of < 0.2 * objective(res.F_model, F_base, t)


TWO = [  # laws without a series form: the connection and the law as two materials through an internal node
    ("9+gap", {"C": 0.2, "alpha": 0.15, "beta": 27.0, "gap.g": 2.0}),
    ("9+gap+series_stiffness", {"C": 0.2, "alpha": 0.15, "beta": 27.0, "gap.g": 2.0, "series_stiffness.Ks": 150.0}),
    ("8+gap", {"C": 0.25, "K": 30.0, "mu": 0.5, "N": 330.0, "gap.g": 2.0}),
    ("9+gap+friction", {"C": 0.2, "alpha": 0.15, "beta": 27.0, "gap.g": 2.0, "friction.Ff": 1.0}),
    ("3+series_stiffness", {"C": 45.0, "alpha": 0.8, "K1": 5.0, "series_stiffness.Ks": 150.0}),
]


@pytest.mark.parametrize("spec,params", TWO, ids=[c[0] for c in TWO])
def test_two_materials_in_series_follow_the_model(spec, params):
    """Laws 3-9 behind a gap or a series spring: the connection's dead zone
    (Ks dz(w, g/2)) and the law with the effects inside the connection, in
    two zeroLength elements through an internal node (TRBDF2): within the
    bound and far closer than the law alone, on a sine ramped up from rest."""
    quiet_opensees()
    t, d = sine(10.0, 1.0)
    d = d * np.minimum(1.0, t)
    model = parse_model(spec)
    ex = opensees_export(model, params, tested={"d": 10.0, "F": 50.0})
    assert ex.connection and ex.commands[-1][2] == 1 + ex.connection and "two materials" in ex.note
    res = check(model, params, t, d, substeps=8, export=ex)
    assert res.of <= res.bound, (res.of, res.bound)
    base = parse_model(model.law.key)
    F_base = check(base, {n: params[n] for n in base.names}, t, d, substeps=8).F_model
    assert res.of < 0.2 * objective(res.F_model, F_base, t)


def test_the_material_is_viscous_damper_with_lgap():
    """The clearance goes in as LGap; a series spring as K; without one a
    contact spring that deflects CONTACT_DEFLECTION of the tested stroke
    under the tested force."""
    ex = opensees_export("2+gap+series_stiffness", CASES[0][1], tag=3)
    assert ex.commands == [("uniaxialMaterial", "ViscousDamper", 3, 150.0, 45.4, 0.3, 2.0)] and not ex.exact
    ex = opensees_export("2+gap", CASES[1][1], tested={"d": 25.0, "F": 200.0})
    assert ex.commands[0][3] == pytest.approx(200.0 / (CONTACT_DEFLECTION * 25.0)) and "contact" in ex.note
    ex = opensees_export("2+gap+series_stiffness", CASES[0][1], units="kN,m,s")  # g in m: 2 mm
    assert ex.commands[0][6] == pytest.approx(0.002) and ex.clearance == pytest.approx(2.0)
    with pytest.raises(InputError, match="tested stroke and force"):
        opensees_export("2+gap", CASES[1][1])


# ------------------------------------------------ end to end on a lab-like record
def _define(path):
    """define_damper from an exported OpenSeesPy script, as a user imports it."""
    scope: dict = {}
    exec(compile(open(path).read(), path, "exec"), scope)
    return scope["define_damper"]


def _zero_length_force(define, t, d):
    """An OpenSees model of my own: node 1 fixed, node 2 driven through d [mm]
    (a Path time series, Penalty constraint), the damper in a zeroLength
    element between them, TRBDF2 steps of the record's dt; the element force [kN]."""
    import openseespy.opensees as ops

    ops.wipe()
    ops.model("basic", "-ndm", 1, "-ndf", 1)
    ops.node(1, 0.0)
    ops.node(2, 0.0)
    ops.fix(1, 1)
    define(ops, 7)
    ops.element("zeroLength", 1, 1, 2, "-mat", 7, "-dir", 1)
    dt = float(t[1] - t[0])
    ops.timeSeries("Path", 1, "-dt", dt, "-values", *map(float, d))
    ops.pattern("Plain", 1, 1)
    ops.sp(2, 1, 1.0)
    ops.constraints("Penalty", 1e12, 1e12)
    ops.numberer("Plain")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", 1e-10, 20)
    ops.algorithm("Newton")
    ops.integrator("TRBDF2")
    ops.analysis("Transient")
    F = [ops.eleForce(1, 2)]
    for _ in range(1, len(t)):
        assert ops.analyze(1, dt) == 0
        F.append(ops.eleForce(1, 2))
    ops.wipe()
    return np.array(F)


@pytest.mark.slow
def test_a_pin_gap_reaches_opensees_from_diagnose(tmp_path):
    from conftest import cli_env
    from fvd_bridge.records import read_record
    from fvd_bridge.rig import VirtualDamper, Noise, paper, write_series

    path = write_series(str(tmp_path / "rec"), [VirtualDamper(C=45.4, alpha=0.3, gap=2.0, name="fvd")],
                        paper(cycles=3), Noise(force=0.5, displacement=0.005), seed=11)[0]

    def cli(*args):
        res = subprocess.run([sys.executable, "-m", "fvd_bridge.cli", *args], capture_output=True, text=True,
                             env=cli_env(), cwd=tmp_path)
        assert res.returncode == 0, res.stderr
        return res

    out = tmp_path / "diag"
    res = cli("diagnose", path, "--law", "2", "--target", "opensees", "--intervals", "0",
              "--no-figures", "--quiet", "--out", str(out))
    report = json.load(open(out / "fvd_diagnose.json"))
    assert report["target"] == "opensees"
    best = report["candidates"][0]
    assert best["effect"] == "gap"
    spec = f"{report['model']}+gap"
    cal = report["calibrations"][spec]
    assert f"fvd-bridge export opensees {cal}" in res.stdout  # the next step is the target's export
    cli("export", "opensees", cal, "-o", str(tmp_path / "damper.py"), "--check")
    rec = read_record(path)
    # the motion: the displacement integrated from the velocity the tool derived, as a structure moves the
    # damper smoothly (the measured d's noise, 0.005 mm, through the contact spring: OF 0.028 where this is 0.0117)
    d = np.concatenate([[0.0], np.cumsum(0.5 * (rec.v[1:] + rec.v[:-1]) * np.diff(rec.t))])
    F_ops = _zero_length_force(_define(str(tmp_path / "damper.py")), rec.t, d)
    of_ops = objective(rec.F, F_ops, rec.t)
    gain = report["of"] - best["of"]
    assert gain > 0.5 * report["of"]  # the gap matters on this record
    assert report["of"] - of_ops >= 0.75 * gain, (report["of"], best["of"], of_ops)
