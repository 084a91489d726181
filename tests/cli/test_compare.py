"""`fvd-bridge compare`: calibrated models checked on a test they were not fitted to."""

import html
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
    from fvd_bridge.rig import VirtualDamper, Noise, acceptance, paper, write_series

    root = tmp_path_factory.mktemp("cmp")
    dev = [VirtualDamper(C=45.4, alpha=0.3, name="dev")]
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


# ------------------------------------------------------------------ peak force and energy per cycle
def _dashpot(c, amp, freq, cycles, dt=0.01, factor=1.0):
    """d = amp sin(w t) [mm] over whole cycles and the force factor x c v [kN] of a linear dashpot."""
    w = 2 * np.pi * freq
    t = np.arange(int(round(cycles / freq / dt)) + 1) * dt
    return t, amp * np.sin(w * t), factor * c * amp * w * np.cos(w * t)


def test_force_measures_of_a_linear_dashpot_by_hand():
    """F = c v on d = A sin(w t): peak c w A, energy per cycle pi c w A^2 (the loop's ellipse); a record of two
    amplitudes: the mean of the two levels' pi c w A^2 over its 4 cycles; a motion without reversals: the total."""
    from fvd_bridge.records.cycles import force_measures

    c, A, f = 2.0, 20.0, 1.0
    w = 2 * np.pi * f
    for cycles in (1, 3, 2.5):  # whole cycles, and a half cycle more
        t, d, F = _dashpot(c, A, f, cycles, dt=0.001)
        m = force_measures(d, F)
        assert m.peak == pytest.approx(c * w * A, rel=1e-9) and m.cycles == pytest.approx(cycles, rel=1e-3)
        assert m.peak_tension == pytest.approx(c * w * A) and m.peak_compression == pytest.approx(c * w * A, rel=1e-4)
        assert m.energy_per_cycle == pytest.approx(np.pi * c * w * A ** 2, rel=1e-4)
        assert m.energy == pytest.approx(cycles * np.pi * c * w * A ** 2, rel=1e-4)
    # twice the force: twice the peak and the energy
    assert force_measures(d, 2 * F).energy_per_cycle == pytest.approx(2 * m.energy_per_cycle, rel=1e-12)
    # irregular: 2 cycles at 10 mm then 2 at 30 mm (joined at d = 0, where v jumps: the trapezoid there is
    # off by a step's (F2 - F1)/2 dd, so a finer step)
    _, d1, F1 = _dashpot(c, 10.0, f, 2, dt=1e-4)
    _, d2, F2 = _dashpot(c, 30.0, f, 2, dt=1e-4)
    m = force_measures(np.concatenate([d1, d2[1:]]), np.concatenate([F1, F2[1:]]))
    assert m.cycles == pytest.approx(4.0, rel=1e-3) and m.peak == pytest.approx(c * w * 30.0)
    assert m.energy_per_cycle == pytest.approx(np.pi * c * w * (2 * 10.0 ** 2 + 2 * 30.0 ** 2) / 4, rel=1e-4)
    # a ramp at 5 mm/s: no reversal, no cycle; the total is c v x stroke
    ramp = np.linspace(0.0, 40.0, 401)
    m = force_measures(ramp, np.full_like(ramp, c * 5.0))
    assert m.energy_per_cycle is None and m.cycles == 0 and m.energy == pytest.approx(c * 5.0 * 40.0)


def test_compare_shows_peak_and_energy_beside_the_measured(tmp_path, monkeypatch, capsys):
    """A law-1 dashpot (C = c) on a record whose measured force is twice c v: the predicted peak and energy per
    cycle are half the measured ones, in the terminal, the JSON and the page, and each is c w A and pi c w A^2."""
    from fvd_bridge import Record, calibrate, cli

    monkeypatch.chdir(tmp_path)
    c = 2.0
    t, d, F = _dashpot(c, 20.0, 1.0, 3)
    cal = calibrate(Record.from_arrays(t, d, F), "1", intervals=0)
    assert cal.values[0] == pytest.approx(c, rel=1e-4)
    cal.save("law1.yaml")
    A, f = 30.0, 0.8
    w = 2 * np.pi * f
    t, d, F = _dashpot(c, A, f, 4, factor=2.0)
    (tmp_path / "twice.csv").write_text("t [s],d [mm],F [kN]\n" + "\n".join(
        f"{a:.4f},{b:.8f},{x:.8f}" for a, b, x in zip(t, d, F)))
    assert cli.main(["compare", "law1.yaml", "twice.csv", "--out", "c", "--no-figures"]) == 0
    stdout = capsys.readouterr().out
    report = json.loads((tmp_path / "c" / "twice_compare.json").read_text())
    model, measured = report["models"][0], report["measured"]
    assert report["cycles"] == pytest.approx(4.0, rel=1e-3)
    # the trapezoidal rule at w dt = 0.05 and the derived velocity: within 1e-3 of the closed forms
    assert model["peak_force_kN"] == pytest.approx(c * w * A, rel=1e-3)
    assert model["energy_per_cycle_kNmm"] == pytest.approx(np.pi * c * w * A ** 2, rel=1e-3)
    assert measured["peak_force_kN"] == pytest.approx(2 * c * w * A, rel=1e-3)
    assert measured["energy_per_cycle_kNmm"] == pytest.approx(2 * np.pi * c * w * A ** 2, rel=1e-3)
    assert model["peak_force_kN"] / measured["peak_force_kN"] == pytest.approx(0.5, abs=5e-4)
    assert model["energy_per_cycle_kNmm"] / measured["energy_per_cycle_kNmm"] == pytest.approx(0.5, abs=5e-4)
    lines = stdout.splitlines()
    head = next(k for k, line in enumerate(lines) if line.startswith("peak force and energy per cycle"))
    assert "4 displacement cycles" in lines[head]
    shown = lines[head + 2].split()  # (measured), peak, energy per cycle: 4 digits
    assert shown[0] == "(measured)" and [float(x) for x in shown[1:]] == pytest.approx(
        [2 * c * w * A, 2 * np.pi * c * w * A ** 2], rel=1.5e-3)
    shown = lines[head + 3].split()  # file, model, peak, ratio, energy per cycle, ratio
    assert shown[:2] == ["law1.yaml", "1"] and shown[3] == shown[5] == "0.500"
    assert [float(shown[2]), float(shown[4])] == pytest.approx([c * w * A, np.pi * c * w * A ** 2], rel=1.5e-3)
    page = html.unescape((tmp_path / "c" / "report.html").read_text())
    assert "energy per cycle [kN mm = J]" in page and page.count("<td>50.0%</td>") == 2
    assert "<td>measured</td>" in page
