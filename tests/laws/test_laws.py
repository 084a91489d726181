"""The nine laws checked against independent integrators and against themselves.

Kernels run on a paper-like record (10 cycles of 40 mm at 0.5 m/s peak
velocity, dt 0.002 s, faded in over the first cycle) with realistic
parameters for a 300 kN damper (kN, mm, s); the references are hand formulas
(laws 1-5) and scipy's solve_ivp with v(t) the same linear interpolation of
the sampled v (laws 6-9).
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from fvd_bridge.laws import LAWS
from fvd_bridge.laws.differential import bouc_wen_force
from fvd_bridge.golden import DT as GOLDEN_DT, GOLDEN_DIR, REFERENCE, read_golden

DT = 0.002  # [s]
AMPLITUDE, V_PEAK, CYCLES = 40.0, 500.0, 10  # [mm], [mm/s]
SCALES = {"F": 300.0, "v": V_PEAK, "d": AMPLITUDE}  # the record's peaks, for Law.bounds
TOL = 0.005  # of the peak force


@pytest.fixture(scope="module")
def record():
    """(t [s], d [mm], v [mm/s]): d = e(t) A sin(w t), e a smoothstep over the first cycle."""
    w = V_PEAK / AMPLITUDE
    period = 2 * np.pi / w
    t = np.arange(round(CYCLES * period / DT) + 1) * DT
    s = np.clip(t / period, 0.0, 1.0)
    e, de = s * s * (3 - 2 * s), 6 * s * (1 - s) / period
    return t, AMPLITUDE * e * np.sin(w * t), AMPLITUDE * (de * np.sin(w * t) + e * w * np.cos(w * t))


def viscous(v, C, alpha):
    return C * np.sign(v) * np.abs(v) ** alpha


HAND = {  # laws 1-5 as printed in the paper (eqs. 1, 2, 5, 6, 7)
    1: lambda d, v, C: C * v,
    2: lambda d, v, C, a: viscous(v, C, a),
    3: lambda d, v, C, a, K1: K1 * d + viscous(v, C, a),
    4: lambda d, v, C, a, K1, K2: K1 * d + K2 * d ** 2 + viscous(v, C, a),
    5: lambda d, v, C, a, K, b: viscous(d, K, b) + viscous(v, C, a),
}


def _law8_rate(z, v, C, K, mu, N):
    blocked = (z >= 1.0 and v > 0.0) or (z <= -1.0 and v < 0.0)
    return 0.0 if blocked else K / (mu * N) * v


ODES = {  # laws 6-9: (dz/dt (z, v, *P), F (z, d, v, *P), jacobian d(dz/dt)/dz or None)
    6: (lambda z, v, C, K, a, b: v - b * abs(v) * z - b * v * abs(z),
        lambda z, d, v, C, K, a, b: a * K * d + (1 - a) * K * z + C * v, None),
    7: (lambda z, v, C, a, K, b: v - np.sign(z) * (K * abs(z) ** b / C) ** (1 / a),
        lambda z, d, v, C, a, K, b: K * np.sign(z) * np.abs(z) ** b,
        lambda z, v, C, a, K, b: -(b / a) * (K / C) ** (1 / a) * abs(z) ** (b / a - 1) if z else 0.0),
    8: (_law8_rate, lambda z, d, v, C, K, mu, N: z * mu * N + C * v, None),
    9: (lambda z, v, C, a, b: v - a * abs(v) * z, lambda z, d, v, C, a, b: b * z + C * v, None),
}


def linear(t, v):
    """v(s) [mm/s], linear between the samples of the uniform grid t (t[0] = 0)."""
    slope = np.diff(v) / DT

    def at(s):
        k = min(int(s / DT), slope.size - 1)
        return v[k] + slope[k] * (s - t[k])
    return at


def reference_force(number, t, d, v, P):
    """Force [kN] of a differential law by solve_ivp, v(t) linear between samples."""
    rate, force, jac = ODES[number]
    v_at = linear(t, v)
    fun = lambda s, z: [rate(z[0], v_at(s), *P)]  # noqa: E731
    if jac is None:
        sol = solve_ivp(fun, (t[0], t[-1]), [0.0], method="DOP853", t_eval=t, rtol=1e-10, atol=1e-12,
                        max_step=DT)
    else:  # law 7 is stiff
        sol = solve_ivp(fun, (t[0], t[-1]), [0.0], method="LSODA", t_eval=t, rtol=1e-10, atol=1e-12,
                        max_step=DT, jac=lambda s, z: [[jac(z[0], v_at(s), *P)]])
    assert sol.success, sol.message
    return force(sol.y[0], d, v, *P)


CASES = [  # (law, parameters, substeps); the first of each law is the brief's realistic set
    (1, (0.6,), 1), (1, (2.0,), 1),
    (2, (45.0, 0.3), 1), (2, (1.99, 0.83), 1),
    (3, (45.0, 0.3, 5.0), 1), (3, (2.0, 1.0, 200.0), 1),
    (4, (45.0, 0.3, 5.0, 0.1), 1), (4, (2.0, 0.5, 0.0, -0.5), 1),
    (5, (45.0, 0.3, 2.0, 1.2), 1), (5, (20.0, 0.5, 0.5, 3.0), 1),
    (6, (0.25, 60.0, 0.01, 0.08), 1), (6, (0.1, 30.0, 0.3, 0.5), 1), (6, (0.0, 100.0, 0.0, 5.0), 1),
    (7, (45.0, 0.3, 100.0, 1.0), 1), (7, (45.0, 0.3, 7000.0, 0.4), 1), (7, (45.0, 0.5, 300.0, 2.0), 1),
    (7, (5.0, 0.1, 60.0, 0.2), 1), (7, (45.0, 0.3, 1000.0, 1.0), 2),
    (8, (0.25, 30.0, 0.5, 330.0), 1), (8, (0.1, 10.0, 1.0, 450.0), 1), (8, (0.3, 50.0, 0.1, 250.0), 1),
    (9, (0.2, 0.15, 27.0), 1), (9, (0.0, 2.0, 100.0), 1), (9, (0.3, 0.01, 20.0), 1),
]


@pytest.mark.parametrize("number, P, substeps", CASES)
def test_law_matches_independent_integrator(record, number, P, substeps):
    t, d, v = record
    F = LAWS[number].force(d, v, DT, np.array([P]), substeps)[0]
    ref = HAND[number](d, v, *P) if number in HAND else reference_force(number, t, d, v, P)
    assert np.max(np.abs(F - ref)) <= TOL * np.max(np.abs(ref))


def test_law9_is_bouc_wen_with_n1_A1_gamma0(record):
    """LuGre (steps.lugre_step) equals the general Bouc-Wen element (steps.bouc_wen_step)."""
    _, d, v = record
    rng = np.random.default_rng(9)
    P = np.column_stack([rng.uniform(0, 0.3, 20), rng.uniform(0, 2, 20), rng.uniform(20, 100, 20)])
    F9 = LAWS[9].force(d, v, DT, P)
    F_bw = bouc_wen_force(d, v, DT, C=P[:, 0], K=P[:, 2], alpha=0.0, A=1.0, beta=P[:, 1], gamma=0.0)
    assert np.max(np.abs(F9 - F_bw)) <= 1e-10 * np.max(np.abs(F9))


def test_law8_slip_variable_stays_in_unit_interval(record):
    """|z| <= 1, i.e. |F - C v| <= mu N, for members up to very stiff slip elements."""
    _, d, v = record
    rng = np.random.default_rng(8)
    law = LAWS[8]
    P = _draw(law, "auto", 50, rng)
    P = P[P[:, 2] * P[:, 3] > 0]
    z = (law.force(d, v, DT, P) - P[:, :1] * v) / (P[:, 2:3] * P[:, 3:4])
    assert np.all(np.abs(z) <= 1.0 + 1e-12)
    assert np.max(np.abs(z)) > 0.999  # the elements do slip


@pytest.mark.parametrize("number", [6, 8, 9])
def test_rate_independent_laws_are_exact_for_linear_v(record, number):
    """Integrated exactly for v linear between samples: sub-steps change nothing."""
    _, d, v = record
    P = _draw(LAWS[number], "auto", 10, np.random.default_rng(number))
    F1, F3 = (LAWS[number].force(d, v, DT, P, m) for m in (1, 3))
    assert np.max(np.abs(F1 - F3)) <= 1e-12 * np.max(np.abs(F1))


@pytest.mark.parametrize("C, alpha, K", [(45.0, 0.3, 100.0), (20.0, 1.0, 50.0)])
def test_law7_with_beta_1_is_maxwell(record, C, alpha, K):
    """beta = 1: spring K in series with the dashpot C|v_d|^alpha, integrated for the force,
    dF/dt = K (v - sign(F)(|F|/C)^(1/alpha)) (OpenSees ViscousDamper)."""
    t, d, v = record
    F = LAWS[7].force(d, v, DT, np.array([[C, alpha, K, 1.0]]))[0]
    v_at = linear(t, v)
    sol = solve_ivp(lambda s, f: [K * (v_at(s) - np.sign(f[0]) * (abs(f[0]) / C) ** (1 / alpha))],
                    (t[0], t[-1]), [0.0], method="LSODA", t_eval=t, rtol=1e-10, atol=1e-10, max_step=DT)
    assert np.max(np.abs(F - sol.y[0])) <= TOL * np.max(np.abs(sol.y[0]))


def _draw(law, mode, n, rng):
    """n parameter rows inside the law's bounds (log-uniform where Parameter.log), plus the corners."""
    b = law.bounds(mode, SCALES)
    u = rng.random((n, len(b)))
    P = b[:, 0] + u * (b[:, 1] - b[:, 0])
    for j, par in enumerate(law.parameters):
        if par.log and b[j, 0] > 0:
            P[:, j] = np.exp(np.log(b[j, 0]) + u[:, j] * np.log(b[j, 1] / b[j, 0]))
    corners = np.array(list(itertools.product(*b)))
    return np.vstack([P, corners])


