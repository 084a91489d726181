"""The virtual test rig: exactness against law 2, energy, each effect's
fingerprint, an independent integrator, reproducibility, series, CLI.

The physics tests use ``simulate`` / ``trace`` in memory, whose v and a are
the exact imposed ones and whose d is exact (noise None): they compare the
rig with closed forms and other integrators, where a derived velocity's
noise and bias would only blur the check. Records written and read back
(write_series, the CLI, tests/lab.py) carry the default 0.005 mm
displacement noise and the tool's derived velocity, like a lab's."""

from __future__ import annotations

import math
import os
import warnings

import numpy as np
import pytest
import yaml
from scipy.integrate import quad, solve_ivp
from scipy.optimize import brentq

from fvd_bridge.cli import main
from fvd_bridge.errors import InputError
from fvd_bridge.laws import get_law
from fvd_bridge.records import RecordWarning, read_record
from lab import lab_from_forces, lab_record
from fvd_bridge.rig import (VirtualDamper, Noise, acceptance, cycle_bounds, demo_series, energy_per_cycle, history,
                            loop_area, orifice_energy_per_cycle, paper, production_series, read_history,
                            read_truth, simulate, trace, write_series)

C0, A0 = 45.4, 0.3  # the paper's design: 292 kN at 500 mm/s


@pytest.fixture(scope="module")
def prot():
    return paper()


# ------------------------------------------------------------------ protocols

def test_paper_protocol_is_tapered_and_analytic(prot):
    t = prot.times()
    d, v, a = prot.motion(t)
    assert prot.dt == 0.002 and t.size == prot.n
    assert abs(np.max(np.abs(v)) - 500.0) < 0.5 and abs(np.max(np.abs(d)) - 40.0) < 0.01
    assert d[0] == v[0] == 0.0 and abs(d[-1]) < 1e-9 and abs(v[-1]) < 1e-9
    # v and a are the exact derivatives of d (central differences on a fine grid)
    h = 1e-6
    tt = np.linspace(0.0, prot.duration, 2001)[1:-1]
    dp, vp, _ = prot.motion(tt + h)
    dm, vm, _ = prot.motion(tt - h)
    _, v0, a0 = prot.motion(tt)
    assert np.max(np.abs((dp - dm) / (2 * h) - v0)) < 1e-4 * 500
    assert np.max(np.abs((vp - vm) / (2 * h) - a0)) < 1e-4 * 500 * 12.5
    # the taper starts smoothly: no jump in a at the start and the end of the fade-in
    for tb in prot.breakpoints():
        lo, hi = prot.motion(np.array([tb - 1e-9, tb + 1e-9]))[2]
        assert abs(hi - lo) < 1e-3


def test_acceptance_protocol_levels():
    p = acceptance()
    assert [s.peak_velocity for s in p.segments] == pytest.approx([5.0, 125.0, 250.0, 375.0, 500.0])
    freqs = [s.frequency for s in p.segments[1:]]  # fixed amplitude: frequency follows the level
    assert freqs == pytest.approx([freqs[0] * k for k in (1, 2, 3, 4)])
    assert all(s.amplitude == 20.0 for s in p.segments[1:]) and p.segments[0].amplitude < 2.0


def test_history_protocol_from_csv(tmp_path):
    t = np.arange(0, 3.0, 0.005)
    d = 10 * np.sin(2 * np.pi * t) * np.minimum(1.0, t)
    path = tmp_path / "h.csv"
    np.savetxt(path, np.column_stack([t, d]), delimiter=",", header="t,d", comments="")
    p = read_history(str(path))
    dd, vv, _ = p.motion(p.times())
    assert np.max(np.abs(dd - d)) < 1e-9
    assert np.max(np.abs(vv - np.gradient(d, t))) < 0.5
    rec = simulate(VirtualDamper(C=10.0, alpha=0.5), p)
    assert rec.n == t.size
    with pytest.raises(InputError, match="t"):
        history([0, 1, 1, 2], [0, 1, 2, 3])


# ------------------------------------------------------------- the orifice law

@pytest.mark.parametrize("alpha", [0.3, 1.0, 1.7])
def test_orifice_only_equals_law2(prot, alpha):
    dev = VirtualDamper(C=C0, alpha=alpha)
    for p in (prot, acceptance(cycles=1)):
        rec = simulate(dev, p)
        F2 = get_law(2).force(rec.d, rec.v, rec.dt, np.array([[C0, alpha]]))[0]
        assert np.max(np.abs(rec.F - F2)) <= 1e-9 * np.max(np.abs(F2))


