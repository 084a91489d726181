"""OUT/report.html: written by calibrate for two lab-like devices, checked in
a real browser (headless Chromium: the DOM after rendering, no console
error, a non-blank screenshot kept in test-artifacts/), and its acceptance
table against the physics put into the records: a device whose oil heats
up fails the spread of peak force and energy over cycles, a steady one
passes."""

from __future__ import annotations

import re
import shutil
import subprocess

import numpy as np
import pytest

from conftest import CLI, REPO, cli_env
from fvd_bridge.report.acceptance import cycle_peaks_and_energies
from fvd_bridge.rig import VirtualDamper, paper

from lab import lab_record

#: the browser the Makefile's sysdeps step installs (Debian package chromium)
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
#: flags for a headless run on a closed network (no background connections)
HEADLESS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
            "--disable-background-networking", "--disable-component-update", "--disable-sync",
            "--enable-logging=stderr", "--v=0"]
toolchain = pytest.mark.skipif(shutil.which("cmake") is None or shutil.which("cc") is None,
                               reason="building an FMU needs cmake and a C compiler")
#: heating of the second device [1/MJ]: its force falls by a third over the paper's ten cycles
HOT = 1.5


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("report")
    protocol = paper()
    for name, heating in (("steady", 0.0), ("hot", HOT)):
        lab_record(VirtualDamper(C=45.0, alpha=0.3, heating=heating, name=name), protocol, seed=3, tmp_path=tmp, name=name)
    out = tmp / "out"
    res = subprocess.run([*CLI, "calibrate", str(tmp / "steady.csv"), str(tmp / "hot.csv"), "--laws", "2",
                          "--runs", "2", "--out", str(out)], capture_output=True, text=True, env=cli_env(),
                         timeout=600)
    assert res.returncode == 0, res.stderr[-2000:]
    return out, tmp


def test_the_page_is_self_contained(report):
    out, _ = report
    html = (out / "report.html").read_text()
    assert not re.search(r"""(src|href)=['"]?(https?:)?//""", html)  # nothing from another host
    assert html.count("data:image/png;base64,") >= 2 + 2  # each device's loops, the series' figures
    for text in ("device steady", "device hot", "acceptance of steady", "acceptance of hot", "95% interval"):
        assert text in html


def test_the_acceptance_table_follows_the_physics(report):
    out, tmp = report
    html = (out / "report.html").read_text()
    hot = html.split("acceptance of hot", 1)[1].split("</table>", 1)[0]
    steady = html.split("acceptance of steady", 1)[1].split("</table>", 1)[0]
    assert re.search(r"peak force spread over cycles.*?FAIL", hot, re.S)
    assert re.search(r"energy per cycle.*?FAIL", hot, re.S)
    # steady passes every rule of its own cycles; its force against the series'
    # nominal (the two devices' mean, the hot one a third down) sits at the 15% edge
    assert re.search(r"peak force spread over cycles.*?pass", steady, re.S)
    assert re.search(r"energy per cycle.*?pass", steady, re.S)
    assert steady.count("FAIL") <= 1 and "FAIL" not in steady.split("nominal value", 1)[-1]
    # a second computation: the peak force in windows of one period (f = v / (2 pi A)) of the protocol
    from fvd_bridge.records import read_record

    rec = read_record(str(tmp / "hot.csv"))
    peaks, _ = cycle_peaks_and_energies(rec)
    period = 2 * np.pi * 40.0 / 500.0
    by_period = [np.abs(rec.F[(rec.t >= k * period) & (rec.t < (k + 1) * period)]).max()
                 for k in range(int(rec.t[-1] / period))]
    assert len(peaks) >= 9 and peaks[0] > peaks[-1] * 1.3  # the heating took a third off
    assert max(by_period) == pytest.approx(peaks.max(), rel=0.01)
    assert min(by_period) == pytest.approx(peaks.min(), rel=0.03)
    assert np.max(np.abs(peaks / peaks.mean() - 1.0)) > 0.15


