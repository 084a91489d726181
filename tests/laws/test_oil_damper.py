"""Law 10, the bilinear oil damper: identification on a lab-like record made
by an independent solver, its OpenSees export driven by a harness of this
test's own, and the step form against that solver."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from fvd_bridge import calibrate
from fvd_bridge.catalog import parse_model
from fvd_bridge.export.opensees import opensees_export
from fvd_bridge.fit.objective import objective
from fvd_bridge.laws import LAWS
from lab import lab_from_forces

#: the device: K [kN/mm], C [kN s/mm], Fr [kN], p [-]; tested at 1 Hz, 40 mm
TRUE = {"K": 100.0, "C": 5.0, "Fr": 300.0, "p": 0.1}
AMPLITUDE, FREQUENCY, DT = 40.0, 1.0, 0.005


def solve(t, v_of, K, C, Fr, p):
    """The law by scipy's solve_ivp (rtol 1e-10) on dF/dt = K (v - v_d(F)),
    v_d = F/C within the relief force, Fr/C + (|F| - Fr)/(p C) beyond:
    the spring force [kN] at the times t [s], from F = 0."""
    def v_d(F):
        return F / C if abs(F) <= Fr else math.copysign(Fr / C + (abs(F) - Fr) / (p * C), F)

    sol = solve_ivp(lambda s, y: [K * (v_of(s) - v_d(y[0]))], (t[0], t[-1]), [0.0], t_eval=t,
                    rtol=1e-10, atol=1e-9, max_step=DT / 5)
    return sol.y[0]


def sine(t):
    w = 2.0 * math.pi * FREQUENCY
    return AMPLITUDE * np.sin(w * t), AMPLITUDE * w * np.cos(w * t)


@pytest.fixture(scope="module")
def clean():
    """t [s], d [mm], v [mm/s], F [kN] of the true device, 3 cycles from rest."""
    t = np.arange(0.0, 3.0 + DT / 2, DT)
    d, v = sine(t)
    F = solve(t, lambda s: AMPLITUDE * 2 * math.pi * FREQUENCY * math.cos(2 * math.pi * FREQUENCY * s), **TRUE)
    return t, d, v, F


def test_step_form_follows_an_independent_solver(clean):
    """TR-BDF2, one step per sample (v linear between samples), against
    solve_ivp on the analytic velocity: OF 1.1e-4 at dt 5 ms; four sub-steps
    a sample bring it to the error of the linear velocity (3e-5)."""
    t, d, v, F = clean
    law = LAWS[10]
    P = np.array([list(TRUE.values())])
    assert objective(law.force(d, v, DT, P)[0], F, t) < 2e-4
    assert objective(law.force(d, v, DT, P, 4)[0], F, t) < 5e-5


@pytest.mark.parametrize("seed", [0, 1])
def test_calibration_recovers_the_device(clean, tmp_path, seed):
    """Noise on d (0.005 mm) and F (1 kN), velocity derived by the tool:
    each parameter within 5% of the truth."""
    t, d, _, F = clean
    rec = lab_from_forces(t, d, F, 1.0, 0.005, seed=seed, tmp_path=tmp_path, name="oil")
    cal = calibrate(rec, parse_model("10"), runs=1, seed=0)
    for name, true in TRUE.items():
        assert cal.named()[name] == pytest.approx(true, rel=0.05), (name, cal.named())


def test_opensees_export_reproduces_the_law(clean):
    """The export (``BilinearOilDamper``) in a zeroLength element of this
    test's own model, its free end driven through the sine by a transient
    analysis (Newmark, started at rest with the initial velocity committed):
    its force against the clean law within OF 0.01."""
    ops = pytest.importorskip("openseespy.opensees")
    t, d, v, F = clean
    commands = opensees_export("10", TRUE, tag=7).commands
    assert [c[1] for c in commands] == ["BilinearOilDamper"]
    ops.wipe()
    ops.model("basic", "-ndm", 1, "-ndf", 1)
    for name, *args in commands:
        getattr(ops, name)(*args)
    ops.node(1, 0.0)
    ops.node(2, 0.0)
    ops.fix(1, 1)
    ops.element("zeroLength", 1, 1, 2, "-mat", 7, "-dir", 1)
    ops.timeSeries("Path", 1, "-dt", DT, "-values", *map(float, d))
    ops.pattern("Plain", 1, 1)
    ops.sp(2, 1, 1.0)
    ops.setNodeVel(2, 1, float(v[0]), "-commit")
    ops.constraints("Penalty", 1e12, 1e12)
    ops.numberer("Plain")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", 1e-10, 20)
    ops.algorithm("Newton")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    ops.analyze(1, 1e-9)  # loads the material's rate at t = 0
    F_ops = np.zeros_like(t)
    for i in range(1, t.size):
        assert ops.analyze(1, DT) == 0
        F_ops[i] = ops.eleForce(1, 2)
    ops.wipe()
    assert objective(F_ops, F, t) < 0.01


def test_no_series_connection():
    """Its own spring is the series spring: series effects are refused by
    the registry's capability, with one line."""
    from fvd_bridge.errors import InputError

    for spec in ("10+series_stiffness", "10+gap"):
        with pytest.raises(InputError, match="cannot sit behind"):
            parse_model(spec)
    exports = parse_model("10+friction").exports()
    assert exports["opensees"] == exports["fmu"] == "" and "effect 'friction'" in exports["sap2000"]
    assert parse_model("10").exports() == {"opensees": "", "fmu": "", "sap2000": "", "etabs": ""}


def test_diagnose_tries_only_what_the_law_can_take(clean, tmp_path):
    """diagnose's candidates come from the registry's refusals: on law 10 it
    refits no series effect (its own spring is the series spring)."""
    from fvd_bridge.catalog import catalog
    from fvd_bridge.diagnose.rank import refit_all

    t, d, _, F = clean
    rec = lab_from_forces(t, d, F, 1.0, 0.005, seed=0, tmp_path=tmp_path, name="oil")
    base = parse_model("10")
    series = {name: e for name, e in catalog().effects.items() if e.stage == "series"}
    assert {base.refusal(e) != "" for e in series.values()} == {True}
    assert refit_all(base, None, rec, series, seed=0, settings=None) == []
    assert base.refusal(catalog().effect("friction")) == ""