def test_energy_per_cycle_pure_orifice(prot):
    seg = prot.segments[0]
    A, om = seg.amplitude, seg.omega
    closed = orifice_energy_per_cycle(C0, A0, A, om)
    numeric = quad(lambda t: C0 * abs(A * om * math.cos(om * t)) ** (1 + A0), 0, 2 * math.pi / om,
                   limit=200, points=[math.pi / (2 * om), 3 * math.pi / (2 * om)])[0]
    assert closed == pytest.approx(numeric, rel=1e-9)
    assert orifice_energy_per_cycle(2.0, 1.0, A, om) == pytest.approx(math.pi * 2.0 * A * A * om)
    tr = trace(VirtualDamper(C=C0, alpha=A0), prot)
    bounds = cycle_bounds(tr["d"])
    energies = energy_per_cycle(tr["d"], tr["F"])
    assert energies.size == len(bounds) >= 10
    steady = bounds[1:-1]
    for (a, b), w in zip(steady, energies[1:-1]):
        assert w == pytest.approx(loop_area(tr["d"][a:b + 1], tr["F"][a:b + 1]), rel=2e-4)
        assert w == pytest.approx(closed, rel=2e-4)
        # the rig's own orifice energy (sample maxima are within dt/2 of the reversals)
        assert 1e6 * (tr["E"][b] - tr["E"][a]) == pytest.approx(closed, rel=2e-5)


# --------------------------------------------------------------- Maxwell part

def test_series_stiffness_lag_and_reversal_force():
    dt = 2 * math.pi * 40.0 / 500.0 / 256
    prot = paper(dt=dt, rest=25 * dt)  # samples on the reversals
    rigid = trace(VirtualDamper(C=C0, alpha=A0), prot)
    soft = trace(VirtualDamper(C=C0, alpha=A0, Ks=100.0), prot)
    steady = cycle_bounds(soft["d"])[2:-2]
    for a, _ in steady:  # a = a displacement maximum (reversal)
        assert abs(rigid["F"][a]) < 0.01 * 292
        assert soft["F"][a] > 0.25 * 292  # force still in tension at the reversal
    # the force lags: its zero crossing comes after the velocity's
    a, b = steady[0]
    i_v = a + np.flatnonzero(np.diff(np.sign(soft["v"][a:b])) != 0)[0]
    i_f = a + np.flatnonzero(np.diff(np.sign(soft["F"][a:b])) != 0)[0]
    assert i_f > i_v + 2
    # loop energy = orifice energy (no friction, no heating; the spring stores none per cycle)
    for (a, b), w in zip(steady, energy_per_cycle(soft["d"], soft["F"])[2:-2]):
        assert w == pytest.approx(1e6 * (soft["E"][b] - soft["E"][a]), rel=1e-3)
    # a very stiff spring is nearly rigid while moving, except right at the
    # reversals, where |v|^alpha is too steep for any finite Ks to follow (at
    # rest the force relaxes only as dS/dt ~ -Ks (S/C)^(1/alpha))
    p3 = paper(cycles=3)
    rigid, stiff = trace(VirtualDamper(C=C0, alpha=A0), p3), trace(VirtualDamper(C=C0, alpha=A0, Ks=1e5), p3)
    moving = np.abs(rigid["v"]) > 5.0
    assert np.mean(np.abs(stiff["F"] - rigid["F"])[moving]) < 1e-3 * 292


def test_linear_maxwell_matches_closed_form():
    """alpha = 1: F/C + dF/dt/Ks = v has the steady state
    F = C A w (cos wt + (C w / Ks) sin wt) / (1 + (C w / Ks)^2)."""
    p = paper(cycles=4)
    C, Ks = 0.6, 100.0
    tr = trace(VirtualDamper(C=C, alpha=1.0, Ks=Ks), p)
    seg, t_s = p.segments[0], p.starts[0]
    om, A = seg.omega, seg.amplitude
    tau = tr["t"] - t_s
    lam = C * om / Ks
    exact = C * A * om * (np.cos(om * tau) + lam * np.sin(om * tau)) / (1 + lam * lam)
    m = (tau > 1.0 / seg.frequency) & (tau < seg.duration - 0.5 / seg.frequency)
    assert np.max(np.abs(tr["F"][m] - exact[m])) < 1e-6 * np.max(np.abs(exact))


