"""Production-scale campaigns: the campaign file, resuming after SIGKILL, the Dask
executor, corrupt units, a changed campaign refused, and the statistics at the
edges (near-zero means, 2-3 runs that disagree, robust outliers, acceptance)."""

import json
import os
import shutil
import signal
import subprocess
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import yaml

from conftest import CLI, cli_env
from fvd_bridge.calibration import checks
from fvd_bridge.campaign import stats
from fvd_bridge.campaign.runner import CampaignSettings
from fvd_bridge.fit import FitResult

TABLES = ("table_A7.csv", "robustness.csv", "pareto.csv", "production.csv", "outliers.csv", "acceptance.csv")

#: 4 rig devices x 2 models x 4 runs = 32 units (every run: all_runs), small DE settings
CAMPAIGN = {
    "rig": {"devices": 4, "nominal": {"C": 45.4, "alpha": 0.3, "friction": 2.0},
            "scatter": {"C": 0.05, "alpha": 0.02}, "protocol": {"name": "paper", "cycles": 3},
            "noise": {"force": 1.0, "displacement": 0.005}, "seed": 3},
    "models": "2,9", "runs": 4, "seed": 1, "optimizer": "de", "pop": 8, "gens": 30, "jobs": 2,
    "no_figures": True, "acceptance": {"velocity": 500, "tolerance": 0.15}, "intervals": 0, "all_runs": True,
}
UNITS = 4 * 2 * 4


def write_campaign(folder: Path, out: str, **changes) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{out}.yaml"
    path.write_text(yaml.safe_dump({**CAMPAIGN, "out": out, **changes}, sort_keys=False))
    return path


def campaign(*args, timeout=600):
    return subprocess.run([*CLI, "campaign", *map(str, args), "--quiet"], capture_output=True, text=True,
                          env=cli_env(), timeout=timeout)


def unit_files(out: Path) -> dict:
    """{task id: bytes} of the stored units."""
    root = out / ".units"
    return {str(p.relative_to(root).with_suffix("")): p.read_bytes() for p in root.rglob("run*.json")}


def sessions(out: Path) -> dict:
    """{session id: units it stored}: the store's own record of who computed each unit."""
    count = {}
    for p in (out / ".units").rglob("run*.json"):
        s = json.loads(p.read_text())["unit"]["stored"]["session"]
        count[s] = count.get(s, 0) + 1
    return count


def tables(out: Path) -> dict:
    return {name: (out / name).read_text() for name in TABLES}


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """An uninterrupted local run."""
    folder = tmp_path_factory.mktemp("campaign")
    path = write_campaign(folder, "ref")
    res = campaign(path)
    assert res.returncode == 0, res.stderr
    return folder, folder / "ref", res


def test_uninterrupted_run_writes_calibrate_outputs_and_production_tables(reference):
    folder, out, res = reference
    assert f"{UNITS} units: 0 already done" in res.stderr
    assert f"units: {UNITS} (0 resumed" in res.stdout and "Pareto set" in res.stdout
    assert list(sessions(out).values()) == [UNITS] and len(unit_files(out)) == UNITS
    for dev in ("device_01", "device_04"):
        assert yaml.safe_load(open(out / "params" / dev / "law9.yaml"))["schema_version"] == 3
    acc = (out / "acceptance.csv").read_text().splitlines()
    assert acc[0].startswith("model,device,F_tension_kN") and len(acc) == 1 + 2 * 4
    assert "rig nominal device" in res.stdout and (out / "records" / "truth.yaml").exists()
    page = (out / "report.html").read_text()  # the series' production tables in the report
    assert "the series&#x27; acceptance" in page and "production statistics" in page
    assert page.count("<section class='device'") == 4
    assert not list(folder.glob(".*partial*"))


