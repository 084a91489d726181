"""Upper- and lower-bound damper properties of a series (campaign.property_bounds) and
`frame --property-bounds` (frames.property_bounds): the factors against hand-computed values,
a rig series' force bounds against each device's C V^alpha, and the frame's
envelope on a five-device series (upper bound governs the damper force,
lower bound the drift)."""

import csv
import html
import json
import subprocess

import numpy as np
import pytest
import yaml

from conftest import CLI, cli_env
from fvd_bridge.campaign.property_bounds import BoundSettings, combined, scatter_factors
from fvd_bridge.errors import InputError
from fvd_bridge.frames.property_bounds import read_bounds

#: five rig devices of a power-law damper (law 2), 5% scatter of C, small DE settings (a few seconds)
SERIES = {
    "rig": {"devices": 5, "nominal": {"C": 45.4, "alpha": 0.3}, "scatter": {"C": 0.05, "alpha": 0.02},
            "protocol": {"name": "paper", "cycles": 2}, "noise": {"force": 1.0, "displacement": 0.005}, "seed": 3},
    "models": "2", "runs": 1, "seed": 1, "optimizer": "de", "pop": 8, "gens": 30, "jobs": 1, "no_figures": True,
    "intervals": 0, "acceptance": {"velocity": 300}, "out": "series_out",
}


def run(*args, timeout=600):
    return subprocess.run([*CLI, *map(str, args)], capture_output=True, text=True, env=cli_env(), timeout=timeout)


# ------------------------------------------------------------------ the factors
def test_factors_follow_the_rule_by_hand():
    x = [90.0, 100.0, 110.0]  # mean 100, sample sigma 10
    s = BoundSettings()  # spec 0.15, the extreme devices, no aging
    t_min, t_max, note = scatter_factors(x, s)
    assert t_min == pytest.approx(0.9) and t_max == pytest.approx(1.1) and note == ""
    assert combined(t_min, t_max, s) == pytest.approx((0.9 * 0.85, 1.1 * 1.15))
    # aging counted at 75%: (1 + 0.75 x 0.2) and (1 - 0.75 x 0.2)
    aged = BoundSettings(aging_max=1.2, aging_min=0.8)
    assert combined(t_min, t_max, aged) == pytest.approx((0.85 * 0.9 * 0.85, 1.15 * 1.1 * 1.15))
    sigma = BoundSettings(statistic="sigma", k=2.0, spec=0.0)
    assert scatter_factors(x, sigma)[:2] == pytest.approx((0.8, 1.2))
    assert combined(0.8, 1.2, sigma) == pytest.approx((0.8, 1.2))
    # one device: no scatter; a mean that is not positive: no factor, and why
    assert scatter_factors([5.0], s)[:2] == (1.0, 1.0)
    low, high, why = scatter_factors([-1.0, 0.5], s)
    assert np.isnan(low) and np.isnan(high) and "not positive" in why
    low, high, why = scatter_factors([1.0, 10.0], BoundSettings(statistic="sigma", k=3.0))
    assert np.isnan(low) and high > 1 and "not positive" in why


def test_bad_settings_and_bounds_are_one_line():
    for data, says in (({"spec": 1.5}, "bounds.spec"), ({"statistic": "median"}, "bounds.statistic"),
                       ({"colour": 1}, "unknown key 'bounds.colour'"), ({"aging_max": 0.9}, "bounds.aging_max")):
        with pytest.raises(InputError, match=says.replace("(", r"\(")):
            BoundSettings.from_dict(data, "s.yaml")
    for text in ("1.2,0.8", "0.9", "a,b", "0,1.2"):
        with pytest.raises(InputError, match="--property-bounds"):
            read_bounds(text)
    b = read_bounds("0.8,1.25")
    assert (b.factors("9").lambda_min, b.factors("9").lambda_max) == (0.8, 1.25)


# ------------------------------------------------------------------ a rig series
@pytest.fixture(scope="module")
def series(tmp_path_factory):
    folder = tmp_path_factory.mktemp("bounds")
    path = folder / "series.yaml"
    path.write_text(yaml.safe_dump(SERIES, sort_keys=False))
    res = run("campaign", path, "--quiet")
    assert res.returncode == 0, res.stderr[-3000:]
    return folder, folder / "series_out", res


def _device_forces(out, velocity):
    """{device: C V^alpha} [kN] from each device's calibration file: law 2's force at the design velocity."""
    forces = {}
    for p in sorted((out / "params").glob("*/law2.yaml")):
        params = yaml.safe_load(p.read_text())["parameters"]
        value = {k: (v["value"] if isinstance(v, dict) else v) for k, v in params.items()}
        forces[p.parent.name] = value["C"] * velocity ** value["alpha"]
    return forces