def _reference_series_force(dev, p, rtol=1e-7):
    """Independent check: scipy Radau on (S, E) with the internal inverse by
    brentq, restarted at each contact event of the gap."""
    def f_int(u, hf):
        A = 1 + dev.asymmetry if u > 0 else 1 - dev.asymmetry
        return hf * dev.C * A * math.copysign(abs(u) ** dev.alpha, u) + dev.friction * math.tanh(u / dev.v_friction)

    def v_o(S, hf):
        if S == 0:
            return 0.0
        sg, hi = math.copysign(1.0, S), 1.0
        while sg * f_int(sg * hi, hf) < abs(S):
            hi *= 2
        return sg * brentq(lambda u: sg * f_int(sg * u, hf) - abs(S), 0, hi, xtol=1e-14, rtol=1e-14)

    ts = p.times()
    tr = trace(dev, p)
    change = np.flatnonzero(np.diff(tr["contact"].astype(int)) != 0)
    # contact events between samples: bisect the analytic motion like the play operator would
    from fvd_bridge.rig.simulate import play
    fine = p.t0 + p.dt * np.arange((ts.size - 1) * 8 + 1) / 8
    d_f, v_f, _ = p.motion(fine)
    pl = play(p, dev.gap, fine, d_f, v_f)
    assert pl.events().size >= change.size
    bounds = np.concatenate([[ts[0]], pl.events(), [ts[-1]]])
    S, E, y0 = np.zeros(ts.size), np.zeros(ts.size), [0.0, 0.0]
    for t0, t1 in zip(bounds[:-1], bounds[1:]):
        contact = pl.side[pl.piece(np.array([0.5 * (t0 + t1)]))[0]] != 0

        def rhs(t, y):
            hf = math.exp(-dev.heating * y[1])
            vy = p.motion(np.array([t]))[1][0] if contact else 0.0
            u = v_o(y[0], hf)
            A = 1 + dev.asymmetry if u > 0 else 1 - dev.asymmetry
            return [dev.Ks * (vy - u), hf * dev.C * A * abs(u) ** (1 + dev.alpha) * 1e-6]

        m = (ts >= t0) & (ts < t1)
        sol = solve_ivp(rhs, (t0, t1), y0, method="Radau", rtol=rtol, atol=[1e-8, 1e-14],
                        dense_output=True, max_step=p.dt)
        S[m], E[m] = sol.sol(ts[m])
        y0 = list(sol.y[:, -1])
    S[-1], E[-1] = y0
    return tr, S, E


def test_maxwell_against_independent_radau():
    p = paper(cycles=1, rest=0.02)
    dev = VirtualDamper(C=C0, alpha=A0, Ks=150.0, friction=3.0, heating=0.1, asymmetry=0.015, gap=0.2)
    tr, S, E = _reference_series_force(dev, p)
    assert np.max(np.abs(tr["F_series"] - S)) < 2e-3  # kN, on a 300 kN loop
    assert np.max(np.abs(tr["E"] - E)) < 1e-6 * E[-1]


def test_maxwell_converges_with_substeps(prot):
    dev = VirtualDamper(C=C0, alpha=A0, Ks=150.0, friction=3.0, heating=0.1, asymmetry=0.015)
    coarse, fine = trace(dev, prot), trace(dev, prot, substeps=64)
    assert coarse["substeps"] < 64
    assert np.max(np.abs(coarse["F"] - fine["F"])) < 1e-3


# ------------------------------------------------------------- other effects

def test_heating_drops_peaks_by_expected_factor(prot):
    theta = 0.3  # 1/MJ
    tr = trace(VirtualDamper(C=C0, alpha=A0, heating=theta), prot)
    seg, t_s = prot.segments[0], prot.starts[0]
    A, om, T = seg.amplitude, seg.omega, 1.0 / seg.frequency
    peaks = np.array([tr["F"][a:b].max() for a, b in cycle_bounds(tr["d"])])
    assert np.all(np.diff(peaks) < 0) and peaks.size == 10
    # tension peaks at the upward zero crossings t_s + T (k + 1); W0 = 1e-6 int C|v|^(1+alpha) dt
    v_of = lambda t: prot.motion(np.array([t]))[1][0]
    w_first = quad(lambda t: C0 * abs(v_of(t)) ** (1 + A0) * 1e-6, t_s, t_s + T, limit=200)[0]
    wc = orifice_energy_per_cycle(C0, A0, A, om) * 1e-6
    expected = C0 * (A * om) ** A0 / (1 + theta * (w_first + wc * np.arange(10)))
    assert peaks == pytest.approx(expected, rel=1e-4)
    assert 0.85 < peaks[-1] / peaks[0] < 0.95


