"""`fvd-bridge frame`: calibrated dampers of a series in the 3-story frame, end to end."""

import csv
import html
import json
import subprocess

import numpy as np
import pytest

from conftest import CLI, cli_env
from fvd_bridge.report.numbers import rounded


@pytest.fixture(scope="module")
def series(tmp_path_factory):
    """Calibration files of a 2-device series (laws 1 and 2) in calibrate's layout, and a short
    synthetic ground motion (2-column text: t [s], a [g])."""
    from fvd_bridge import calibrate
    from fvd_bridge.rig import VirtualDamper, Noise, paper, simulate

    root = tmp_path_factory.mktemp("series")
    for k, C in enumerate((44.0, 48.0)):
        rec = simulate(VirtualDamper(C=C, alpha=0.3, name=f"dev{k}"), paper(cycles=3), Noise(force=1.0, displacement=0.005),
                       seed=k)
        for spec in ("1", "2"):
            calibrate(rec, spec, seed=k, pop=8, gens=40).save(str(root / "cal" / "params" / rec.name / f"law{spec}.yaml"))
    t = np.arange(0.0, 4.0, 0.01)
    a = 0.3 * np.sin(2 * np.pi * 1.0 * t) * np.sin(np.pi * t / 4.0)
    (root / "quake.txt").write_text("# a 1 Hz pulse train [g]\n" + "\n".join(f"{x:.3f} {y:.6f}" for x, y in zip(t, a)))
    return root


def frame(*args):
    return subprocess.run([*CLI, "frame", *args], capture_output=True, text=True, env=cli_env(), timeout=900)


def test_frame_compares_laws_and_the_series(series, tmp_path):
    out = tmp_path / "fr"
    res = frame(str(series / "cal"), "--record", str(series / "quake.txt"), "--out", str(out), "--quiet",
                "--stroke-limit", "1.0")
    assert res.returncode == 0, res.stderr[-3000:]
    assert "verdict:" in res.stdout and "production series" in res.stdout
    rows = list(csv.DictReader(open(out / "frame_table.csv")))
    assert sorted(r["model"] for r in rows) == ["", "1", "1", "2", "2"]
    bare = next(r for r in rows if r["model"] == "")
    damped = [r for r in rows if r["model"]]
    # dampers take energy out: every damped case drifts less than the bare frame
    assert all(float(r["drift [%]"]) < float(bare["drift [%]"]) for r in damped)
    assert all(float(r["energy [kJ]"]) > 0 for r in damped)
    # the 1 mm stroke limit is exceeded and said so
    assert all("exceeds 1 mm" in r["exceeded"] for r in damped)
    spread = list(csv.DictReader(open(out / "frame_series.csv")))
    drift = [r for r in spread if r["quantity"] == "drift"]
    assert {r["model"] for r in drift} == {"1", "2"} and all(int(r["devices"]) == 2 for r in drift)
    assert all(float(r["min"]) <= float(r["mean"]) <= float(r["max"]) for r in drift)
    summary = json.load(open(out / "frame_summary.json"))
    page = (out / "report.html").read_text()
    assert all(html.escape(line) in page for line in summary["verdict_lines"])
    assert summary["verdict"].startswith("best-fitting model")
    for name in ("drift_profiles.png", "damper_hysteresis.png", "histories.png"):
        assert (out / "figures" / name).is_file()
    # each damper's deformation history replays on the rig
    hist = sorted((out / "histories").glob("dev0_law2_story1.csv"))
    assert hist
    rig = subprocess.run([*CLI, "rig", "--out", str(tmp_path / "replay"), "--protocol", f"history:{hist[0]}"],
                         capture_output=True, text=True, env=cli_env())
    assert rig.returncode == 0, rig.stderr


def test_frame_bad_input_gets_one_line(series, tmp_path):
    bad = tmp_path / "bad.txt"
    bad.write_text("0.00 0.1\n0.01 abc\n")
    res = frame(str(series / "cal"), "--record", str(bad), "--out", str(tmp_path / "x"))
    assert res.returncode == 2 and "bad.txt" in res.stderr and "line 2" in res.stderr
    assert "Traceback" not in res.stderr and not (tmp_path / "x").exists()
    res = frame(str(tmp_path / "nothing"), "--record", str(series / "quake.txt"))
    assert res.returncode == 2 and "no such file or folder" in res.stderr