@pytest.mark.parametrize("mode", ["auto", "paper"])
@pytest.mark.parametrize("number", sorted(LAWS))
def test_population_is_rows_and_finite(record, number, mode):
    """A population's forces are finite and equal each member evaluated alone
    (to rounding: a lone member takes the scalar path, a population the SIMD one)."""
    _, d, v = record
    law = LAWS[number]
    P = _draw(law, mode, 40, np.random.default_rng(number))
    F = law.force(d, v, DT, P)
    assert F.shape == (len(P), d.size) and np.all(np.isfinite(F))
    rows = np.array([law.force(d, v, DT, P[i:i + 1])[0] for i in (0, 1, 17, len(P) - 1)])
    np.testing.assert_allclose(rows, F[[0, 1, 17, len(P) - 1]], rtol=0, atol=1e-12 * np.max(np.abs(F)))


@pytest.mark.parametrize("number", sorted(LAWS))
def test_golden_output(number):
    """The kernels reproduce tests/golden/lawN.csv (regenerate: python -m fvd_bridge.golden)."""
    law = LAWS[number]
    pars, cols = read_golden(GOLDEN_DIR / f"law{number}.csv")
    d, v, F_golden = cols["d"], cols["v"], cols["F"]
    assert tuple(pars.values()) == REFERENCE[number] and list(pars) == law.names
    F = law.force(d, v, GOLDEN_DT, np.array([REFERENCE[number]]))[0]
    assert np.max(np.abs(F - F_golden)) <= 1e-9 * np.max(np.abs(F_golden))


