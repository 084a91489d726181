"""Parameter intervals (fit.intervals) against the truth they must cover.

Records are lab-like: a law-2 device (C 40, alpha 0.3) under the paper's
protocol, 1 kN force noise and 0.01 mm displacement noise, velocity derived
by the reader.  Before the rests got a velocity of 0 the estimates sat
about 0.4% below the truth (the velocity's noise at rest, through a law
with alpha 0.3), several times their scatter.  ``ramped_record`` makes
records another way (not the rig: a cosine-ramped sinusoid with rests,
written as t,d,F by the test itself), as a lab's acceptance test would.
"""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from fvd_bridge.api import calibrate
from fvd_bridge.calibration import Calibration
from fvd_bridge.catalog import catalog
from fvd_bridge.fit import fit_model
from fvd_bridge.fit.intervals import intervals
from fvd_bridge.rig import VirtualDamper, paper
from fvd_bridge.records import ReadOptions, Record, read_record
from fvd_bridge.records.velocity import rest_mask
from lab import lab_from_forces, lab_record

TRUTH = {"C": 40.0, "alpha": 0.3}


def ramped_record(seed: int, tmp_path, rest: float = 0.5) -> Record:
    """A law-2 device (TRUTH) under 40 mm at 500 mm/s, 3 cycles between
    one-cycle cosine ramps, ``rest`` s still before and after, 500 Hz;
    force noise 0.8 kN, displacement noise 0.01 mm; written as t,d,F and read."""
    w, fs = 500.0 / 40.0, 500.0
    T = 2 * np.pi / w
    t = np.arange(0.0, 5 * T, 1 / fs)
    env = np.clip(np.minimum(t, 5 * T - t) / T, 0.0, 1.0)
    d = 40.0 * 0.5 * (1 - np.cos(np.pi * env)) * np.sin(w * t)
    v = np.gradient(d, t, edge_order=2)  # the truth's own velocity: only its force uses it
    still = int(rest * fs)
    t = np.arange(t.size + 2 * still) / fs
    d, v = (np.concatenate([np.zeros(still), x, np.zeros(still)]) for x in (d, v))
    F = TRUTH["C"] * np.sign(v) * np.abs(v) ** TRUTH["alpha"]
    rng = np.random.default_rng(100 + seed)
    path = tmp_path / f"ramped{seed}.csv"
    np.savetxt(path, np.column_stack([t, d + 0.01 * rng.standard_normal(t.size),
                                      F + 0.8 * rng.standard_normal(t.size)]),
               delimiter=",", header="t,d,F", comments="", fmt=("%.4f", "%.5f", "%.4f"))
    return read_record(str(path), ReadOptions(units={"t": "s", "d": "mm", "F": "kN"}))


def coverage(records):
    """(covered per parameter, relative widths, errors of the fits, estimates
    strictly inside) of law 2's fit and intervals on each record."""
    model = catalog().model("2")
    truth = np.array([TRUTH[n] for n in model.names])
    covered, widths, errors, inside = [], [], [], []
    for s, rec in enumerate(records):
        fit = fit_model(model, rec, seed=0)
        iv = intervals(model, rec, fit.values, bounds=fit.bounds, seed=s)
        covered.append((iv.ci95[:, 0] <= truth) & (truth <= iv.ci95[:, 1]))
        widths.append((iv.ci95[:, 1] - iv.ci95[:, 0]) / truth)
        errors.append((fit.values - truth) / iv.stderr)
        inside.append((iv.ci95[:, 0] < fit.values) & (fit.values < iv.ci95[:, 1]))
    return np.array(covered), np.array(widths), np.array(errors), np.array(inside)


def test_intervals_cover_the_truth_on_a_few_lab_records(tmp_path):
    """5 noise seeds of the rig's paper protocol: the estimates are within
    their standard errors of the truth on average, each strictly inside its
    interval, and the intervals cover C and alpha in at least 4 of 5, each
    narrower than 2%."""
    recs = [lab_record(VirtualDamper(C=40.0, alpha=0.3), paper(), 1.0, 0.01, seed=s, tmp_path=tmp_path, name=f"r{s}")
            for s in range(5)]
    covered, widths, errors, inside = coverage(recs)
    assert np.all(np.abs(errors.mean(axis=0)) < 1.0), errors  # mean error below one standard error
    assert inside.all()
    assert covered.sum(axis=0).min() >= 4, covered
    assert widths.max() < 0.02