def test_sigkill_then_resume_gives_the_same_tables_and_computes_no_unit_twice(reference, tmp_path):
    path = write_campaign(tmp_path, "killed")
    out = tmp_path / "killed"
    log = open(tmp_path / "killed.stderr", "w")
    proc = subprocess.Popen([*CLI, "campaign", str(path), "--quiet"], stdout=log, stderr=log, env=cli_env(),
                            start_new_session=True)
    try:
        deadline = time.time() + 300
        while time.time() < deadline and proc.poll() is None:
            if (out / ".units").is_dir() and len(unit_files(out)) >= 4:
                break
            time.sleep(0.005)
        os.kill(proc.pid, signal.SIGKILL)  # the campaign dies at once, wherever it is
        proc.wait()
    finally:
        try:
            os.killpg(proc.pid, signal.SIGKILL)  # its orphaned pool workers, if any
        except ProcessLookupError:
            pass
        log.close()
    assert proc.returncode == -signal.SIGKILL
    before = unit_files(out)
    assert 4 <= len(before) < UNITS, "the kill came too late to test resuming"
    assert not (out / "table_A7.csv").exists()  # no partial output
    first = sessions(out)
    assert list(first.values()) == [len(before)]

    res = campaign(path)
    assert res.returncode == 0, res.stderr
    after = unit_files(out)
    assert f"{UNITS} units: {len(before)} already done" in res.stderr
    assert f"units: {UNITS} ({len(before)} resumed" in res.stdout
    assert f"{UNITS - len(before)} computed now" in res.stdout
    assert all(after[k] == v for k, v in before.items())  # finished units kept, not redone
    both = sessions(out)  # every unit computed once: by the killed start or by the resumed one
    assert len(after) == UNITS and both == {**first, **{s: n for s, n in both.items() if s not in first}}
    assert sorted(both.values()) == sorted([len(before), UNITS - len(before)])
    assert tables(out) == tables(reference[1])


def test_corrupt_units_are_redone(reference, tmp_path):
    out = tmp_path / "ref"
    shutil.copytree(reference[1], out)
    path = tmp_path / "ref.yaml"
    shutil.copy(reference[0] / "ref.yaml", path)
    units = sorted((out / ".units").rglob("run*.json"))
    units[0].write_text(units[0].read_text()[:200])  # a partial file
    data = json.loads(units[5].read_text())
    data["unit"]["result"]["of"] *= 1.01  # a changed value: checksum mismatch
    units[5].write_text(json.dumps(data))
    res = campaign(path)
    assert res.returncode == 0, res.stderr
    assert res.stderr.count("corrupt unit") == 2 and "checksum mismatch" in res.stderr
    assert "2 computed now, 2 corrupt redone" in res.stdout
    assert sorted(sessions(out).values()) == [2, UNITS - 2]
    assert tables(out) == tables(reference[1])


def test_changed_campaign_is_refused_in_one_line(reference, tmp_path):
    out = tmp_path / "ref"
    shutil.copytree(reference[1], out)
    for change, words in (({"runs": 3}, "settings.runs: 4 -> 3"), ({"models": "2,6"}, "settings.specs"),
                          ({"rig": {**CAMPAIGN["rig"], "seed": 4}}, "settings.source.rig.seed: 3 -> 4")):
        path = write_campaign(tmp_path, "ref", **change)
        res = campaign(path)
        assert res.returncode == 2, res.stderr
        assert res.stderr.count("\n") == 1 and str(path) in res.stderr and words in res.stderr, res.stderr
        assert "results would mix" in res.stderr
    assert list(sessions(out).values()) == [UNITS]  # nothing computed
    assert yaml.safe_load(open(out / "records" / "truth.yaml"))["campaign_rig"]["seed"] == 3  # not regenerated


@pytest.mark.slow
def test_dask_local_cluster_gives_the_local_tables(reference, tmp_path):
    """Process workers (a LocalCluster of 2 single-threaded workers)."""
    path = write_campaign(tmp_path, "dask")
    res = campaign(path, "--executor", "dask")
    assert res.returncode == 0, res.stderr
    assert "dask LocalCluster, 2 workers" in res.stderr
    assert tables(tmp_path / "dask") == tables(reference[1])


@pytest.mark.parametrize("text, words", [
    ("runz: 3\n", "unknown key 'runz'"),
    ("laws: 2\n", "unknown key 'laws' (use 'models')"),
    ("runs: many\n", "key 'runs': invalid int value: 'many'"),
    ("optimizer: sa\n", "key 'optimizer'"),
    ("rig: {devices: 2, colour: red}\n", "unknown key 'rig.colour'"),
    ("acceptance: {tolerance: 2}\n", "key 'acceptance.tolerance'"),
])
def test_bad_campaign_file_one_line(tmp_path, text, words):
    path = tmp_path / "bad.yaml"
    path.write_text("rig: {devices: 2}\nout: o\nmodels: 2\n" + text if not text.startswith("rig") else
                    "out: o\nmodels: 2\n" + text)
    res = campaign(path)
    assert res.returncode == 2 and res.stderr.count("\n") == 1, res.stderr
    assert str(path) in res.stderr and words in res.stderr, res.stderr
    assert not (tmp_path / "o").exists()


