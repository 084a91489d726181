"""Physical effects: each equation against an independent computation, the
composition against the virtual rig, nesting, specs, plugins and bad input."""

from __future__ import annotations

import math
import textwrap
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from fvd_bridge import cli
from fvd_bridge.catalog import catalog
from fvd_bridge.effects import EFFECTS
from fvd_bridge.effects.plugins import load_plugins
from fvd_bridge.errors import InputError
from fvd_bridge.laws import LAWS
from fvd_bridge.catalog import parse_model
from fvd_bridge.records import Record
from fvd_bridge.rig import VirtualDamper, acceptance, paper, simulate
from conftest import PLUGIN

C, ALPHA = 45.4, 0.3
SEVEN = ("series_stiffness", "friction", "thermal_softening", "gap", "asymmetry", "parallel_stiffness", "inertia")


def sine_record(n_cycles=3.0, freq=2.0, amp=20.0, dt=0.0025, phase0=True) -> Record:
    """d = amp sin(w t) with exact v, a (starts at rest only if phase0 is False)."""
    t = np.arange(int(round(n_cycles / freq / dt)) + 1) * dt
    w = 2 * np.pi * freq
    d, v, a = amp * np.sin(w * t), amp * w * np.cos(w * t), -amp * w * w * np.sin(w * t)
    return Record(t, d, C * np.sign(v) * np.abs(v) ** ALPHA, v, a, name="sine")


def values(model, **named) -> np.ndarray:
    return np.array([named[n] for n in model.names], dtype=float)


@pytest.fixture(scope="module")
def acc():
    return acceptance(dt=0.005, cycles=2)


# ------------------------------------------------------------ catalogue
def test_seven_effects_are_documented():
    assert set(SEVEN) <= set(EFFECTS)
    for e in EFFECTS.values():
        assert e.summary and e.equation and e.symptom and e.cause
        assert len(e.none) == len(e.parameters)
        for p in e.parameters:
            assert p.unit and p.description
        if e.function is not None:
            assert e.function.__doc__ and len(e.function.__doc__) > 40


@pytest.mark.parametrize("name", SEVEN)
def test_bounds_scale_with_record_and_contain_no_effect(name):
    e = catalog().effect(name)
    small, big = {"F": 30.0, "v": 50.0, "d": 10.0}, {"F": 300.0, "v": 500.0, "d": 40.0}
    for s in (small, big):
        b = e.bounds(s)
        assert b.shape == (len(e.parameters), 2) and np.all(b[:, 0] < b[:, 1])
        none = np.clip(e.none, b[:, 0], b[:, 1])
        assert np.all((none >= b[:, 0]) & (none <= b[:, 1]))
        finite = np.isfinite(e.none)
        assert np.all(none[finite] == np.asarray(e.none)[finite])  # 'off' lies inside, not clipped
    if any(p.unit != "-" for p in e.parameters):
        assert not np.allclose(e.bounds(small), e.bounds(big))


def test_effects_cli_lists_all(capsys):
    assert cli.main(["effects"]) == 0
    out = capsys.readouterr().out
    for name in SEVEN:
        assert f"{name} (" in out
    for unit in ("[kN/mm]", "[kN]", "[1/MJ]", "[mm]", "[kg]", "[-]"):
        assert unit in out


# ------------------------------------------------------------ specs
def test_spec_names_and_layout():
    m = parse_model("2+friction+series_stiffness")
    assert m.spec == "2+friction+series_stiffness"
    assert m.names == ["C", "alpha", "friction.Ff", "series_stiffness.Ks"]
    assert m.units == ["kN/(mm/s)^alpha", "-", "kN", "kN/mm"]
    assert parse_model("law9+gap").names[-1] == "gap.g"


@pytest.mark.parametrize("spec, words", [
    ("2+frict", ["unknown effect 'frict'", "friction"]),
    ("2+friction+friction", ["'friction' appears twice"]),
    ("12+friction", ["unknown law"]),
])
def test_bad_specs_are_one_line_input_errors(spec, words):
    with pytest.raises(InputError) as exc:
        parse_model(spec)
    msg = str(exc.value)
    assert "\n" not in msg and all(w in msg for w in words)