@pytest.mark.skipif(CHROMIUM is None, reason="Chromium is not installed (make sysdeps installs it)")
def test_chromium_renders_the_report(report, tmp_path):
    out, _ = report
    page = (out / "report.html").as_uri()
    dom = subprocess.run([CHROMIUM, *HEADLESS, f"--user-data-dir={tmp_path / 'profile'}", "--dump-dom", page],
                         capture_output=True, text=True, timeout=120)
    assert dom.returncode == 0, dom.stderr[-2000:]
    assert dom.stdout.count("<table") >= 2 * 3 + 1  # per device: tests, fit, acceptance; the series
    assert len(re.findall(r"<img ", dom.stdout)) >= 4
    assert "device steady" in dom.stdout and "device hot" in dom.stdout
    assert not re.search(r"CONSOLE\(\d+\)|Uncaught", dom.stderr)  # no console error
    shot = tmp_path / "report.png"
    res = subprocess.run([CHROMIUM, *HEADLESS, f"--user-data-dir={tmp_path / 'profile2'}", "--window-size=1280,2400",
                          f"--screenshot={shot}", page], capture_output=True, text=True, timeout=120)
    assert res.returncode == 0 and shot.exists(), res.stderr[-2000:]
    import matplotlib.image as mpimg

    pixels = mpimg.imread(str(shot))
    assert pixels.std() > 0.05  # not blank
    artifacts = REPO / "test-artifacts"
    artifacts.mkdir(exist_ok=True)
    shutil.copy(shot, artifacts / "report_screenshot.png")


def test_report_rebuilds_the_page_and_refuses_a_foreign_folder(report, tmp_path):
    out, _ = report
    (out / "report.html").unlink()
    res = subprocess.run([*CLI, "report", str(out), "--tolerance", "0.5"], capture_output=True, text=True,
                         env=cli_env(), timeout=300)
    assert res.returncode == 0, res.stderr[-2000:]
    html = (out / "report.html").read_text()
    assert "tolerance +-50%" in html
    res = subprocess.run([*CLI, "report", str(tmp_path)], capture_output=True, text=True, env=cli_env())
    assert res.returncode == 2 and "not an output folder" in res.stderr and "Traceback" not in res.stderr
    res = subprocess.run([*CLI, "report", str(out), "--tolerance", "15"], capture_output=True, text=True,
                         env=cli_env())
    assert res.returncode == 2 and "--tolerance 15" in res.stderr


def _exports_table(html: str, caption: str) -> list[list[str]]:
    """The rows of the report's tables with ``caption``, over every device (cells as text)."""
    bodies = [part.split("</table>", 1)[0] for part in html.split(caption)[1:]]
    return [re.findall(r"<td>(.*?)</td>", row) for body in bodies for row in re.findall(r"<tr>(.*?)</tr>", body)[1:]]


@toolchain
def test_the_exports_and_their_fidelity_are_in_the_report(report, tmp_path):
    """Each model's OpenSees mapping is checked in the page (law 2 maps exactly
    onto a native material: OF at round-off), and the exports made of the
    folder's calibrations are listed with their units and checks, the same
    figures the export verbs print; a calibration file outside an output
    folder notes nothing."""
    out, _ = report
    html = (out / "report.html").read_text()
    rows = _exports_table(html, "each model&#x27;s OpenSees material")
    assert {r[1] for r in rows} == {"steady", "hot"} and all(r[2] == "exact" for r in rows)
    assert all(float(r[3]) < 1e-9 and r[5] == "within its bound" for r in rows)
    cal = out / "params" / "steady" / "law2.yaml"
    script, fmu = tmp_path / "damper.tcl", tmp_path / "damper.fmu"
    res = subprocess.run([*CLI, "export", "opensees", str(cal), "--units", "kip,in,s", "--check", "-o", str(script)],
                         capture_output=True, text=True, env=cli_env(), timeout=300)
    assert res.returncode == 0, res.stderr[-2000:]
    printed = float(re.search(r"OF\(OpenSees vs model\) = (\S+),", res.stderr).group(1))
    res = subprocess.run([*CLI, "export", "fmu", str(cal), "-o", str(fmu)], capture_output=True, text=True,
                         env=cli_env(), timeout=600)
    assert res.returncode == 0, res.stderr[-2000:]
    printed_fmu = float(re.search(r"OF\(FMU vs model\) = (\S+) ", res.stderr).group(1))
    html = (out / "report.html").read_text()
    made = _exports_table(html, "the exports made")
    assert [(r[0], r[1], r[2], r[3]) for r in made] == [("opensees", "2", "damper.tcl", "kip,in,s"),
                                                        ("fmu", "2", "damper.fmu", "kN,mm,s")]
    assert float(made[0][5]) == pytest.approx(printed, rel=1e-2, abs=1e-15)
    assert float(made[1][5]) == pytest.approx(printed_fmu, rel=1e-2, abs=1e-15)
    hot = html.split("<h2>device hot</h2>", 1)[1].split("</section>", 1)[0]
    assert "the exports made" not in hot and "each model&#x27;s OpenSees material" in hot  # hot has none
    elsewhere = tmp_path / "law2.yaml"
    shutil.copy(cal, elsewhere)
    before = (out / "exports.json").read_text()
    res = subprocess.run([*CLI, "export", "opensees", str(elsewhere), "-o", str(tmp_path / "other.py")],
                         capture_output=True, text=True, env=cli_env(), timeout=300)
    assert res.returncode == 0 and (out / "exports.json").read_text() == before