def test_gap_zero_force_plateau_of_the_right_width(prot):
    g = 2.0
    tr = trace(VirtualDamper(C=C0, alpha=A0, gap=g), prot)
    d, F = tr["d"], tr["F"]
    assert np.all(np.abs(tr["y"] - d) <= g / 2 + 1e-9)
    dense = np.linspace(0, prot.duration, 400001)
    dd = prot.motion(dense)[0]
    checked = 0
    for a, _ in cycle_bounds(d)[1:-1]:  # a: sample at a displacement maximum
        zero = np.flatnonzero(F == 0.0)
        after = zero[zero >= a - 5]
        run_end = after[np.flatnonzero(np.diff(after) > 1)[0]] if np.any(np.diff(after) > 1) else after[-1]
        near = np.abs(dense - tr["t"][a]) < 0.05
        d_max = dd[near].max()
        assert d_max - d[run_end] <= g + 1e-9  # still in the gap at the last zero-force sample
        assert d_max - d[run_end + 1] >= g - 1e-9  # in contact at the next one
        assert np.ptp(tr["y"][a + 1:run_end + 1]) < 1e-12  # the body stands still
        checked += 1
    assert checked >= 8


def test_asymmetry_friction_accumulator_mass(prot):
    tr0 = trace(VirtualDamper(C=C0, alpha=A0), prot)
    tr = trace(VirtualDamper(C=C0, alpha=A0, asymmetry=0.02, friction=3.0, Kp=0.2, preload=1.5, mass=50.0), prot)
    assert tr["F"][0] == pytest.approx(1.5)  # at rest: the preload only
    assert np.max(tr["F_orifice"]) == pytest.approx(1.02 * np.max(tr0["F"]), rel=1e-12)
    assert np.min(tr["F_orifice"]) == pytest.approx(0.98 * np.min(tr0["F"]), rel=1e-12)
    moving = np.abs(tr["v"]) > 50
    assert np.allclose(np.abs(tr["F_friction"][moving]), 3.0, rtol=1e-9)
    assert np.allclose(tr["F_parallel"], 0.2 * tr["d"] + 1.5)
    assert np.allclose(tr["F_inertia"], 50.0 * tr["a"] * 1e-6)
    assert np.allclose(tr["F"], tr["F_orifice"] + tr["F_friction"] + tr["F_parallel"] + tr["F_inertia"])


# ----------------------------------------------------- noise, seeds, series

def test_seeded_noise_is_reproducible(prot):
    dev = VirtualDamper(C=C0, alpha=A0, Ks=150.0)
    clean = simulate(dev, prot)
    a = simulate(dev, prot, Noise(force=1.0, displacement=0.01), seed=7)
    b = simulate(dev, prot, Noise(force=1.0, displacement=0.01), seed=7)
    c = simulate(dev, prot, Noise(force=1.0, displacement=0.01), seed=8)
    assert np.array_equal(a.F, b.F) and np.array_equal(a.d, b.d)
    assert not np.array_equal(a.F, c.F)
    assert np.std(a.F - clean.F) == pytest.approx(1.0, rel=0.06)
    assert np.std(a.d - clean.d) == pytest.approx(0.01, rel=0.06)
    assert np.array_equal(a.v, clean.v)  # v stays the exact imposed velocity
    assert a.provenance["rig"]["Ks"] == 150.0 and a.provenance["noise"]["force_kN"] == 1.0
    assert a.d_noise == 0.01 and not np.any(a.v_noise) and not np.any(a.a_noise)
    # the default noise is lab-like: 0.005 mm on d; no noise at all is noise=None (the exact truth)
    assert Noise() == Noise(0.0, 0.005) and clean.d_noise == 0.0
    lab = simulate(dev, prot, Noise(), seed=7)
    assert np.std(lab.d - clean.d) == pytest.approx(0.005, rel=0.06) and np.array_equal(lab.F, clean.F)