# ------------------------------------------------------------ statistics at the edges
def fit(spec, names, params, of, bounds, log=None):
    return FitResult(spec=spec, names=names, units=["-"] * len(names), values=np.array(params, float), of=of,
                     bounds=np.array(bounds, float), bounds_mode="auto", optimizer="de", seed=[0],
                     evaluations=1, log=log or [False] * len(names), off=[None] * len(names))


def test_near_zero_mean_is_reported_and_kept_out_of_beta():
    # law 6's alpha: 0 on one device, 0.0025 on the other, searched in [0, 1]
    means = np.array([[0.30, 500.0, 0.0, 1.0], [0.32, 520.0, 0.0025, 1.1]])
    ranges = [[0, 1.8], [0, 750], [0, 1], [0, 5]]
    nz = stats.near_zero(means, ranges, [False] * 4)
    assert nz.tolist() == [False, False, True, False]
    delta_n, beta = stats.robustness(means, nz)
    assert np.isnan(delta_n[2]) and np.all(np.isfinite(delta_n[[0, 1, 3]]))
    assert beta == pytest.approx(np.mean([0.01 / 0.31, 10 / 510, 0.05 / 1.05]))
    naive = stats.robustness(means)[1]
    assert naive > 0.2 > beta  # without the rule alpha's +-100% would dominate beta
    # a log-scaled parameter keeps its relative scatter; no ranges: only an exact 0 is near zero
    assert not stats.near_zero(np.array([[0.001], [0.002]]), [[1e-6, 10]], [True])[0]
    assert stats.near_zero(np.array([[0.001], [0.002]]), None).tolist() == [False]

    from fvd_bridge.campaign.outputs import summarize

    class Rec:
        def __init__(self, name):
            self.name = name

    names = ["C", "K", "alpha", "beta"]
    results = {(dev, "6"): [fit("6", names, row, 0.05, ranges)] * 2 for dev, row in zip(("a", "b"), means)}
    m = summarize([Rec("a"), Rec("b")], results, CampaignSettings(specs=("6",), runs=2))["models"]["6"]
    assert m["near_zero"].tolist() == [False, False, True, False] and m["beta"] == pytest.approx(beta)
    assert len(m["notes"]) == 1 and m["notes"][0].startswith("alpha: mean over devices 0.00125 is near zero")
    assert "kept out of beta" in m["notes"][0]


@pytest.mark.parametrize("ofs, flagged", [
    ((0.1921, 0.2023), True),         # 5.3% apart: the sigma rule (2.6% of the mean) let it pass
    ((0.1921, 0.1950), False),        # 1.5%
    ((0.100, 0.100, 0.106), True),    # 3 runs, 6%
    ((0.100, 0.102, 0.104), False),   # 3 runs, 4%
])
def test_runs_disagree_with_two_or_three_runs(ofs, flagged):
    from fvd_bridge.catalog import parse_model

    runs = [fit("2", ["C", "alpha"], [45.0, 0.3], of, [[0, 900], [0, 1]]) for of in ofs]
    codes = [w["code"] for w in checks.fit_warnings(parse_model("2"), runs)]
    assert ("runs_disagree" in codes) is flagged
    assert checks.relative_range(ofs) == pytest.approx((max(ofs) - min(ofs)) / min(ofs))
    if ofs == (0.1921, 0.2023):
        assert np.std(ofs) < 0.05 * np.mean(ofs)  # what the old rule saw


def test_robust_outliers():
    x = np.array([10.0, 10.1, 9.9, 10.05, 9.95, 10.02, 13.0])
    flags, z = stats.robust_outliers(x, k=3.5)
    assert flags.tolist() == [False] * 6 + [True] and z[-1] > 3.5
    # MAD = 0 (most values equal): the mean absolute deviation takes over
    flags, _ = stats.robust_outliers(np.array([5.0, 5, 5, 5, 5, 6]))
    assert flags.tolist() == [False] * 5 + [True]
    assert not stats.robust_outliers(np.full(6, 2.0))[0].any()
    assert not stats.robust_outliers(np.array([1.0, 1.0, 100.0]))[0].any()  # too few to judge
    assert stats.robust_outliers(np.array([1.0, 1.1, 0.9, 1.0, np.nan]))[0].tolist() == [False] * 4 + [True]