# ------------------------------------------------------------ nesting
@pytest.mark.parametrize("law", sorted(LAWS))
def test_each_effect_switched_off_is_the_bare_law(law):
    rec = sine_record(n_cycles=2, dt=0.005)
    base = parse_model(str(law))
    b = base.bounds("auto", {"F": 300.0, "v": 250.0, "d": 20.0})
    p = 0.3 * b[:, 0] + 0.7 * b[:, 1] if law != 7 else np.array([20.0, 0.3, 100.0, 1.0])
    F0 = base.force(rec, p[None, :])[0]
    for name in SEVEN:
        e = catalog().effect(name)
        if e.stage == "series" and not base.law.connection:
            continue  # refused by the registry (tests/laws/test_oil_damper.py)
        m = parse_model(f"{law}+{name}")
        off = np.clip(e.none, *e.bounds(rec.scales()).T)
        F = m.force(rec, np.r_[p, off][None, :])[0]
        np.testing.assert_allclose(F, F0, atol=1e-9 * np.abs(F0).max(), err_msg=f"{law}+{name}")


# ------------------------------------------------------------ equations, independently
def test_friction_asymmetry_parallel_inertia_closed_forms():
    rec = sine_record()
    law = LAWS[2].force(rec.d, rec.v, rec.dt, np.array([[C, ALPHA]]))[0]
    cases = {
        "friction": (dict(**{"friction.Ff": 12.0}), law + 12.0 * np.tanh(rec.v / 1.0)),
        "asymmetry": (dict(**{"asymmetry.r": 0.2}), law * np.where(law > 0, 1.2, 0.8)),
        "parallel_stiffness": (dict(**{"parallel_stiffness.Kp": 3.0, "parallel_stiffness.F0": -7.0}),
                               law + 3.0 * rec.d - 7.0),
        "inertia": (dict(**{"inertia.m": 1500.0}), law + 1500.0 * rec.a * 1e-6),
    }
    for name, (extra, expected) in cases.items():
        m = parse_model(f"2+{name}")
        F = m.force(rec, values(m, C=C, alpha=ALPHA, **extra)[None, :])[0]
        np.testing.assert_allclose(F, expected, rtol=1e-12, atol=1e-9, err_msg=name)


def test_thermal_softening_against_explicit_energy_integration():
    """dE/dt = 1e-6 F v, F = F_law exp(-theta E), integrated by RK4 on a fine
    analytic grid, against the effect's closed form on the samples."""
    rec = sine_record(n_cycles=6, dt=0.004)
    theta = 3.0
    m = parse_model("2+thermal_softening")
    F = m.force(rec, values(m, C=C, alpha=ALPHA, **{"thermal_softening.theta": theta})[None, :])[0]
    w = 2 * np.pi * 2.0

    def power(t, E):
        v = 20.0 * w * np.cos(w * t)
        return 1e-6 * C * np.abs(v) ** (1 + ALPHA) * np.exp(-theta * E)

    sol = solve_ivp(power, (0, rec.t[-1]), [0.0], t_eval=rec.t, rtol=1e-10, atol=1e-14, method="DOP853")
    Fref = C * np.sign(rec.v) * np.abs(rec.v) ** ALPHA * np.exp(-theta * sol.y[0])
    assert np.max(np.abs(F - Fref)) < 2e-3 * np.max(np.abs(Fref))
    assert F[-1] / Fref[-1] == pytest.approx(1.0, abs=2e-3)
    assert np.abs(F[-100:]).max() < 0.95 * np.abs(F[:100]).max()  # it does soften


def _maxwell_reference(rec, Ks, law_rate, freq=2.0, amp=20.0):
    """dF/dt = Ks (v(t) - u(F)) by Radau on the analytic motion."""
    w = 2 * np.pi * freq
    sol = solve_ivp(lambda t, F: Ks * (amp * w * np.cos(w * t) - law_rate(F)), (0, rec.t[-1]), [0.0],
                    t_eval=rec.t, method="Radau", rtol=1e-9, atol=1e-9)
    return sol.y[0]