def test_campaign_writes_bounds_from_the_series_scatter(series):
    folder, out, res = series
    b = json.loads((out / "bounds.json").read_text())
    assert b["settings"] == {"spec": 0.15, "statistic": "extremes", "k": 2.0, "aging_max": 1.0, "aging_min": 1.0}
    force = next(r for r in b["models"]["2"]["rows"] if r["quantity"] == "F(V)")
    F = _device_forces(out, 300.0)
    assert len(F) == 5
    x = np.array(list(F.values()))
    # the force at the sampled peak velocity: C V^alpha to the sampling of the sinusoid
    assert force["nominal"] == pytest.approx(x.mean(), rel=2e-3)
    assert force["lambda_max"] == pytest.approx(x.max() / x.mean() * 1.15, rel=2e-3)
    assert force["lambda_min"] == pytest.approx(x.min() / x.mean() * 0.85, rel=2e-3)
    assert force["lower"] < x.min() and force["upper"] > x.max()  # every device inside its bounds
    # the nominal device: the force nearest the mean
    assert b["models"]["2"]["nominal_device"] == min(F, key=lambda d: abs(F[d] - x.mean()))
    rows = list(csv.DictReader(open(out / "bounds.csv")))
    assert [r["quantity"] for r in rows] == ["F(V)", "C", "alpha"]
    assert "Upper and lower bounds" in res.stdout and "F(V) [kN]" in res.stdout
    page = (out / "report.html").read_text()
    assert "upper- and lower-bound properties" in page and "18.2.4.5" in page
    start = page.index("upper- and lower-bound properties")
    table = page[start:page.index("</table>", start)]
    numbers = [c.split("</td>")[0] for c in table.split("<td>")[1:]]
    digits = [len(n.replace(".", "").lstrip("0")) for n in numbers if n[:1].isdigit()]
    assert len(digits) >= 3 * 7 and max(digits) <= 6  # every number rounded for people


#: calibrate's options for the campaign's settings (SERIES): the same fits, seed for seed
SERIES_OPTIONS = ("--laws", "2", "--runs", "1", "--seed", "1", "--optimizer", "de", "--pop", "8", "--gens", "30",
                  "--jobs", "1", "--no-figures", "--intervals", "0", "--quiet")


def test_calibrate_of_the_series_writes_the_campaigns_bounds(series, tmp_path):
    """calibrate on the campaign's records with its settings (the design velocity its acceptance's) writes the
    campaign's bounds.json and bounds.csv, and frame --property-bounds reads calibrate's folder as it reads the
    campaign's."""
    from fvd_bridge.calibration import Calibration
    from fvd_bridge.frames.property_bounds import nominal_ratio

    folder, out, _ = series
    records = sorted((out / "records").glob("device_*.csv"))
    cal = tmp_path / "cal"
    res = run("calibrate", *records, *SERIES_OPTIONS, "--design-velocity", "300", "--out", cal)
    assert res.returncode == 0, res.stderr[-3000:]
    assert json.loads((cal / "bounds.json").read_text()) == json.loads((out / "bounds.json").read_text())
    assert (cal / "bounds.csv").read_text() == (out / "bounds.csv").read_text()
    assert "Upper and lower bounds at the design velocity V = 300 mm/s" in res.stdout and "bounds.json" in res.stdout
    mine, theirs = read_bounds(str(cal)), read_bounds(str(out))
    assert mine.models == theirs.models and mine.motion == theirs.motion and set(mine.models) == {"2"}
    # the damper a frame brings to the series' nominal force: F_nominal / (C V^alpha) of its device
    F = _device_forces(cal, 300.0)
    nominal = mine.factors("2").nominal_force
    assert nominal == pytest.approx(np.mean(list(F.values())), rel=2e-3)
    device = Calibration.load(str(cal / "params" / "device_02" / "law2.yaml"))
    assert nominal_ratio(mine, device) == pytest.approx(nominal / F["device_02"], rel=2e-3)


def test_calibrate_of_one_device_says_its_bounds_in_one_line(series, tmp_path):
    """One device: no scatter (lambda_test = 1), the specification's 0.85 and 1.15 alone, said in one line;
    a campaign file names acceptance.velocity for the design velocity."""
    from fvd_bridge.commands.campaign import read_campaign_file

    folder, out, _ = series
    one = tmp_path / "one"
    res = run("calibrate", out / "records" / "device_04.csv", *SERIES_OPTIONS, "--out", one)
    assert res.returncode == 0, res.stderr[-3000:]
    said = [line for line in res.stdout.splitlines() if "bounds" in line and "wrote" not in line]
    assert len(said) == 1 and said[0].startswith("bounds.json: one device") and "0.85 and 1.15" in said[0], said
    force = next(r for r in json.loads((one / "bounds.json").read_text())["models"]["2"]["rows"]
                 if r["quantity"] == "F(V)")
    assert (force["test_min"], force["test_max"]) == (1.0, 1.0)
    assert (force["lambda_min"], force["lambda_max"]) == pytest.approx((0.85, 1.15))
    assert force["nominal"] == pytest.approx(_device_forces(one, 500.0)["device_04"], rel=2e-3)  # the default V
    f = read_bounds(str(one)).factors("2")
    assert (f.lambda_min, f.lambda_max) == pytest.approx((0.85, 1.15))
    path = tmp_path / "v.yaml"
    path.write_text(yaml.safe_dump({**SERIES, "design_velocity": 300}))
    with pytest.raises(InputError, match=r"design_velocity.*acceptance: \{velocity: V\}"):
        read_campaign_file(str(path))