def test_acceptance_force_at_the_design_velocity():
    from fvd_bridge.campaign.acceptance import Acceptance, design_motion, forces_at_velocity
    from fvd_bridge.catalog import parse_model

    acc = Acceptance(velocity=400.0)
    motion = design_motion(acc, amplitude=30.0, dt=0.002)
    assert np.max(motion.v) == pytest.approx(400.0, rel=1e-4)
    P = np.array([[45.0, 0.3], [50.0, 0.3]])
    F = forces_at_velocity(parse_model("2").force(motion, P), motion.v)
    assert F == pytest.approx(np.repeat(P[:, :1] * 400.0 ** 0.3, 2, axis=1), rel=1e-4)  # tension, compression



def test_a_rig_series_is_held_to_its_nominal_dampers_rating_not_to_the_rig():
    """Without acceptance.nominal_force a rig series' nominal force is its nominal damper's rating, C V^alpha
    (law 2's force on the acceptance sinusoid), not the rig's simulation of it: the nominal's seal friction
    (2 kN) and spring are what the damper is, not what it is rated; the source says so."""
    from types import SimpleNamespace

    from fvd_bridge.campaign.acceptance import Acceptance, design_motion, evaluate
    from fvd_bridge.campaign.sources import rig_rating, rig_spec
    from fvd_bridge.records import Record

    rating = rig_rating(rig_spec({"devices": 2, "nominal": {"C": 45.4, "alpha": 0.3, "friction": 2.0, "Ks": 150}},
                                 "series.yaml"))
    assert rating.force(design_motion(Acceptance(velocity=300.0), amplitude=30.0, dt=0.002)) == pytest.approx(
        45.4 * 300.0 ** 0.3, rel=1e-4)
    t = np.arange(0, 4, 0.002)
    rec = Record.from_arrays(t, 30 * np.sin(2 * np.pi * t), 50 * np.cos(2 * np.pi * t), name="dev")
    summary = {"devices": ["dev"], "models": {"2": {"best": {"dev": SimpleNamespace(values=np.array([45.4, 0.3]))}}}}
    a = evaluate(summary, [rec], CampaignSettings(specs=("2",)), Acceptance(velocity=300.0), rating=rating)
    assert a["nominal_force"] == pytest.approx(45.4 * 300.0 ** 0.3, rel=1e-4)
    assert a["nominal_source"] == "rig nominal device: C V^alpha, law 2 with C 45.4, alpha 0.3"
    assert a["models"]["2"]["deviation"][0] < 1e-4 and a["models"]["2"]["passed"][0]  # the rated device itself
    assert evaluate(summary, [rec], CampaignSettings(specs=("2",)), Acceptance())["why_not"]  # no nominal: says so

def test_derived_quantities_are_averaged_over_runs():
    """Law 8's slip force mu*N in the table is the mean (and sigma) of each
    run's product, not the product of the mean mu and the mean N (two runs
    with the same mu*N = 60 kN but different mu and N: 60, sigma 0; the
    product of the means would give 0.45 x 150 = 67.5)."""
    from fvd_bridge.campaign.outputs import summarize
    from fvd_bridge.campaign.runner import CampaignSettings
    from fvd_bridge.fit.result import FitResult
    from fvd_bridge.laws import LAWS

    law = LAWS[8]
    bounds = law.bounds("paper", {})

    def run(mu, N):
        return FitResult("8", law.names, [p.unit for p in law.parameters], np.array([0.2, 30.0, mu, N]), 0.1,
                         bounds, "paper", "de", 0, 1)

    class Rec:
        name = "dev"

    summary = summarize([Rec()], {("dev", "8"): [run(0.3, 200.0), run(0.6, 100.0)]}, CampaignSettings(("8",)))
    mean, sigma, unit = summary["models"]["8"]["derived"][0]["mu*N"]
    assert (mean, sigma, unit) == (pytest.approx(60.0), pytest.approx(0.0, abs=1e-12), "kN")


@pytest.mark.parametrize("optimizer", ["de", "ga"])
def test_runs_disagree_hint_never_names_the_optimizer_in_use(optimizer):
    from fvd_bridge.catalog import parse_model

    runs = [replace(fit("2", ["C", "alpha"], [45.0, 0.3], of, [[0, 900], [0, 1]]), optimizer=optimizer)
            for of in (0.139, 0.447)]
    msg = next(w["message"] for w in checks.fit_warnings(parse_model("2"), runs) if w["code"] == "runs_disagree")
    assert f"({optimizer})" in msg and ("optimizer='de'" in msg) == (optimizer != "de")  # Python's words