@pytest.mark.parametrize("law, p, Ks", [(1, [0.6], 40.0), (2, [C, ALPHA], 60.0), (2, [C, 0.6], 200.0)])
def test_series_stiffness_against_radau_maxwell(law, p, Ks):
    rec = sine_record(n_cycles=2, dt=0.0025)
    m = parse_model(f"{law}+series_stiffness")
    F = m.force(rec, np.array([p + [Ks]]))[0]
    a = 1.0 if law == 1 else p[1]
    Fref = _maxwell_reference(rec, Ks, lambda f: np.sign(f) * (np.abs(f) / p[0]) ** (1 / a))
    scale = np.abs(Fref).max()
    assert np.max(np.abs(F - Fref)) < 5e-3 * scale
    assert np.mean(np.abs(F - Fref)) < 5e-4 * scale
    F0 = parse_model(str(law)).force(rec, np.array([p]))[0]
    assert np.mean(np.abs(F - F0)) > 0.01 * scale  # the spring matters here


def test_series_stiffness_with_a_hysteretic_law_against_radau():
    """Law 9 (LuGre + viscous) behind a spring: states x_o, z; u = (Ks (d - x_o) - b z) / Cv."""
    Cv, a_, b_, Ks = 0.3, 0.2, 50.0, 30.0
    rec = sine_record(n_cycles=2, dt=0.002)
    w = 2 * np.pi * 2.0

    def rhs(t, s):
        x, z = s
        u = (Ks * (20.0 * np.sin(w * t) - x) - b_ * z) / Cv
        return [u, u - a_ * abs(u) * z]

    sol = solve_ivp(rhs, (0, rec.t[-1]), [0.0, 0.0], t_eval=rec.t, method="Radau", rtol=1e-9, atol=1e-10)
    Fref = Ks * (rec.d - sol.y[0])
    m = parse_model("9+series_stiffness")
    F = m.force(rec, np.array([[Cv, a_, b_, Ks]]), substeps=4)[0]
    assert np.mean(np.abs(F - Fref)) < 2e-3 * np.abs(Fref).max()


def test_law7_with_unit_exponent_is_law2_behind_a_spring():
    """Two independent codes: Lu's visco-elastic law (beta = 1) and law 2 + series_stiffness."""
    rec = sine_record(n_cycles=2, dt=0.0025)
    K = 80.0
    F7 = LAWS[7].force(rec.d, rec.v, rec.dt, np.array([[C, ALPHA, K, 1.0]]), 16)[0]
    m = parse_model("2+series_stiffness")
    F = m.force(rec, np.array([[C, ALPHA, K]]), substeps=4)[0]
    assert np.mean(np.abs(F - F7)) < 2e-3 * np.abs(F7).max()


def test_series_stiffness_at_its_upper_bound_is_rigid():
    rec = sine_record()
    m = parse_model("2+series_stiffness")
    hi = m.bounds("auto", rec.scales())[-1, 1]
    F = m.force(rec, np.array([[C, ALPHA, hi], [C, ALPHA, 0.5 * hi]]))
    F0 = LAWS[2].force(rec.d, rec.v, rec.dt, np.array([[C, ALPHA]]))[0]
    np.testing.assert_array_equal(F[0], F0)
    assert np.mean(np.abs(F[1] - F0)) < 0.01 * np.abs(F0).max()


# ------------------------------------------------------------ against the rig
RIG_CASES = {
    "series_stiffness": dict(Ks=60.0), "friction": dict(friction=10.0), "thermal_softening": dict(heating=1.0),
    "gap": dict(gap=1.0), "asymmetry": dict(asymmetry=0.1), "parallel_stiffness": dict(Kp=2.0, preload=10.0),
    "inertia": dict(mass=2000.0),
}
RIG_NAMES = {"series_stiffness.Ks": "Ks", "friction.Ff": "friction", "thermal_softening.theta": "heating",
             "gap.g": "gap", "asymmetry.r": "asymmetry", "parallel_stiffness.Kp": "Kp",
             "parallel_stiffness.F0": "preload", "inertia.m": "mass", "C": "C", "alpha": "alpha"}


def rig_params(model, dev) -> np.ndarray:
    return np.array([getattr(dev, RIG_NAMES[n]) for n in model.names], dtype=float)


@pytest.mark.parametrize("name", SEVEN)
def test_each_effect_reproduces_the_rig(name, acc):
    dev = VirtualDamper(C=C, alpha=ALPHA, **RIG_CASES[name])
    rec = simulate(dev, acc)
    m = parse_model(f"2+{name}")
    F = m.force(rec, rig_params(m, dev)[None, :])[0]
    assert np.mean(np.abs(F - rec.F)) < 0.05  # kN, against 1 kN of realistic noise
    assert np.max(np.abs(F - rec.F)) < 2.0
    if name == "series_stiffness":  # second order: converges to the rig's SDIRK3 solution
        F4 = m.force(rec, rig_params(m, dev)[None, :], substeps=4)[0]
        assert np.mean(np.abs(F4 - rec.F)) < 0.005