def test_frame_tells_what_it_ran(series, tmp_path):
    """--duration that keeps little of the record's energy is warned about
    (with the share kept and where the strong motion is); N dampers per
    story of one device act as one device N times stronger (the same frame
    response; the force reported per damper, 1/N of it); the bare frame's
    damper columns print '-'; OpenSees' messages go to OUT/opensees.log, not
    to the console ('Process 0 Terminating' included)."""
    law2 = series / "cal" / "params" / "dev0" / "law2.yaml"
    rec = str(series / "quake.txt")
    short = frame(str(law2), "--record", rec, "--duration", "0.5", "--out", str(tmp_path / "a"), "--quiet",
                  "--no-figures")
    assert short.returncode == 0, short.stderr[-2000:]
    assert "warning: --duration 0.5 keeps" in short.stderr and "strong motion (5-95%) lies at" in short.stderr
    kept = json.load(open(tmp_path / "a" / "frame_summary.json"))["settings"]["energy_kept"]
    t = np.arange(0.0, 4.0, 0.01)
    a = 0.3 * np.sin(2 * np.pi * t) * np.sin(np.pi * t / 4.0)
    assert kept == pytest.approx(np.sum(a[t <= 0.5] ** 2) / np.sum(a ** 2), rel=1e-3)
    runs = {}
    for name, extra in (("two", ["--dampers-per-story", "2"]), ("double", ["--scale-force", "2"])):
        res = frame(str(law2), "--record", rec, "--out", str(tmp_path / name), "--no-figures", *extra)
        assert res.returncode == 0, res.stderr[-2000:]
        assert "Process 0 Terminating" not in res.stderr + res.stdout and "WARNING" not in res.stderr
        runs[name] = {r["case"]: r for r in csv.DictReader(open(tmp_path / name / "frame_table.csv"))}
        assert (tmp_path / name / "opensees.log").is_file()
        bare = next(line for line in res.stdout.splitlines() if line.startswith("bare frame"))
        assert bare.split()[-3:] == ["-", "-", "-"]
    case = next(k for k in runs["two"] if k != "bare frame")
    assert float(runs["two"][case]["drift [%]"]) == pytest.approx(float(runs["double"][case]["drift [%]"]), rel=1e-9)
    assert float(runs["two"][case]["force [kN]"]) == pytest.approx(0.5 * float(runs["double"][case]["force [kN]"]),
                                                                  rel=1e-9)
    one = frame(str(law2), "--record", rec, "--out", str(tmp_path / "one"), "--no-figures", "--quiet")
    assert one.returncode == 0, one.stderr[-2000:]
    single = {r["case"]: r for r in csv.DictReader(open(tmp_path / "one" / "frame_table.csv"))}
    assert float(single[case]["drift [%]"]) > float(runs["two"][case]["drift [%]"])
    bad = frame(str(law2), "--record", rec, "--dampers-per-story", "0", "--out", str(tmp_path / "z"))
    assert bad.returncode == 2 and "--dampers-per-story 0" in bad.stderr and not (tmp_path / "z").exists()


def test_an_analysis_that_stops_early_is_left_out_of_the_verdict(series, tmp_path):
    """Each case's summary gives where its analysis ended and where the record
    does (analysis_end_s past record_end_s: the free vibration after it); a
    case that stopped early is left out of the series statistics and the
    verdict, which names it with the time it stopped at."""
    from types import SimpleNamespace

    from fvd_bridge.frames.compare import Case
    from fvd_bridge.frames.verdict import series_spread, verdict

    out = tmp_path / "fr"
    res = frame(str(series / "cal" / "params" / "dev0"), "--record", str(series / "quake.txt"), "--out", str(out),
                "--quiet", "--no-figures")
    assert res.returncode == 0, res.stderr[-2000:]
    for case in json.load(open(out / "frame_summary.json"))["cases"]:
        r = case["response"]
        assert r["record_end_s"] == pytest.approx(3.99, abs=1e-6) and r["analysis_end_s"] > r["record_end_s"]
        assert r["solver"]["completed"]

    def case(spec, drift, completed):
        solver = SimpleNamespace(completed=completed, failed_at=None if completed else 37.4)
        result = SimpleNamespace(solver=solver, record_end=53.7, t=np.array([0.0]))
        c = Case(f"law {spec} | dev", spec, "dev", 0.01 if spec == "9" else 0.02, result=result, n_params=2)
        c.values = lambda: {"drift": drift, "residual": 0.0, "pfa": 0.3, "force": 100.0, "stroke": 10.0,
                            "energy": 1.0}
        return c
    cases = [case("2", 1.00, False), case("1", 1.02, True), case("9", 1.01, True)]
    spread = series_spread(cases)
    assert set(spread) == {"1", "9"}
    text = verdict(spread, cases)
    assert "simplest within 5% on peak drift and damper force: law 1" in text
    assert "left out, the analysis did not reach its end: law 2 | dev (stopped at 37.4 s of the record's 53.7 s)" in text


