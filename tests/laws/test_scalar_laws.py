"""The single-member step form of the nine laws (fvd_bridge.laws.scalar), the
reference for the FMU's C code, checked against the population drivers
(algebraic.py, differential.py) and the golden outputs.

Members are drawn (seeded) across each law's 'auto' bounds for the golden
input, plus the golden reference set; the drivers evaluate them as one
population (SIMD blocks), the scalar form one member at a time.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import pytest

from fvd_bridge.fit.space import Space
from fvd_bridge.golden import DT, GOLDEN_DIR, read_golden
from fvd_bridge.laws import LAWS
from fvd_bridge.laws.scalar import advance, force, history, law_constants, new_state

MEMBERS = 30
TOL = 1e-12  # of a member's peak force: the scalar form and the drivers differ only in rounding


@lru_cache(maxsize=None)
def golden(n):
    """(parameters, d [mm], v [mm/s], F [kN]) of tests/golden/law<n>.csv."""
    pars, cols = read_golden(GOLDEN_DIR / f"law{n}.csv")
    d, v, F = (np.ascontiguousarray(cols[c]) for c in "dvF")
    return np.array(list(pars.values())), d, v, F


@lru_cache(maxsize=None)
def population(n):
    """MEMBERS parameter rows drawn across law n's auto bounds (log-uniform for
    parameters searched on a log scale, as the search's space maps them), then the golden reference set."""
    p_ref, d, v, F = golden(n)
    law = LAWS[n]
    bounds = law.bounds("auto", {"F": np.max(np.abs(F)), "v": np.max(np.abs(v)), "d": np.max(np.abs(d))})
    if n == 7:  # keep the dashpot: C >= 1e-3 of its upper bound
        bounds[0, 0] = max(bounds[0, 0], 1e-3 * bounds[0, 1])
    rng = np.random.default_rng(100 + n)
    u = rng.random((MEMBERS, len(law.parameters)))
    P = Space.of(bounds, [p.log for p in law.parameters]).to_params(u)  # as the search draws them
    return np.vstack([P, p_ref])


def worst(n, P, substeps=1):
    """max over members of max|F_scalar - F_driver| / max|F_driver|."""
    _, d, v, _ = golden(n)
    Fp = LAWS[n].force(d, v, DT, P, substeps)
    return max(np.max(np.abs(history(n, p, d, v, DT, substeps) - f)) / np.max(np.abs(f)) for p, f in zip(P, Fp))


@pytest.mark.parametrize("n", range(1, 10))
def test_scalar_history_matches_population_driver(n):
    """Row by row, to TOL of the member's peak force.  Law 7 reaches this only
    because the scalar form inlines its solver as the driver does: LLVM then
    fuses the same multiply-adds (fastmath 'contract'); with another block
    layout it fuses others and the two differ by ~1e-15 of the peak."""
    assert worst(n, population(n)) <= TOL


@pytest.mark.parametrize("n", range(6, 10))
def test_scalar_history_with_substeps(n):
    assert worst(n, population(n)[-6:], substeps=3) <= TOL


@pytest.mark.parametrize("n", range(1, 10))
def test_scalar_history_reproduces_golden_output(n):
    p, d, v, F = golden(n)
    assert np.max(np.abs(history(n, p, d, v, DT) - F)) <= 1e-9 * np.max(np.abs(F))


def test_steps_compose_to_history():
    """history is new_state, then advance and force sample by sample."""
    p, d, v, F = golden(9)
    k, s = law_constants(9, p, DT), new_state(9)
    out = [force(9, k, s, d[0], v[0])]
    for i in range(1, d.size):
        advance(9, k, s, v[i - 1], v[i], DT)
        out.append(force(9, k, s, d[i], v[i]))
    assert np.array_equal(out, history(9, p, d, v, DT))
    assert new_state(2).size == 0 and np.all(new_state(8) == 0.0)