def test_a_model_fitted_per_test_has_no_bounds_and_says_why(tmp_path):
    """A parameter fitted per test: the force at the design velocity is a test's, so the series has no bounds of
    that model; bounds.json says why and frame --property-bounds repeats it (no fit needed: the model is left
    out first)."""
    from fvd_bridge import Record
    from fvd_bridge.campaign import property_bounds as bounds
    from fvd_bridge.campaign.acceptance import Acceptance
    from fvd_bridge.campaign.runner import CampaignSettings
    from fvd_bridge.text.property_bounds import format_bounds

    t = np.arange(0, 4, 0.01)
    rec = Record.from_arrays(t, 20 * np.sin(2 * np.pi * t), 50 * np.cos(2 * np.pi * t))
    cs = CampaignSettings(specs=("2",), per_test=((None, "alpha"),))
    b = bounds.compute({"devices": [rec.name], "models": {"2": {}}}, [rec], cs, Acceptance(), BoundSettings())
    assert b["models"] == {} and "alpha fitted per test" in b["skipped"]["2"]
    assert "no bounds: alpha fitted per test" in format_bounds(b)
    bounds.write(str(tmp_path), b)
    with pytest.raises(InputError, match="no model with force factors.*alpha fitted per test"):
        read_bounds(str(tmp_path))


def test_a_bad_bounds_key_is_refused_before_any_work(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump({**SERIES, "bounds": {"spec": 2}}))
    res = run("campaign", path, "--quiet")
    assert res.returncode == 2 and "bounds.spec" in res.stderr and len(res.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "series_out").exists()


# ------------------------------------------------------------------ the frame
def _frame(shared_dir, out, *args):
    return run("frame", *args, "--record", shared_dir / "records" / "elcentro_1940_NS_2688pts_g_dt0.02.dat",
               "--duration", "8", "--out", out, "--no-figures", "--quiet")


def test_frame_bounds_on_a_five_device_series(series, shared_dir, tmp_path):
    """The acceptance: the upper-bound damper force is the highest of the three and the lower-bound
    drift the largest, or the page says why not."""
    folder, out, _ = series
    fr = tmp_path / "fr"
    res = _frame(shared_dir, fr, out, "--property-bounds", out)
    assert res.returncode == 0, res.stderr[-3000:]
    summary = json.loads((fr / "frame_summary.json").read_text())
    bounds = json.loads((out / "bounds.json").read_text())
    force = next(r for r in bounds["models"]["2"]["rows"] if r["quantity"] == "F(V)")
    cases = [c for c in summary["cases"] if c["model"]]
    assert len(cases) == 15 and {c["bound"] for c in cases} == {"nominal", "upper", "lower"}
    # each device brought to the series' nominal force, then x lambda_max, x lambda_min
    F = _device_forces(out, 300.0)
    for c in cases:
        lam = {"nominal": 1.0, "upper": force["lambda_max"], "lower": force["lambda_min"]}[c["bound"]]
        assert c["force_factor"] == pytest.approx(force["nominal"] / F[c["device"]] * lam, rel=2e-3)
    env = summary["bounds"]["envelope"]["2"]
    peak = {b: {q: max(c["quantities"][q] for c in cases if c["bound"] == b) for q in ("drift", "force")}
            for b in ("nominal", "upper", "lower")}
    for q in ("drift", "force"):
        assert env[q]["envelope"] == pytest.approx(max(p[q] for p in peak.values()))
        assert env[q]["governing"] == max(peak, key=lambda b: peak[b][q])
    page = html.unescape((fr / "report.html").read_text())
    line = next(x for x in summary["verdict_lines"] if x.startswith("bounds, law 2: envelope"))
    assert line in page and line in res.stdout
    if env["force"]["governing"] != "upper" or env["drift"]["governing"] != "lower":
        assert "does not give the largest" in page  # the page says why not
    else:
        assert peak["upper"]["force"] > peak["nominal"]["force"] > peak["lower"]["force"]
        assert peak["lower"]["drift"] > peak["nominal"]["drift"] > peak["upper"]["drift"]
        assert "(the upper bound governs" in line and "peak interstory drift" in line
    # the nominal's spread stays the series' (the bounds are not series scatter)
    assert sorted(summary["series"]["2"]["devices"]) == sorted(F)