def test_the_acceptance_nominal_ranks_on_the_same_data(tmp_path):
    """Issue 31, point 6: a device folder holding a one-test and a two-test
    calibration (two calibrate runs into one folder) picks the acceptance's
    nominal model by each model's OF on the test both were fitted on, not by
    their own OFs; its file gone, it ranks nothing and says so."""
    import fvd_bridge as fb
    from fvd_bridge.report.page import build_report

    slow = lab_record(VirtualDamper(C=45.0, alpha=0.3, name="sn1"), paper(velocity=150.0, cycles=3), seed=0,
                      tmp_path=tmp_path, name="sn1_slow")
    fast = lab_record(VirtualDamper(C=45.0, alpha=0.3, name="sn1"), paper(cycles=3), seed=1, tmp_path=tmp_path,
                      name="sn1_fast")
    one = fb.calibrate(slow, "1", intervals=0)
    two = fb.calibrate([slow, fast], "2", device="sn1", intervals=0)
    out = tmp_path / "out"
    one.save(str(out / "params" / "sn1" / "law1.yaml"))
    two.save(str(out / "params" / "sn1" / "law2.yaml"))
    build_report(str(out))
    best = min((one, two), key=lambda c: c.of_on(slow))
    assert f"nominal force: law {best.spec} (the lowest OF on sn1_slow)" in (out / "report.html").read_text()
    (tmp_path / "sn1_slow.csv").rename(tmp_path / "away.csv")
    build_report(str(out))
    assert ("nominal force: law 1 (fitted to different tests: not ranked, the first file&#x27;s)"
            in (out / "report.html").read_text())


def _viscous(amplitudes, freqs, C=1.0, dt=0.002, name="test"):
    """A linear viscous test, F = C v [kN], cycle k at amplitudes[k] [mm] and
    freqs[k] [Hz], phase-continuous, starting and ending at d = 0 moving up."""
    from fvd_bridge.records import Record

    t, d, v, t0 = [], [], [], 0.0
    for A, f in zip(amplitudes, freqs):
        s = np.arange(0.0, 1.0 / f, dt)
        t.append(t0 + s), d.append(A * np.sin(2 * np.pi * f * s)), v.append(2 * np.pi * f * A * np.cos(2 * np.pi * f * s))
        t0 += 1.0 / f
    t, d, v = np.concatenate(t), np.concatenate(d), np.concatenate(v)
    return Record(t, d, C * v, v, np.gradient(v, t), name=name)


def _rows(checks, what):
    return [c for c in checks if c.what.startswith(what)]


