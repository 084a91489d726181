"""Model golden outputs (law + effects): the package reproduces tests/golden/law<SPEC>.csv,
and the generator writes the same numbers into any folder."""

import numpy as np
import pytest

from fvd_bridge.golden import GOLDEN_DIR, MODEL_SPECS, golden_record, read_golden, reference_params, write_golden
from fvd_bridge.catalog import parse_model
from fvd_bridge.laws import LAWS


@pytest.mark.parametrize("spec", MODEL_SPECS)
def test_model_golden_output(spec):
    model = parse_model(spec)
    pars, cols = read_golden(GOLDEN_DIR / f"law{spec}.csv")
    assert list(pars) == model.names and np.allclose(list(pars.values()), reference_params(model), rtol=1e-12)
    F = model.force(golden_record(cols), np.array([list(pars.values())]))[0]
    assert np.max(np.abs(F - cols["F"])) <= 1e-9 * np.max(np.abs(cols["F"]))


def test_every_effect_has_goldens_on_laws_2_and_9():
    from fvd_bridge.effects import EFFECTS

    for law in (2, 9):
        for name in EFFECTS:
            assert (GOLDEN_DIR / f"law{law}+{name}.csv").is_file()
    assert sum("+" in s[2:] for s in MODEL_SPECS) >= 2  # combinations


def test_effects_change_the_golden_force():
    """Each effect's reference size is large enough to be seen against the law alone."""
    _, base = read_golden(GOLDEN_DIR / "law2.csv")
    for spec in (s for s in MODEL_SPECS if s.startswith("2+") and s.count("+") == 1):
        _, cols = read_golden(GOLDEN_DIR / f"law{spec}.csv")
        assert np.max(np.abs(cols["F"] - base["F"])) > 0.01 * np.max(np.abs(base["F"])), spec


def test_generator_writes_the_same_numbers(tmp_path):
    paths = write_golden(tmp_path)
    assert len(paths) == len(LAWS) + len(MODEL_SPECS)
    for path in paths:
        _, new = read_golden(path)
        _, old = read_golden(GOLDEN_DIR / path.name)
        assert new.keys() == old.keys()
        assert np.max(np.abs(new["F"] - old["F"])) <= 1e-9 * np.max(np.abs(old["F"])), path.name