def test_the_guides_table_of_laws_is_the_registrys():
    """The guide's table of laws is `fvd-bridge laws --markdown`, generated
    from the registry: a law added there shows up in the docs' table."""
    from pathlib import Path

    from fvd_bridge.commands.laws import markdown_table

    readme = (Path(__file__).resolve().parents[2] / "docs" / "guide" / "laws.md").read_text()
    table = markdown_table()
    assert table in readme
    assert all(f"| {n} {law.name} |" in table for n, law in LAWS.items())


@pytest.mark.parametrize("beta", [1.0, 0.2])
def test_law7_starts_from_rest(beta):
    """Samples at rest before the motion (zero-travel steps from z = 0) leave
    law 7 at rest: the force after five of them equals the force after one
    (which takes no zero-travel step), in the population kernel and in the
    scalar step form.  It was zero throughout, with NaN inside, until the
    Newton step's underflow at rest was caught."""
    from fvd_bridge.laws.scalar import history

    t = np.arange(0.0, 2.0, 0.002)
    d, v = 20.0 * np.sin(2 * np.pi * t) ** 2, 40.0 * np.pi * np.sin(4 * np.pi * t)  # from rest, smoothly
    p = np.array([45.0, 0.3, 100.0, beta])

    def after_rest(n):
        return np.concatenate([np.zeros(n), d]), np.concatenate([np.zeros(n), v])

    one = LAWS[7].force(*after_rest(1), 0.002, p[None, :])[0][1:]
    assert np.abs(one).max() > 100.0
    five = after_rest(5)
    for F in (LAWS[7].force(*five, 0.002, p[None, :])[0], history(7, p, *five, 0.002, 1)):
        assert np.all(np.abs(F[:5]) < 1e-9)  # at rest (x of 1e-304 mm, not exactly 0)
        np.testing.assert_allclose(F[5:], one, rtol=0, atol=1e-9 * np.abs(one).max())
