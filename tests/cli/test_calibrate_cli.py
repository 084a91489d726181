"""The calibrate verb end to end on two rig devices: every output exists and parses."""

import csv
import hashlib
import json
import re
import subprocess
import sys

import numpy as np
import pytest
import yaml

from fvd_bridge.rig import VirtualDamper, Noise, paper, write_series


@pytest.fixture(scope="module")
def two_devices(tmp_path_factory):
    out = tmp_path_factory.mktemp("rig")
    devs = [VirtualDamper(C=45.4, alpha=0.3, name="dev_a"), VirtualDamper(C=48.0, alpha=0.31, name="dev_b")]
    paths = write_series(str(out), devs, paper(cycles=3), Noise(force=1.0), seed=1)
    return paths[:-1]


def calibrate(args, cwd=None):
    """The calibrate verb in a subprocess; without intervals unless the test asks for them (their own tests:
    tests/fit/test_intervals.py)."""
    more = [] if "--intervals" in args else ["--intervals", "0"]
    return subprocess.run([sys.executable, "-m", "fvd_bridge.cli", "calibrate", *args, *more],
                          capture_output=True, text=True, cwd=cwd)


def test_calibrate_writes_every_output(two_devices, tmp_path):
    out = tmp_path / "cal"
    res = calibrate([*two_devices, "--laws", "1,2,9", "--runs", "2", "--pop", "8", "--gens", "40",
                     "--out", str(out), "--jobs", "1", "--quiet", "--seed", "4", "--intervals", "4"])
    assert res.returncode == 0, res.stderr
    assert "Pareto set" in res.stdout
    for dev in ("dev_a", "dev_b"):
        for law in (1, 2, 9):
            p = yaml.safe_load(open(out / "params" / dev / f"law{law}.yaml"))
            assert p["schema_version"] == 3 and p["model"] == str(law)
            assert set(p["parameters"]) == {1: {"C"}, 2: {"C", "alpha"}, 9: {"C", "alpha", "beta"}}[law]
            assert p["units"] == {"force": "kN", "displacement": "mm", "time": "s"}
            assert p["settings"]["runs"] == 2 and p["record"]["name"] == dev
        # law 2 recovers the orifice law of the rig device (noise 1 kN)
        p2 = yaml.safe_load(open(out / "params" / dev / "law2.yaml"))["parameters"]
        assert p2["alpha"]["value"] == pytest.approx({"dev_a": 0.3, "dev_b": 0.31}[dev], abs=0.01)
        # each parameter with its bootstrap interval (4 replicates here), printed too
        lo, hi = p2["alpha"]["ci95"]
        assert lo < hi and p2["alpha"]["stderr"] > 0
    assert "95% intervals of the calibrations" in res.stdout and "law 2, dev_a:" in res.stdout
    rows = list(csv.DictReader(open(out / "table_A7.csv")))
    assert {(r["model"], r["device"], r["quantity"]) for r in rows} >= {("2", "dev_a", "OF"), ("9", "dev_b", "beta")}
    rob = list(csv.DictReader(open(out / "robustness.csv")))
    assert {r["model"] for r in rob} == {"1", "2", "9"}
    par = list(csv.DictReader(open(out / "pareto.csv")))
    assert any(r["non_dominated"] == "1" for r in par)
    summary = json.load(open(out / "summary.json"))
    made = [r for r in summary["runs"] if not r["stop"].startswith("wider search")]
    wider = {r["model"] for r in summary["runs"] if r["stop"].startswith("wider search")}
    assert summary["schema_version"] == 1 and len(made) == 2 * 3 * 2
    # law 1 misses these orifice devices far above their noise floor: its search looked wider, and says so
    assert "1" in wider and "2" not in wider
    said = yaml.safe_load(open(out / "params" / "dev_a" / "law1.yaml"))["warnings"]
    assert any("what the record's noise allows" in w for w in said)
    figs = {p.name for p in (out / "figures").iterdir()}
    assert {"of_bars.png", "pareto.png", "dispersion_law9.png", "loops_dev_a_law2.png"} <= figs
    assert not list(tmp_path.glob(".*partial*"))