def test_dampers_too_small_to_matter_are_said_so_with_the_command_that_sizes_them(series, tmp_path):
    """Issue 32, point 4: below 2% of critical damping in the first mode
    (energy method at the stated roof drift) the verdict says the dampers are
    too small to matter and gives the command that sizes them; the page and
    the printed table show no raw float; bad sizing options get one line."""
    import re

    law2 = str(series / "cal" / "params" / "dev0" / "law2.yaml")
    rec = str(series / "quake.txt")
    out = tmp_path / "small"
    res = frame(law2, "--record", rec, "--duration", "1.5", "--design-drift", "0.03", "--out", str(out), "--quiet")
    assert res.returncode == 0, res.stderr[-2000:]
    summary = json.load(open(out / "frame_summary.json"))
    xi = summary["cases"][1]["supplemental_damping"]
    assert xi["target"] is None and xi["achieved"] is None and 0 < xi["estimated"] < 0.02
    line = summary["verdict_lines"][-1]
    assert "too small to matter" in line and f"--record {rec} --duration 1.5 --design-drift 0.03 " \
        "--target-damping 0.2" in line
    assert "the choice of model" not in summary["verdict"]  # one model: no choice to weigh
    page = (out / "report.html").read_text()
    cells = re.findall(r"<td>([^<]*)</td>", page)
    digits = [len(re.sub(r"\D", "", c.lstrip("0.-"))) for c in cells if re.fullmatch(r"-?[0-9.]+", c)]
    assert digits and max(digits) <= 6
    # the page opens with the answer: the damper, and that it is too small to matter, with the command
    answer = summary["answer"]
    assert answer[0] == "Damper: law 2, 1 per story: dev0." and "<b>Damper:</b> law 2, 1 per story: dev0." in page
    assert page.index("class='answer'") < page.index("<table")
    damping = next(line for line in answer if line.startswith("Damping:"))
    assert "too small to matter" in damping and "--target-damping 0.2" in damping
    assert html.escape(damping.partition(": ")[2]) in page and f"  {damping}" in res.stdout
    assert not re.search(r"\d\.\d{7,}", res.stdout)
    both = frame(law2, "--record", rec, "--target-damping", "0.2", "--scale-force", "2", "--out", str(tmp_path / "b"))
    assert both.returncode == 2 and "--scale-force" in both.stderr and not (tmp_path / "b").exists()
    big = frame(law2, "--record", rec, "--target-damping", "20", "--out", str(tmp_path / "c"))
    assert big.returncode == 2 and "--target-damping 20" in big.stderr and "Traceback" not in big.stderr


def test_the_old_bounds_option_still_runs_with_a_one_line_note(capsys):
    """frame's ASCE 7 property bounds are --property-bounds (--bounds alone is calibrate's search box); the old
    name still reads the same value, says so in one line on stderr, and is left out of the help."""
    from fvd_bridge.cli import build_parser

    parser = build_parser("frame")
    given = ["frame", "cal.yaml", "--record", "quake.txt"]
    new = parser.parse_args([*given, "--property-bounds", "0.8,1.25"])
    assert new.property_bounds == "0.8,1.25" and capsys.readouterr().err == ""
    old = parser.parse_args([*given, "--bounds", "0.8,1.25"])
    note = capsys.readouterr().err
    assert old.property_bounds == "0.8,1.25" and note.count("\n") == 1
    assert note.startswith("note: frame --bounds is now --property-bounds")
    with pytest.raises(SystemExit):
        parser.parse_args(["frame", "--help"])
    shown = capsys.readouterr().out
    assert "--property-bounds" in shown and "--bounds" not in shown


@pytest.fixture(scope="module")
def one_and_two_tests(tmp_path_factory, series):
    """Calibrations of one lab-like device (two tests, files with their
    sidecars): law 1 on its slow test, law 2 on both tests, law 2 on the
    slow test alone; the quake of ``series``."""
    import fvd_bridge as fb
    from fvd_bridge.rig import VirtualDamper, paper

    from lab import lab_record

    root = tmp_path_factory.mktemp("tests")
    device = VirtualDamper(C=45.0, alpha=0.3, name="sn1")
    slow = lab_record(device, paper(velocity=150.0, cycles=3), seed=0, tmp_path=root, name="sn1_slow")
    fast = lab_record(device, paper(cycles=3), seed=1, tmp_path=root, name="sn1_fast")
    cals = {"law1_slow": fb.calibrate(slow, "1", intervals=0),
            "law2_both": fb.calibrate([slow, fast], "2", device="sn1", intervals=0),
            "law2_slow": fb.calibrate(slow, "2", intervals=0)}
    for name, cal in cals.items():
        cal.save(str(root / f"{name}.yaml"))
    return root, cals, slow, fast, series / "quake.txt"