def test_production_series_statistics():
    nominal = VirtualDamper(C=C0, alpha=A0, Ks=150.0, friction=3.0, asymmetry=0.02)
    scatter = {"C": 0.10, "alpha": 0.05, "Ks": 0.2}
    devs = production_series(2000, nominal, scatter, seed=1)
    lc = np.log([d.C / C0 for d in devs])
    assert abs(lc.mean()) < 3 * 0.10 / math.sqrt(2000) and lc.std() == pytest.approx(0.10, rel=0.08)
    al = np.array([d.alpha for d in devs])
    assert abs(al.mean() - A0) < 3 * 0.015 / math.sqrt(2000) and al.std() == pytest.approx(0.015, rel=0.08)
    assert np.log([d.Ks / 150.0 for d in devs]).std() == pytest.approx(0.2, rel=0.08)
    assert all(d.friction == 3.0 and d.asymmetry == 0.02 for d in devs)  # not scattered
    assert production_series(5, nominal, scatter, seed=1) == devs[:5]
    assert production_series(5, nominal, scatter, seed=2) != devs[:5]
    assert all(d.Ks is None for d in production_series(3, VirtualDamper(), {"Ks": 0.2}, seed=0))
    with pytest.raises(InputError, match="bogus"):
        production_series(2, nominal, {"bogus": 0.1})


def test_demo_series_resembles_the_paper(prot):
    devs = demo_series(seed=0)
    assert len(devs) == 5 and devs == demo_series(seed=0)
    peaks = [np.max(np.abs(simulate(d, prot).F)) for d in devs]
    assert 255 < min(peaks) and max(peaks) < 345
    for d in devs:
        assert 100 <= d.Ks <= 250 and 1.5 <= d.friction <= 4.5 and abs(d.alpha - 0.3) < 0.03


@pytest.mark.parametrize("bad,name", [({"C": -1}, "C"), ({"alpha": 0}, "alpha"), ({"alpha": 2.5}, "alpha"),
                                      ({"gap": -0.1}, "gap"), ({"Ks": -5}, "Ks"), ({"asymmetry": 1.0}, "asymmetry"),
                                      ({"mass": -1}, "mass"), ({"heating": float("nan")}, "heating")])
def test_device_refuses_nonsense(bad, name):
    with pytest.raises(InputError, match=rf"\b{name}\b"):
        VirtualDamper(**bad)
    assert VirtualDamper(Ks=float("inf")).rigid


# ------------------------------------------------------------- writing, CLI

def test_write_series_reads_back(tmp_path, prot):
    devs = production_series(2, VirtualDamper(C=C0, alpha=A0, Ks=150.0), {"C": 0.05}, seed=3)
    paths = write_series(str(tmp_path), devs, prot, Noise(0.5), seed=11, with_velocity=True)
    assert [os.path.basename(p) for p in paths] == ["device_01.csv", "device_02.csv", "truth.yaml"]
    assert sorted(os.listdir(tmp_path)) == ["device_01.csv", "device_01.yaml", "device_02.csv", "device_02.yaml",
                                            "truth.yaml"]  # each record with its unit sidecar
    truth = read_truth(str(tmp_path))
    assert truth["devices"] == devs and truth["noise"]["force_kN"] == 0.5
    assert truth["noise"]["displacement_mm"] == 0.005
    for dev, f in zip(devs, truth["files"]):
        with warnings.catch_warnings():
            warnings.simplefilter("error", RecordWarning)  # the sidecar states the units
            rec = read_record(f)
        ref = simulate(dev, prot, Noise(0.5), seed=truth["noise"]["per_device_seeds"][devs.index(dev)])
        assert rec.n == prot.n and np.allclose(rec.F, ref.F, rtol=1e-8, atol=1e-8)
        assert np.allclose(rec.d, ref.d, rtol=1e-8, atol=1e-8)
        assert rec.provenance["velocity"]["method"] == "measured"
        assert rec.provenance["units"] == {"t": "s", "d": "mm", "F": "kN", "v": "mm/s"}
    assert not any(".part" in p for p in os.listdir(tmp_path))