def test_unit_factors_change_nothing(series, shared_dir, tmp_path):
    """--property-bounds 1,1: the three dampers are one and the same, so are their responses; given by its old
    name --bounds (calibrate's search box), as old command lines give it, with a one-line note."""
    folder, out, _ = series
    fr = tmp_path / "one"
    res = _frame(shared_dir, fr, out / "params" / "device_02" / "law2.yaml", "--bounds", "1,1")
    assert res.returncode == 0, res.stderr[-3000:]
    assert "note: frame --bounds is now --property-bounds" in res.stderr
    cases = [c for c in json.loads((fr / "frame_summary.json").read_text())["cases"] if c["model"]]
    assert [c["force_factor"] for c in cases] == [1.0, 1.0, 1.0]
    for q in ("drift", "force", "energy"):
        assert len({c["quantities"][q] for c in cases}) == 1


def test_frame_bounds_bad_input_is_one_line_and_writes_nothing(series, shared_dir, tmp_path):
    folder, out, _ = series
    cal = out / "params" / "device_02" / "law2.yaml"
    empty = tmp_path / "empty"
    empty.mkdir()
    other = tmp_path / "law9.json"
    b = json.loads((out / "bounds.json").read_text())
    other.write_text(json.dumps({**b, "models": {"9": b["models"]["2"]}}))
    for given, says in (("0.8", "LMIN,LMAX"), ("1.3,1.1", "0 < LMIN <= 1 <= LMAX"), (empty, "no bounds.json"),
                        (other, "no bounds for law 2")):
        fr = tmp_path / "fr_bad"
        res = _frame(shared_dir, fr, cal, "--property-bounds", given)
        assert res.returncode == 2, res.stderr
        assert says in res.stderr and len(res.stderr.strip().splitlines()) == 1 and "Traceback" not in res.stderr
        assert not fr.exists()


def test_bounds_scale_the_dampers_sized_on_the_nominal(series, shared_dir, tmp_path):
    """--target-damping sizes the nominal damper; the bounds are it x lambda: their energy-method damping is the
    target x lambda, and the free-vibration decay (measured apart from the formula) orders them the same way."""
    folder, out, _ = series
    fr = tmp_path / "sized"
    res = _frame(shared_dir, fr, out / "params" / "device_03" / "law2.yaml", "--property-bounds", "0.8,1.25",
                 "--target-damping", "0.1")
    assert res.returncode == 0, res.stderr[-3000:]
    cases = {c["bound"]: c for c in json.loads((fr / "frame_summary.json").read_text())["cases"] if c["model"]}
    for bound, lam in (("nominal", 1.0), ("upper", 1.25), ("lower", 0.8)):
        damping = cases[bound]["supplemental_damping"]
        assert damping["estimated"] == pytest.approx(0.1 * lam, rel=1e-9)
        assert cases[bound]["force_factor"] == pytest.approx(cases["nominal"]["force_factor"] * lam, rel=1e-9)
        assert damping["achieved"] == pytest.approx(0.1 * lam, rel=0.2)
    achieved = {b: c["supplemental_damping"]["achieved"] for b, c in cases.items()}
    assert achieved["lower"] < achieved["nominal"] < achieved["upper"]


def test_a_model_fitted_per_test_is_not_checked_against_the_nominal():
    """The acceptance as the bounds: a model with a parameter fitted per test is left out with the
    reason (it crashed on the per-test layout), in the result, the terminal lines and the JSON."""
    from fvd_bridge import Record
    from fvd_bridge.campaign import acceptance, production
    from fvd_bridge.campaign.acceptance import Acceptance
    from fvd_bridge.campaign.runner import CampaignSettings
    from fvd_bridge.text.production import format_production

    t = np.arange(0, 4, 0.01)
    rec = Record.from_arrays(t, 20 * np.sin(2 * np.pi * t), 50 * np.cos(2 * np.pi * t))
    cs = CampaignSettings(specs=("2",), per_test=((None, "alpha"),))
    a = acceptance.evaluate({"devices": [rec.name], "models": {"2": {}}}, [rec], cs, Acceptance(nominal_force=50.0))
    assert a["models"] == {} and "alpha fitted per test" in a["skipped"]["2"]
    prod = {"devices": [rec.name], "k": 3.0, "models": {}}
    assert "law 2: not checked (alpha fitted per test" in format_production(prod, a)
    assert "alpha fitted per test" in production.as_json(prod, a)["acceptance"]["skipped"]["2"]
