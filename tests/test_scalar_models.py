"""The one-member step form of a whole model (fvd_bridge.effects.scalar), the
reference for the FMU's C code, checked against the population entry
``Model.force`` (compose.py over the population drivers) and the model
goldens.

For each model of MODEL_SPECS (each effect on law 2 and on law 9, and the
combinations), MEMBERS parameter rows are drawn (seeded) across the model's
'auto' bounds for the golden record (log-uniform where the optimizer
searches on a log scale, fit.space; series Ks below KS_RIGID), plus the
golden reference set; ``Model.force`` evaluates them as one population, the
scalar form one member at a time.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import pytest

from fvd_bridge.effects import EFFECTS, Effect, Parameter
from fvd_bridge.effects.catalog import KS_RIGID
from fvd_bridge.effects.scalar import (EFFECT_NAMES, OFF, PARAMETERS, model_history, scalar_arguments,
                                       scalar_force)
from fvd_bridge.errors import InputError
from fvd_bridge.fit.space import Space
from fvd_bridge.golden import GOLDEN_DIR, MODEL_SPECS, read_golden
from fvd_bridge.laws.scalar import history
from fvd_bridge.catalog import parse_model
from fvd_bridge.records import Record

MEMBERS = 10
TOL = 1e-12  # of a member's peak force: the scalar form and the population differ only in rounding


@lru_cache(maxsize=None)
def golden(spec):
    """(model, reference parameters, record with the golden force, golden F [kN])."""
    pars, cols = read_golden(GOLDEN_DIR / f"law{spec}.csv")
    record = Record(cols["t"], cols["d"], cols["F"], cols["v"], cols["a"], name="golden")
    return parse_model(spec), np.array(list(pars.values())), record, cols["F"]


@lru_cache(maxsize=None)
def population(spec):
    """MEMBERS rows drawn across the model's auto bounds, then the reference set."""
    model, p_ref, record, _ = golden(spec)
    bounds = model.bounds("auto", record.scales())
    if model.has("series_stiffness"):  # a spring, not the rigid connection
        j = model.names.index("series_stiffness.Ks")
        bounds[j, 1] = 0.999 * KS_RIGID
    u = np.random.default_rng(200 + MODEL_SPECS.index(spec)).random((MEMBERS, len(model.names)))
    P = Space.of(bounds, model.log_scale("auto")).to_params(u)
    return np.vstack([P, p_ref])


def worst(spec, P, substeps=1):
    """max over members of max|F_scalar - F_population| / max|F_population|."""
    model, _, record, _ = golden(spec)
    Fp = model.force(record, P, substeps)
    return max(np.max(np.abs(scalar_force(model, p, record, substeps) - f)) / np.max(np.abs(f))
               for p, f in zip(P, Fp))


@pytest.mark.parametrize("spec", MODEL_SPECS)
def test_scalar_model_reproduces_golden_output(spec):
    model, p, record, F = golden(spec)
    assert np.max(np.abs(scalar_force(model, p, record) - F)) <= 1e-9 * np.max(np.abs(F))


@pytest.mark.parametrize("spec", MODEL_SPECS)
def test_scalar_model_matches_population(spec):
    """Row by row, to TOL of the member's peak force; bit for bit on this
    machine (both paths call the same scalar functions with the same
    fastmath flags, and neither fuses the sums), TOL leaves room for another
    CPU's vector width in the population drivers."""
    assert worst(spec, population(spec)) <= TOL


@pytest.mark.parametrize("spec", [s for s in MODEL_SPECS if s.startswith("9+") or "series" in s or "gap" in s])
def test_scalar_model_with_substeps(spec):
    """Bit for bit only with the law's sub-step velocities compiled with the
    drivers' fastmath flags (effects.scalar.law_sample): 'arcp' makes j/m a
    product by 1/m (without it: up to 3e-16 of the peak, within TOL)."""
    assert worst(spec, population(spec)[-4:], substeps=3) <= TOL


def test_rigid_series_spring_is_the_model_without_it():
    """Ks >= KS_RIGID: the model without series_stiffness (as compose.py)."""
    spec = "2+gap+series_stiffness+asymmetry"
    model, p, record, _ = golden(spec)
    rigid = p.copy()
    rigid[model.names.index("series_stiffness.Ks")] = KS_RIGID
    assert worst(spec, rigid[None, :]) <= TOL
    without = model.without_effect("series_stiffness")
    keep = model.columns_without("series_stiffness")
    assert np.array_equal(scalar_force(model, rigid, record), scalar_force(without, rigid[keep], record))


def test_without_effects_it_is_the_law():
    """All flags off: laws.scalar.history on the record's d, v."""
    _, _, record, _ = golden("9+gap")
    code, flags, p_law, p_eff = scalar_arguments(parse_model("9"), [0.2, 0.15, 27.0])
    assert not flags.any() and np.array_equal(p_eff, OFF)
    F = model_history(code, flags, p_law, p_eff, record.d, record.v, record.a, record.dt, 2)
    assert np.array_equal(F, history(9, p_law, record.d, record.v, record.dt, 2))


def test_parameter_layout_is_the_catalogs():
    assert EFFECT_NAMES == tuple(EFFECTS)
    assert PARAMETERS == ("gap.g", "series_stiffness.Ks", "asymmetry.r", "thermal_softening.theta", "friction.Ff",
                          "parallel_stiffness.Kp", "parallel_stiffness.F0", "inertia.m")
    model = parse_model("2+inertia+gap")
    code, flags, p_law, p_eff = scalar_arguments(model, [45.0, 0.3, 1000.0, 1.0])
    assert code == 2 and list(p_law) == [45.0, 0.3]
    assert [EFFECT_NAMES[i] for i in np.flatnonzero(flags)] == ["gap", "inertia"]
    assert p_eff[PARAMETERS.index("inertia.m")] == 1000.0 and p_eff[PARAMETERS.index("gap.g")] == 1.0


def test_plugin_effects_and_bad_vectors_are_refused():
    user = Effect(name="drag", stage="parallel", function=lambda P, t, x, xv, xa: P[:, 0:1] * xv, none=(0.0,),
                  parameters=(Parameter("cd", "kN s/mm", (0.0, 1.0), lambda s: (0.0, 1.0), "drag"),),
                  equation="+ cd xv", summary="drag", source="my_effects.py")
    model = parse_model("2+friction").with_effect(user)
    with pytest.raises(InputError, match="'drag' \\(my_effects.py\\)"):
        scalar_arguments(model, [45.0, 0.3, 5.0, 0.1])
    with pytest.raises(InputError, match="expected 3 parameters"):
        scalar_arguments(parse_model("2+friction"), [45.0, 0.3])