def test_acceptance_applies_the_cycle_rules_to_constant_amplitude_cycles_only():
    """Issue 32, point 3: on a ramped amplitude the per-cycle rules read 'not
    applicable' with the reason; on constant-amplitude cycles at one velocity
    they apply, hold the energy to pi C omega A^2 (a linear damper's loop,
    by hand), and fail where one cycle's energy is really off."""
    from fvd_bridge.report.acceptance import checks_of_test, levels

    ramp = _viscous(np.linspace(8.0, 40.0, 6), [1.0] * 6, name="ramp")
    checks = checks_of_test(ramp, nominal_force=None)
    energy = _rows(checks, "energy per cycle")
    assert len(energy) == 1 and energy[0].verdict == "not applicable" and energy[0].measured is None
    assert "amplitude" in energy[0].why_not and "constant amplitude" in energy[0].why_not
    assert _rows(checks, "peak force spread")[0].verdict == "not applicable"
    assert all(c.source for c in checks) and "ASCE 7-16" in energy[0].source

    steady = _viscous([20.0] * 6, [1.0] * 6, name="steady")
    energy = _rows(checks_of_test(steady, nominal_force=None), "energy per cycle")
    assert len(energy) == 1 and energy[0].verdict == "pass"
    assert "at 20.0 mm, 126 mm/s" in energy[0].what  # the level it applies to, stated
    assert energy[0].reference == pytest.approx(np.pi * 1.0 * 2 * np.pi * 1.0 * 20.0 ** 2, rel=2e-3)

    off = _viscous([20.0] * 6, [1.0] * 6, name="off")
    a, b = levels(off)[0].cycles[2]
    off.F[a:b + 1] *= 1.3  # one cycle dissipates 30% more: 1.3 / 1.06 - 1 = 23% above the mean of six
    energy = _rows(checks_of_test(off, nominal_force=None), "energy per cycle")[0]
    assert energy.verdict == "FAIL"
    assert energy.deviation == pytest.approx(1.3 / (1 + 0.3 / len(levels(off)[0].cycles)) - 1.0, rel=0.02)
    assert _rows(checks_of_test(off, None, tolerance=0.30), "energy per cycle")[0].verdict == "pass"  # a setting


def test_acceptance_checks_each_velocity_level_and_the_series_rule_needs_a_series():
    """Three cycles at each of three frequencies (one amplitude, as the rig's acceptance protocol): three levels,
    each checked at its own velocity; with one device the production check
    (against the series' nominal) is not applicable."""
    from fvd_bridge.report.acceptance import checks_of_test, levels

    rec = _viscous([20.0] * 9, [0.5] * 3 + [1.0] * 3 + [2.0] * 3, name="levels")
    assert [len(lv.cycles) for lv in levels(rec)] == [2, 2, 2]  # whole cycles; those straddling two levels left out
    assert [lv.velocity for lv in levels(rec)] == pytest.approx([2 * np.pi * f * 20.0 for f in (0.5, 1.0, 2.0)],
                                                                rel=0.01)
    checks = checks_of_test(rec, nominal_force=100.0, series_size=1)
    assert [c.verdict for c in _rows(checks, "energy per cycle")] == ["pass"] * 3
    production = _rows(checks, "force at")[0]
    assert production.verdict == "not applicable" and "one device" in production.why_not
    assert _rows(checks_of_test(rec, nominal_force=200.0, series_size=2), "force at")[0].verdict == "FAIL"


def test_a_parameter_fitted_per_test_shows_each_tests_value_and_interval():
    """The calibration table names a per-test parameter's tests and gives
    each its own value and 95% interval, as the file holds them."""
    from pathlib import Path

    import yaml

    from fvd_bridge.calibration import Calibration
    from fvd_bridge.report.html import parameter_rows

    path = Path(__file__).parents[1] / "fixtures" / "calibration_v3" / "device_per_test.yaml"
    C = yaml.safe_load(path.read_text())["parameters"]["C"]
    rows = {row[0]: row for row in parameter_rows(Calibration.load(path))}
    (first, value0), (second, value1) = C["per_test"].items()
    assert float(rows[f"C ({first})"][1]) == pytest.approx(value0, abs=C["stderr"])
    assert float(rows[f"C ({second})"][1]) == pytest.approx(value1, abs=C["stderr"])
    lo, hi = (float(x) for x in rows[f"C ({second})"][4].strip("[]").split(","))
    assert lo == pytest.approx(C["per_test_ci95"][second][0], abs=C["stderr"])
    assert hi == pytest.approx(C["per_test_ci95"][second][1], abs=C["stderr"])
    assert "C" not in rows and "alpha" in rows