def test_same_seed_same_parameters(two_devices, tmp_path):
    outs = []
    for k in range(2):
        out = tmp_path / f"c{k}"
        res = calibrate([two_devices[0], "--laws", "2", "--runs", "1", "--optimizer", "ga", "--pop", "20",
                         "--gens", "10", "--out", str(out), "--jobs", "1", "--quiet", "--no-figures"])
        assert res.returncode == 0, res.stderr
        outs.append(yaml.safe_load(open(out / "params" / "dev_a" / "law2.yaml"))["parameters"])
    assert outs[0] == outs[1]


def test_warns_on_paper_bounds(two_devices, tmp_path):
    """The paper's bounds starve law 2 (C <= 2): the fit ends on the bound and says so."""
    out = tmp_path / "paper"
    res = calibrate([two_devices[0], "--laws", "2", "--runs", "1", "--bounds", "paper", "--pop", "8",
                     "--gens", "30", "--out", str(out), "--jobs", "1", "--quiet", "--no-figures"])
    assert res.returncode == 0, res.stderr
    assert "C ended on its upper bound 2 (paper bounds; try --bounds auto)" in res.stdout
    p = yaml.safe_load(open(out / "params" / "dev_a" / "law2.yaml"))
    assert any("upper bound" in w for w in p["warnings"])
    assert p["parameters"]["C"]["value"] == pytest.approx(2.0, rel=1e-3)


@pytest.mark.parametrize("args, needle", [
    (["--laws", "12"], "unknown law '12'"),
    (["--laws", "2+nonsense"], "nonsense"),
    (["--bounds", "tight"], "invalid choice"),
    (["--bound", "2:zeta=0,1", "--laws", "2"], "has no parameter 'zeta'"),
    (["--runs", "0"], "--runs 0"),
    (["--window", "500,600"], "--window '500,600': holds 0 samples"),
    (["--window", "2"], "expected T0,T1"),
])
def test_bad_options_exit_2(two_devices, tmp_path, args, needle):
    res = calibrate([two_devices[0], "--out", str(tmp_path / "x"), "--quiet", *args])
    assert res.returncode == 2
    assert needle in res.stderr and "Traceback" not in res.stderr
    assert not (tmp_path / "x").exists()


def test_bound_override_is_used(two_devices, tmp_path):
    out = tmp_path / "ov"
    res = calibrate([two_devices[0], "--laws", "2", "--runs", "1", "--bound", "2:alpha=0.5,0.9", "--pop", "8",
                     "--gens", "20", "--out", str(out), "--jobs", "1", "--quiet", "--no-figures"])
    assert res.returncode == 0, res.stderr
    p = yaml.safe_load(open(out / "params" / "dev_a" / "law2.yaml"))["parameters"]["alpha"]
    assert p["bounds"] == [0.5, 0.9] and np.isclose(p["value"], 0.5, atol=1e-3)


def test_yaml_config_sets_options(two_devices, tmp_path):
    out = tmp_path / "cfg_out"
    cfg = tmp_path / "cal.yaml"
    cfg.write_text(f"laws: '2'\nruns: 1\npop: 8\ngens: 20\nout: {out}\njobs: 1\nbound: ['2:alpha=0.5,0.9']\n")
    res = calibrate([two_devices[0], "--config", str(cfg), "--quiet", "--no-figures"])
    assert res.returncode == 0, res.stderr
    p = yaml.safe_load(open(out / "params" / "dev_a" / "law2.yaml"))
    assert p["settings"]["runs"] == 1 and p["parameters"]["alpha"]["bounds"] == [0.5, 0.9]
    cfg.write_text("runs: 1\nwibble: 3\n")
    res = calibrate([two_devices[0], "--config", str(cfg), "--out", str(tmp_path / "y")])
    assert res.returncode == 2 and "unknown option 'wibble'" in res.stderr
    # values are checked as on the command line: one line naming the file and the option
    for text, words in (("runs: two\n", ["option 'runs'", "invalid int value: 'two'"]),
                        ("optimizer: pso\n", ["option 'optimizer'", "invalid choice: 'pso'"])):
        cfg.write_text(text)
        res = calibrate([two_devices[0], "--config", str(cfg), "--out", str(tmp_path / "z")])
        err = res.stderr.strip()
        assert res.returncode == 2 and len(err.splitlines()) == 1 and str(cfg) in err, err
        assert all(w in err for w in words), err
        assert not (tmp_path / "z").exists()