@pytest.mark.slow
def test_intervals_cover_the_truth_in_17_of_20_ramped_records(tmp_path):
    """The acceptance figure, on records the rig did not make: 20 seeds of
    ``ramped_record``, coverage of C and alpha >= 17, median width under 25%
    of the value, every estimate strictly inside its interval."""
    covered, widths, errors, inside = coverage([ramped_record(s, tmp_path) for s in range(20)])
    assert covered.sum(axis=0).min() >= 17, covered.sum(axis=0)
    assert np.median(widths, axis=0).max() < 0.25
    assert inside.all()
    assert np.all(np.abs(errors.mean(axis=0)) < 1.0), errors.mean(axis=0)


@pytest.mark.slow
def test_a_gaps_interval_covers_its_clearance_on_acceptance_records(tmp_path):
    """The clearance g moves the OF in flat steps, so the replicates search
    it along its line (``fit.intervals``); on 10 noise seeds of an orifice
    with a 1 mm gap under the acceptance protocol (records unlike the
    earthquake test the line search was shaped on) the 95% intervals of g,
    C and alpha cover the truth in at least 8 of 10 (10 of 10 each when
    written), every estimate inside its interval."""
    from fvd_bridge.rig import acceptance

    truth = {"C": 20.0, "alpha": 0.5, "gap.g": 1.0}
    model = catalog().model("2+gap")
    hits = dict.fromkeys(truth, 0)
    for s in range(10):
        rec = lab_record(VirtualDamper(C=20.0, alpha=0.5, gap=1.0), acceptance(cycles=2), 1.0, 0.01, seed=200 + s,
                         tmp_path=tmp_path, name=f"gap{s}")
        fit = fit_model(model, rec, seed=0)
        iv = intervals(model, rec, fit.values, bounds=fit.bounds, seed=s)
        assert np.all((iv.ci95[:, 0] < fit.values) & (fit.values < iv.ci95[:, 1]))
        for name, value in truth.items():
            lo, hi = iv.ci95[model.names.index(name)]
            hits[name] += bool(lo <= value <= hi)
    assert min(hits.values()) >= 8, hits


def test_rests_take_no_force_from_the_velocity_noise(tmp_path):
    """The rests of a ramped record (0.5 s before and after) are found and
    get a velocity of 0, and law 2's fit on it is within its scatter of the
    truth: before, the rests' velocity noise pulled C down 1.6%."""
    rec = ramped_record(0, tmp_path)
    rests = rec.provenance["velocity"]["rests_s"]
    assert rests[0][0] == 0.0 and 0.45 <= rests[0][1] <= 0.55 and rests[-1][1] == pytest.approx(rec.t[-1], abs=0.01)
    fit = fit_model(catalog().model("2"), rec, seed=0)
    assert fit.values[0] == pytest.approx(TRUTH["C"], rel=0.004)
    still = rest_mask(rec)  # the rests' samples are those of zero velocity, in a slice of the record too
    assert still.sum() > 400 and np.array_equal(still, (rec.v == 0.0) & (rec.a == 0.0))
    part = rec.slice(100, rec.n - 50)
    assert np.array_equal(rest_mask(part), still[100:rec.n - 50])


def test_law8_names_what_is_not_identified_and_gives_the_product(tmp_path):
    """Law 8's mu and N trade off (only mu*N acts): the intervals say so and
    the product gets an interval around the slip force of the truth."""
    model = catalog().model("8")
    truth = np.array([0.25, 30.0, 0.5, 330.0])  # slip force mu*N = 165 kN
    rig = paper(cycles=3, dt=0.005)
    t = rig.times()
    d, v, a = rig.motion(t)
    F = model.force(Record(t, d, np.zeros_like(t), v, a), truth[None, :])[0]
    rec = lab_from_forces(t, d, F, 1.0, 0.005, seed=0, tmp_path=tmp_path, name="law8")
    cal = calibrate(rec, model, runs=1)
    lines = "\n".join(cal.interval_lines())
    assert "not identified: mu: only mu*N acts" in lines and "not identified: N: only mu*N acts" in lines
    assert cal.intervals.parameters["mu"].ci95 == pytest.approx(tuple(cal.bounds[2]))
    product, (value, _) = cal.intervals.derived["mu*N"], cal.derived()["mu*N"]
    assert value == pytest.approx(165.0, rel=0.02)
    assert product.ci95[0] < value < product.ci95[1]