def test_all_effects_together_reproduce_the_rig():
    """The rig's gap is its own physics, a play operator on the damper body's
    motion (rig/simulate.py): the spring behind it keeps its force in the
    clearance, the accumulator and the mass act on the body.  It is the
    contact gap only for a law without force at rest and no spring
    (test_each_effect_reproduces_the_rig['gap'], tests/effects/test_contact_gap.py),
    so here the device has none and the model's gap is closed (g = 0)."""
    dev = VirtualDamper(C=C, alpha=ALPHA, Ks=150.0, friction=3.0, heating=0.2, gap=0.0, asymmetry=0.03, Kp=0.5,
                 preload=2.0, mass=500.0)
    rec = simulate(dev, paper(dt=0.002))
    m = parse_model("2+" + "+".join(SEVEN))
    F = m.force(rec, rig_params(m, dev)[None, :])[0]
    assert np.mean(np.abs(F - rec.F)) < 0.05
    assert np.mean(np.abs(F - rec.F)) < 0.001 * np.abs(rec.F).max()


# ------------------------------------------------------------ plugins


def test_plugin_effect_composes_like_a_builtin(tmp_path):
    path = tmp_path / "my_effects.py"
    path.write_text(PLUGIN)
    m = catalog([str(path)]).model("2+cubic_spring+friction")
    assert m.names[-2:] == ["cubic_spring.K3", "friction.Ff"]
    rec = sine_record()
    F = m.force(rec, np.array([[C, ALPHA, 1e-3, 5.0]]))[0]
    expected = C * np.sign(rec.v) * np.abs(rec.v) ** ALPHA + 1e-3 * rec.d ** 3 + 5.0 * np.tanh(rec.v)
    np.testing.assert_allclose(F, expected, rtol=1e-10, atol=1e-9)


@pytest.mark.parametrize("text, words", [
    ("def broken(:\n", ["line 1", "syntax error"]),
    ("X = 1\n", ["defines no EFFECTS"]),
    ("raise RuntimeError('boom')\n", ["failed to load", "boom"]),
    (PLUGIN.replace('name="cubic_spring"', 'name="friction"'), ["clashes with the built-in"]),
    (PLUGIN.replace("P[:, 0:1] * np.asarray(x) ** 3", "np.ones(7)"), ["returned shape"]),
    (PLUGIN.replace("none=(0.0,)", "none=(5.0,)"), ["outside the bounds"]),
    (PLUGIN.replace('stage="parallel"', 'stage="sideways"'), ["stage 'sideways'"]),
])
def test_bad_plugin_files_are_refused_in_one_line(tmp_path, text, words):
    path = tmp_path / "bad_plugin.py"
    path.write_text(textwrap.dedent(text))
    with pytest.raises(InputError) as exc:
        load_plugins([str(path)])
    msg = str(exc.value)
    assert "\n" not in msg and "bad_plugin.py" in msg
    assert all(w in msg for w in words), msg


def test_cli_bad_effect_input_exit_2(tmp_path, capsys):
    bad = tmp_path / "bad.py"
    bad.write_text("EFFECTS = [1]\n")
    for argv, word in ((["effects", "--plugin", str(bad)], "Effect objects"),
                       (["effects", "--plugin", str(tmp_path / "none.py")], "no such file")):
        assert cli.main(argv) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and word in err


def test_contributions_sum_to_the_model_force():
    """Pastas-style per-term contributions; behind a series spring the law's
    part includes asymmetry and heating (they are solved inside the spring)."""
    from fvd_bridge.effects.compose import contributions

    rec = sine_record(n_cycles=2)
    cases = (("2+asymmetry+thermal_softening+friction+inertia", [C, ALPHA, 0.1, 2.0, 8.0, 900.0],
              {"law", "asymmetry", "thermal_softening", "friction", "inertia"}),
             ("2+series_stiffness+asymmetry+friction+parallel_stiffness", [C, ALPHA, 80.0, 0.1, 8.0, 1.0, 3.0],
              {"law", "friction", "parallel_stiffness"}))
    for spec, p, keys in cases:
        m = parse_model(spec)
        parts = contributions(m, rec, np.array(p))
        assert set(parts) == keys
        np.testing.assert_allclose(sum(parts.values()), m.force(rec, np.array([p]))[0], atol=1e-8)