def test_frame_ranks_models_on_the_same_data_only(one_and_two_tests, tmp_path):
    """Issue 31, point 6: a one-test calibration and a two-test one are not
    ranked by their own OFs.  Their common test's file at hand: both are
    ranked by their OF on it (the verdict says on what); gone: not ranked,
    and the verdict says why in one line; --rank-on FILE ranks them on that
    record.  Two calibrations on the same test rank by their own OFs, as before."""
    root, cals, slow, fast, quake = one_and_two_tests
    one, two = str(root / "law1_slow.yaml"), str(root / "law2_both.yaml")

    def run(name, *args):
        res = frame(*args, "--record", str(quake), "--duration", "1.5", "--out", str(tmp_path / name), "--quiet",
                    "--no-figures")
        assert res.returncode == 0, res.stderr[-2000:]
        summary = json.load(open(tmp_path / name / "frame_summary.json"))
        assert all(f"  - {line}" in res.stdout for line in summary["verdict_lines"])
        assert summary["verdict"] == "; ".join(summary["verdict_lines"])
        return summary

    common = run("common", one, two)
    of_there = {"1": cals["law1_slow"].of_on(slow), "2": cals["law2_both"].of_on(slow)}
    best = min(of_there, key=of_there.get)
    assert common["verdict"].startswith(f"best-fitting model on the test sn1_slow, which every model was fitted on: "
                                        f"law {best} (mean OF there {rounded(of_there[best])})")
    assert {s: v["common_of"] for s, v in common["series"].items()} == pytest.approx(of_there, rel=1e-9)
    # law 2 on both tests: its OF on the slow test is not its calibration OF (the mean over both)
    assert of_there["2"] != pytest.approx(cals["law2_both"].of, rel=1e-3)
    page = (tmp_path / "common" / "report.html").read_text()
    assert all(html.escape(line) in page for line in common["verdict_lines"])

    (root / "sn1_slow.csv").rename(root / "away.csv")
    try:
        gone = run("gone", one, two)
    finally:
        (root / "away.csv").rename(root / "sn1_slow.csv")
    assert gone["verdict"].startswith("fitted to different tests: not ranked (law 1 on sn1_slow; law 2 on sn1_fast, "
                                      "sn1_slow; give a test record to rank them on, frame --rank-on FILE)")
    assert "best-fitting" not in gone["verdict"] and "simplest" not in gone["verdict"]
    assert all(v["common_of"] is None for v in gone["series"].values())

    given = run("given", one, two, "--rank-on", str(root / "sn1_fast.csv"))
    of_fast = {"1": cals["law1_slow"].of_on(fast), "2": cals["law2_both"].of_on(fast)}
    best = min(of_fast, key=of_fast.get)
    assert given["verdict"].startswith(f"best-fitting model on the record sn1_fast: law {best} "
                                       f"(mean OF there {rounded(of_fast[best])})")
    assert [c["ranked_on"]["of"] for c in given["cases"][1:]] == pytest.approx([of_fast["1"], of_fast["2"]])

    same = run("same", one, str(root / "law2_slow.yaml"))
    own = {"1": cals["law1_slow"].of, "2": cals["law2_slow"].of}
    best = min(own, key=own.get)
    assert same["verdict"].startswith(f"best-fitting model: law {best} (mean OF {rounded(own[best])})")
    assert all(c["ranked_on"] is None for c in same["cases"])


@pytest.mark.parametrize("building", ["3-story", "9-story"])
def test_frame_prints_the_periods_beside_the_benchmark(building):
    """``frame --building B --periods --json``: the bare frame's first three
    periods (frame_periods') and the benchmark's, as one JSON line."""
    from fvd_bridge.frames.buildings import nine_story, three_story
    from fvd_bridge.frames.model import frame_periods

    res = subprocess.run(CLI + ["frame", "--building", building, "--periods", "--json"], capture_output=True,
                         text=True, env=cli_env())
    assert res.returncode == 0, res.stderr
    out = json.loads(res.stdout.strip().splitlines()[-1])
    b = three_story() if building == "3-story" else nine_story()
    assert out["periods"] == pytest.approx(frame_periods(b, 3).tolist(), rel=1e-9)
    f, ref = np.asarray(out["frequencies"]), np.asarray(out["benchmark_frequencies"])
    assert ref.tolist() == pytest.approx([0.99, 3.06, 5.83] if building == "3-story" else [0.443, 1.18, 2.05])
    assert np.all(np.abs(f / ref - 1) < 0.002)
    table = subprocess.run(CLI + ["frame", "--building", building, "--periods"], capture_output=True, text=True,
                           env=cli_env()).stdout
    assert "benchmark" in table and len([line for line in table.splitlines() if line.strip()[:1].isdigit()]) == 3
    missing = subprocess.run(CLI + ["frame", "--building", building], capture_output=True, text=True, env=cli_env())
    assert missing.returncode == 2 and "PARAMS" in missing.stderr and "Traceback" not in missing.stderr