def test_calibration_file_reproduces_its_of(two_devices, tmp_path):
    """What the exporters read: the parameter file alone reproduces the fitted OF."""
    from fvd_bridge.calibration import Calibration
    from fvd_bridge.errors import InputError
    from fvd_bridge.fit import objective
    from fvd_bridge.records import read_record

    out = tmp_path / "c"
    res = calibrate([two_devices[0], "--laws", "9", "--runs", "1", "--pop", "8", "--gens", "30",
                     "--out", str(out), "--jobs", "1", "--quiet", "--no-figures"])
    assert res.returncode == 0, res.stderr
    path = out / "params" / "dev_a" / "law9.yaml"
    cal = Calibration.load(str(path))
    rec = read_record(two_devices[0])
    F = cal.model.force(rec, cal.values[None, :])[0]
    assert objective(rec.F, F, rec.t) == pytest.approx(cal.of, rel=1e-9)
    data = yaml.safe_load(open(path))
    data["parameters"]["alpha"]["unit"] = "1/m"
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(data))
    with pytest.raises(InputError, match="parameters.alpha.unit"):
        Calibration.load(str(bad))


def test_calibrate_with_plugin_effect(two_devices, tmp_path):
    from conftest import PLUGIN

    plugin = tmp_path / "my_effects.py"
    plugin.write_text(PLUGIN)
    out = tmp_path / "pl"
    res = calibrate([two_devices[0], "--laws", "2+cubic_spring", "--plugin", str(plugin), "--runs", "2",
                     "--pop", "8", "--gens", "30", "--out", str(out), "--jobs", "2", "--quiet"])
    assert res.returncode == 0, res.stderr
    p = yaml.safe_load(open(out / "params" / "dev_a" / "law2+cubic_spring.yaml"))
    assert [e["name"] for e in p["effects"]] == ["cubic_spring"] and "cubic_spring.K3" in p["parameters"]
    # the file names its plugin by name and content hash; reading it imports nothing by itself
    assert p["settings"]["plugins"] == [{"file": "my_effects.py",
                                         "sha256": hashlib.sha256(plugin.read_bytes()).hexdigest()}]
    # the rig device has no cubic spring: the fit leaves it near zero
    assert abs(p["parameters"]["cubic_spring.K3"]["value"]) < 1e-4
    assert (out / "figures" / "loops_dev_a_law2+cubic_spring.png").is_file()


def test_window_keeps_part_of_the_record(two_devices, tmp_path):
    """--window T0,T1 fits only that part (the velocity derived on the whole
    record first) and the calibration file says which part."""
    from fvd_bridge.calibration import Calibration
    from fvd_bridge.commands.common import window
    from fvd_bridge.records import read_record

    out = tmp_path / "w"
    res = calibrate([two_devices[0], "--laws", "2", "--runs", "1", "--pop", "8", "--gens", "40", "--window", "1,4",
                     "--out", str(out), "--quiet"])
    assert res.returncode == 0, res.stderr
    cal = Calibration.load(str(out / "params" / "dev_a" / "law2.yaml"))
    assert cal.record.window == [1.0, 4.0]
    part = window(read_record(two_devices[0]), "1,4")
    assert part.t[0] >= 1.0 and part.t[-1] <= 4.0 and cal.record.samples == part.n
    # eq. 18 on the window, computed here: integral |F - F_model| dt / (sigma_F (t1 - t0))
    err = np.trapezoid(np.abs(part.F - cal.force(part)), part.t) / (np.std(part.F) * (part.t[-1] - part.t[0]))
    assert cal.of == pytest.approx(float(err), rel=1e-6)


def test_one_device_table_promises_no_statistic_it_does_not_show(two_devices, tmp_path):
    """One device, runs that agree: the table is not headed 'Mean (sigma)', and no note speaks of
    beta_r, which one device does not have (a friction of nil would be 'kept out of beta')."""
    res = calibrate([two_devices[0], "--laws", "2,2+friction", "--runs", "2", "--out", str(tmp_path / "one"),
                     "--jobs", "1", "--quiet", "--no-figures"])
    assert res.returncode == 0, res.stderr
    table = res.stdout.split("\n\n")[1]
    assert "Mean over runs" in res.stdout and "(sigma)" not in res.stdout, res.stdout
    assert not re.search(r"\d \([-+.\de]+\)$", table, re.M), table  # no cell shows a sigma
    assert "Robustness notes" not in res.stdout and "kept out of beta" not in res.stdout, res.stdout
    assert "beta_r (the robustness index) and the Pareto front" in res.stdout