def test_population_evaluation_is_consistent_row_by_row():
    """The vectorized drivers give each row what it would get alone."""
    rec = sine_record(n_cycles=2)
    m = parse_model("2+gap+series_stiffness+thermal_softening+asymmetry+friction")
    b = m.bounds("auto", rec.scales())
    rng = np.random.default_rng(0)
    P = b[:, 0] + rng.random((6, len(b))) * (b[:, 1] - b[:, 0])
    P[:, -1] = np.linspace(0, 5, 6)
    F = m.force(rec, P)
    for i in range(P.shape[0]):
        np.testing.assert_allclose(F[i], m.force(rec, P[i:i + 1])[0], rtol=1e-12, atol=1e-9)
    assert np.all(np.isfinite(F))


def test_extreme_parameters_stay_finite():
    rec = sine_record(n_cycles=1)
    for spec in ("2+series_stiffness", "5+series_stiffness", "7+series_stiffness", "6+series_stiffness+gap",
                 "2+thermal_softening+gap"):
        m = parse_model(spec)
        b = m.bounds("auto", rec.scales())
        corners = np.array([b[:, 0], b[:, 1], 0.5 * (b[:, 0] + b[:, 1])])
        corners[:, 0] = np.maximum(corners[:, 0], 1e-6)  # a damper has some damping
        assert np.all(np.isfinite(m.force(rec, corners))), spec
        assert math.isfinite(float(np.abs(m.force(rec, corners)).max()))


# ------------------------------------------------------------------ a user's series effect
OIL_COLUMN = Path(__file__).resolve().parents[2] / "examples" / "bulk_modulus.py"


def test_a_plugin_series_effect_sets_the_connection():
    """examples/bulk_modulus.py sets Ks from an oil's bulk modulus: law 2 behind
    it is law 2 + series_stiffness at the same Ks (the same connection
    kernel), its 'off' value is the bare law, and it cannot share Ks with
    series_stiffness."""
    cat = catalog([str(OIL_COLUMN)])
    rec = simulate(VirtualDamper(C=45.4, alpha=0.3), acceptance(dt=0.005, cycles=2), None, name="probe")
    B = 1500.0
    F_plugin = cat.model("2+bulk_modulus").force(rec, np.array([[45.4, 0.3, B]]))[0]
    F_series = cat.model("2+series_stiffness").force(rec, np.array([[45.4, 0.3, B * 15000.0 / 200.0 * 1e-3]]))[0]
    assert np.max(np.abs(F_plugin - F_series)) <= 1e-9 * np.max(np.abs(F_series))
    off = cat.model("2+bulk_modulus").force(rec, np.array([[45.4, 0.3, 1e6]]))[0]
    assert np.array_equal(off, cat.model("2").force(rec, np.array([[45.4, 0.3]]))[0])
    with pytest.raises(InputError, match="sets the connection's Ks"):
        cat.model("2+bulk_modulus+series_stiffness")
    assert cat.model("2+bulk_modulus").exports()["fmu"]  # a plugin has no C step form


@pytest.mark.parametrize("body,words", [
    ('slots=("Ff",), function=lambda P: (P[:, 0],)', "sets the connection's Ks and/or g"),
    ('slots=("Ks",), function=lambda P: (1.0 / P[:, 0],)', "models must be nested"),
    ('slots=("Ks",), function=lambda P: P[:, 0]', "returns a tuple of 1 arrays"),
])
def test_malformed_series_plugins_are_refused(tmp_path, body, words):
    path = tmp_path / "bad_series.py"
    path.write_text(textwrap.dedent(f"""
        import numpy as np
        from fvd_bridge.effects import Effect, Parameter
        EFFECTS = [Effect(name="bad", stage="series", parameters=(Parameter("k", "kN/mm", (0.0, 1.0),
                          lambda s: (0.0, 1.0), "k"),), none=(np.inf,), equation="", summary="", {body})]
        """))
    with pytest.raises(InputError, match=words):
        load_plugins([str(path)])