def test_lab_record_derives_velocity_like_a_lab(tmp_path):
    """tests/lab.py: rig or model forces written as CSV t,d,F with the sidecar
    and read back, so v is the tool's derivative of the noisy d."""
    p = acceptance(cycles=2)
    dev = VirtualDamper(C=C0, alpha=A0)
    rec = lab_record(dev, p, 1.0, 0.01, seed=3, tmp_path=tmp_path)
    exact = simulate(dev, p, Noise(1.0, 0.01), seed=3)
    assert sorted(f.name for f in tmp_path.iterdir()) == ["device.csv", "device.yaml"]
    np.testing.assert_allclose(rec.F, exact.F, atol=1e-6)  # the same noise as simulate's
    np.testing.assert_allclose(rec.d, exact.d, atol=1e-8)
    assert rec.provenance["velocity"]["window_chosen"] == "adaptive" and rec.warnings == []
    assert rec.d_noise == pytest.approx(0.01, rel=0.2)
    err = rec.v - exact.v
    assert 0 < np.sqrt(np.mean(err**2)) < 0.005 * 500  # derived, not exact, and close
    assert rec.provenance["truth"]["rig"]["C"] == C0 and rec.provenance["truth"]["seed"] == 3
    t = p.times()
    d, v, _ = p.motion(t)
    other = lab_from_forces(t, d, 2.0 * v, 0.5, 0.0, seed=1, tmp_path=tmp_path, name="linear")
    np.testing.assert_allclose(other.d, d, atol=1e-7)  # no displacement noise asked
    assert np.std(other.F - 2.0 * v) == pytest.approx(0.5, rel=0.06)


def test_write_series_leaves_nothing_on_error(tmp_path, prot, monkeypatch):
    import fvd_bridge.rig.series as series

    calls = []

    def failing(rec, path, **kw):
        calls.append(path)
        if len(calls) == 2:
            raise OSError("disk full")
        return real(rec, path, **kw)

    real = series.write_csv
    monkeypatch.setattr(series, "write_csv", failing)
    with pytest.raises(OSError):
        write_series(str(tmp_path / "out"), production_series(3, VirtualDamper(), {}, 0), paper(cycles=1))
    assert os.listdir(tmp_path) == []  # no out folder, no staging folder beside it


def test_cli_writes_csv_and_truth(tmp_path, capsys):
    out = tmp_path / "rig"
    rc = main(["rig", "--out", str(out), "--devices", "2", "--Ks", "150", "--friction", "2", "--gap", "0.1",
               "--noise", "0.5", "--seed", "4", "--scatter", "0.05", "--cycles", "3"])
    assert rc == 0
    truth = yaml.safe_load(open(out / "truth.yaml"))
    assert truth["units"]["Ks"] == "kN/mm" and len(truth["devices"]) == 2
    assert truth["devices"][0]["parameters"]["gap"] == pytest.approx(0.1, rel=0.3)
    for entry in truth["devices"]:
        rec = read_record(str(out / entry["file"]))
        assert rec.n > 1000 and 200 < np.max(np.abs(rec.F)) < 400
    assert truth["noise"]["displacement_mm"] == 0.005  # the default: lab-like
    rc = main(["rig", "--out", str(tmp_path / "demo"), "--demo", "--protocol", "acceptance", "--cycles", "1"])
    assert rc == 0 and len(os.listdir(tmp_path / "demo")) == 11  # 5 CSV + 5 sidecars + truth.yaml
    rc = main(["rig", "--out", str(tmp_path / "exact"), "--disp-noise", "0", "--cycles", "2"])
    assert rc == 0 and yaml.safe_load(open(tmp_path / "exact" / "truth.yaml"))["noise"]["displacement_mm"] == 0.0


@pytest.mark.parametrize("argv,name", [(["--C", "-1"], "C"), (["--alpha", "3"], "alpha"),
                                       (["--gap", "-1"], "gap"), (["--Ks", "soft"], "Ks"),
                                       (["--protocol", "nope"], "protocol"), (["--devices", "0"], "devices"),
                                       (["--noise", "-2"], "noise"), (["--scatter", "x"], "scatter"),
                                       (["--disp-noise", "-0.1"], "displacement")])
def test_cli_bad_parameters_exit_2(tmp_path, capsys, argv, name):
    rc = main(["rig", "--out", str(tmp_path / "bad")] + argv)
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1 and name in err
    assert not (tmp_path / "bad").exists()