def test_intervals_travel_in_the_calibration_file(tmp_path):
    """stderr, ci95 per parameter and the correlation matrix are written and read back."""
    rec = lab_record(VirtualDamper(C=40.0, alpha=0.3), paper(cycles=3), 1.0, 0.005, seed=1, tmp_path=tmp_path, name="r")
    cal = calibrate(rec, "2", runs=1, intervals=8)
    path = cal.save(str(tmp_path / "law2.yaml"))
    raw = yaml.safe_load(open(path))
    for name in ("C", "alpha"):
        lo, hi = raw["parameters"][name]["ci95"]
        assert lo < raw["parameters"][name]["value"] + 3 * raw["parameters"][name]["stderr"] and lo < hi
    assert raw["correlation"]["names"] == ["C", "alpha"] and raw["intervals"]["replicates"] == 8
    back = Calibration.load(path)
    assert back.interval_lines() == cal.interval_lines()
    assert calibrate(rec, "2", runs=1, intervals=0).intervals is None


def test_the_bootstraps_differentiator_is_savgol_filter_at_each_samples_window():
    """with_windows (gathered coefficients, scipy's savgol_coeffs at each
    sample's position) equals scipy's savgol_filter (mode 'interp') run over
    the whole rows at each window and picked per sample, ends included: the
    windows a record's derivation chose, on 3 noisy rows with a rest."""
    from fvd_bridge.records.velocity import _savgol, derive, with_windows

    rng = np.random.default_rng(0)
    t = np.arange(3000) * 0.002
    d = 40.0 * np.sin(12.5 * t) * (t > 0.5)
    der = derive(d + 0.01 * rng.standard_normal(t.size), 0.002)
    D = d + 0.01 * rng.standard_normal((3, t.size))
    for deriv, window in ((0, der.v_window), (1, der.v_window), (2, der.a_window)):
        assert np.unique(window).size > 3 and window[0] > window[t.size // 2]  # long at rest, short in motion
        ref = np.zeros_like(D)
        for w in np.unique(window):
            ref[:, window == w] = _savgol(D, int(w), 3, deriv, 0.002)[:, window == w]
        got = with_windows(D, 0.002, window, 3, deriv)
        assert np.max(np.abs(got - ref)) <= 1e-9 * np.max(np.abs(ref))  # two sums of the same products


@pytest.mark.parametrize("law", ["2", "9"])
def test_the_replicates_newton_steps_reach_their_own_refits(tmp_path, law):
    """A second algorithm: the k-step bootstrap's Newton steps on each
    replicate (``newton_refits``) against that replicate's full local refit
    (``polish_model``, eq. 18's L1 by the soft-L1 continuation), 20
    replicates of a ramped lab record fitted with law 2 and law 9.  The two
    estimators differ by the soft-L1 scale (5% of the force noise) and the
    stopping rules (the steps' STEP_TOL of the spread, the refit's
    L1_TOLERANCE), each a small share of the replicates' spread: their means
    agree within a quarter of it and their spreads within 25%."""
    from fvd_bridge.fit.api import polish_model
    from fvd_bridge.fit.intervals import _replicates, newton_refits, smoothed
    from fvd_bridge.fit.layout import Layout
    from fvd_bridge.records.cycles import force_noise

    rec = ramped_record(3, tmp_path)
    model = catalog().model(law)
    fit = fit_model(model, rec, seed=0)
    clean = smoothed(rec)
    F_clean = model.force(clean, fit.values[None, :])[0]
    replicas = _replicates(rec, F_clean, clean, force_noise(rec.F), 20, np.random.default_rng(5))
    newton, _ = newton_refits(model, Layout(model, (rec.name,)), replicas, fit.values, [force_noise(rec.F)],
                              fit.bounds)
    refits = np.array([polish_model(model, r, fit.values)[0] for r in replicas])
    spread = refits.std(axis=0, ddof=1)
    assert np.all(np.abs(newton.mean(axis=0) - refits.mean(axis=0)) < 0.25 * spread)
    assert np.all(np.abs(newton.std(axis=0, ddof=1) / spread - 1.0) < 0.25)
    assert np.all(np.abs(refits.mean(axis=0) - fit.values) > 0.5 * spread)  # the bias the steps must follow
