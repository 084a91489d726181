"""`fvd-bridge compare`: calibrated models checked on a test they were not fitted to."""

import json
import subprocess

import numpy as np
import pytest

from conftest import CLI, cli_env


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    """Laws 1 and 2 calibrated on a paper-protocol test of a law-2 device; an acceptance test
    of the same device (lab-like CSVs: t,d,F, velocity derived, 1 kN force noise and the
    rig's default 0.005 mm displacement noise)."""
    from fvd_bridge import calibrate, read_record
    from fvd_bridge.rig import Device, Noise, acceptance, paper, write_series

    root = tmp_path_factory.mktemp("cmp")
    dev = [Device(C=45.4, alpha=0.3, name="dev")]
    noise = Noise(force=1.0)
    a = write_series(str(root / "paper"), dev, paper(cycles=3), noise, seed=1)[0]
    b = write_series(str(root / "acc"), dev, acceptance(cycles=2), noise, seed=2)[0]
    rec = read_record(a)
    files = []
    for spec in ("1", "2"):
        files.append(calibrate(rec, spec, seed=0, pop=8, gens=60).save(str(root / f"law{spec}.yaml")))
    return root, files, a, b


def compare(*args, cwd=None):
    return subprocess.run([*CLI, "compare", *args], capture_output=True, text=True, env=cli_env(), cwd=cwd)


def test_the_exact_model_generalises_and_law1_does_not(fitted, tmp_path):
    from fvd_bridge.calibration import Calibration
    from fvd_bridge.fit.floor import input_noise_floor
    from fvd_bridge.records import read_record

    root, files, _, other = fitted
    res = compare(*files, other, "--json", "--out", str(tmp_path / "c"))
    assert res.returncode == 0, res.stderr
    report = json.loads(res.stdout)
    assert report["record"] == other and [m["model"] for m in report["models"]] == ["2", "1"]
    of = {m["model"]: m["of"] for m in report["models"]}
    cal = Calibration.load(files[1])
    # the floor of the record: its force and displacement noise through the model
    floor = input_noise_floor(cal.model, cal.values, read_record(other)).floor
    assert of["2"] < 1.5 * floor and of["1"] > 5 * of["2"]
    assert (tmp_path / "c" / "dev_compare.png").is_file()
    page = (tmp_path / "c" / "report.html").read_text()  # the same ranking, in the report
    assert "calibrated models on" in page and page.index(">2<") < page.index(">1<")
    text = compare(*files, other, "--window", "1,6", "--out", str(tmp_path / "w")).stdout
    assert "generalises best: 2" in text and "where 1 fails" in text


def test_prediction_on_a_displacement_history(fitted, tmp_path):
    _, files, _, _ = fitted
    t = np.arange(0, 4, 0.01)
    hist = tmp_path / "story1.csv"
    hist.write_text("t,d\n" + "\n".join(f"{x:.3f},{10 * np.sin(2 * np.pi * x):.6f}" for x in t))
    res = compare(*files, str(hist), "--out", str(tmp_path / "p"))
    assert res.returncode == 0, res.stderr
    assert "prediction on the displacement history" in res.stdout and "peak force" in res.stdout
    assert "beyond" not in res.stderr  # 10 mm at 1 Hz: inside the paper test's 40 mm, 500 mm/s ...
    assert "dominant frequency 1 Hz is outside the 2 Hz the model" in res.stderr  # ... but at half its frequency
    fast = tmp_path / "story2.csv"  # 60 mm at 2 Hz: 754 mm/s, beyond both peaks
    fast.write_text("t,d\n" + "\n".join(f"{x:.3f},{60 * np.sin(4 * np.pi * x):.6f}" for x in t))
    res = compare(*files, str(fast), "--out", str(tmp_path / "q"))
    assert res.returncode == 0, res.stderr
    assert "peak stroke 59.88 mm" in res.stderr and "peak velocity 754" in res.stderr and "extrapolation" in res.stderr
    assert "frequency" not in res.stderr  # 2 Hz: the test's


def test_bad_input_gets_one_line(fitted, tmp_path):
    root, files, paper_csv, _ = fitted
    res = compare(str(root / "missing.yaml"), paper_csv)
    assert res.returncode == 2 and "missing.yaml" in res.stderr and res.stderr.count("\n") == 1
    # the same test written in N and m, read without --units
    lines = open(paper_csv).read().splitlines()
    head = [ln for ln in lines if ln.startswith("#") or ln.startswith("t")]
    rows = [ln.split(",") for ln in lines if ln and ln[0].isdigit() or ln.startswith("-")]
    body = [f"{r[0]},{float(r[1]) / 1e3:.9g},{float(r[2]) * 1e3:.9g}" for r in rows]
    si = tmp_path / "si.csv"
    si.write_text("\n".join(head + body) + "\n")
    res = compare(*files, str(si), "--out", str(tmp_path / "u"))
    assert res.returncode == 2 and "--units" in res.stderr and res.stderr.count("\n") == 1
    assert not (tmp_path / "u").exists()
