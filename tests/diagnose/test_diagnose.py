"""diagnose on lab-like rig records (t,d,F read back, velocity derived): the
ladder finds two planted effects and stops; a plugin effect is calibrated
and ranked; where the model fails; the CLI's JSON, figures and bad input.
(Each planted effect alone, and no effect: tests/diagnose/test_diagnose_lab.py.)"""

from __future__ import annotations

import dataclasses
import shlex
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import CLI, PLUGIN, REPO, cli_env
import fvd_bridge as fb
from fvd_bridge import FittedParameter, cli
from fvd_bridge.diagnose import climb, diagnose, diagnose_settings
from fvd_bridge.fit import fit_model
from fvd_bridge.fit.objective import AT_FLOOR, NEAR_FLOOR
from fvd_bridge.catalog import catalog
from fvd_bridge.records import Record, read_record
from fvd_bridge.records.writers import write_csv
from fvd_bridge.rig import VirtualDamper, acceptance, paper
from fvd_bridge.text.diagnosis import format_ladder
from lab import lab_record

C, ALPHA = 45.4, 0.3
#: small optimizer settings: DE population per parameter, generations, polish evaluations
SETTINGS = diagnose_settings(8, 60)
#: planted effects, clearly above 1 kN of force noise and 0.005 mm of displacement noise
PLANTED = {
    "friction": dict(friction=60.0),
    "thermal_softening": dict(heating=3.0),
    "gap": dict(gap=2.5),
    "asymmetry": dict(asymmetry=0.12),
}
SEVEN = ("gap", "series_stiffness", "asymmetry", "thermal_softening", "friction", "parallel_stiffness", "inertia")


@pytest.fixture(scope="module")
def protocol():
    """Acceptance test (5 velocity levels, 2 cycles each, 0.5 to 4 Hz), 2657 samples."""
    return acceptance(dt=0.005, cycles=2)


@pytest.fixture(scope="module")
def lab_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("lab")


def rig_record(protocol, folder, name="none", seed=11, **params) -> Record:
    """A lab-like record (CSV t,d,F read back, velocity derived; 1 kN force and
    0.005 mm displacement noise) of the rig's law-2 orifice with ``params``."""
    return lab_record(VirtualDamper(C=C, alpha=ALPHA, **params), protocol, 1.0, 0.005, seed, folder, name=name)


def test_ladder_finds_two_planted_effects_and_stops(protocol, lab_dir):
    rec = rig_record(protocol, lab_dir, "two", friction=60.0, heating=3.0)
    lad = climb(rec, "2", seed=0, settings=SETTINGS)
    added = [r.spec.split("+")[-1] for r in lad.rungs[1:]]
    assert sorted(added) == ["friction", "thermal_softening"], format_ladder(lad)
    assert lad.stop
    ofs = [r.of for r in lad.rungs]
    assert ofs == sorted(ofs, reverse=True) and all(r.improvement > 0.2 for r in lad.rungs[1:])
    assert ofs[-1] <= 2.0 * lad.final.floor
    # the floor is the record's: every rung is judged against the first rung's
    assert len({d.floor for d in lad.diagnoses}) == 1
    p = lad.rungs[-1].params
    assert p["friction.Ff"] == pytest.approx(60.0, rel=0.1)
    assert p["thermal_softening.theta"] == pytest.approx(3.0, rel=0.2)
    assert "ladder" in format_ladder(lad) and "stopped" in format_ladder(lad)




def test_the_verdict_reads_the_misfit_against_the_floor_as_the_report_page_does(tmp_path, protocol, lab_dir):
    """With no candidate credited, the verdict reads the OF against the
    noise floor with the report page's thresholds (``fit.objective``): up to
    NEAR_FLOOR it is close to the noise (the page: "little is left to
    explain"), beyond it the misfit is not a known effect.  Close: the
    rig's default device, an exact orifice whose record has no force noise
    (``fvd-bridge rig`` as a user runs it), 1.6-1.7x its floor; before, it
    was called an unknown effect.  Beyond: a 6 kN force at 0.37 Hz that
    follows neither d nor v (a load-cell pick-up), 4x the floor."""
    assert cli.main(["rig", "--out", str(tmp_path / "rig")]) == 0
    exact = read_record(str(tmp_path / "rig" / "device_01.csv"))
    diag = diagnose(exact, "2", seed=0, settings=SETTINGS)
    assert not diag.at_floor and AT_FLOOR < diag.of / diag.floor <= NEAR_FLOOR and diag.best is None
    assert "close to the noise" in diag.verdict() and "or the floor (an estimate) is low" in diag.verdict()
    base = rig_record(protocol, lab_dir, "pickup")
    pickup = dataclasses.replace(base, F=base.F + 6.0 * np.sin(2 * np.pi * 0.37 * base.t), name="pickup")
    diag = diagnose(pickup, "2", seed=0, settings=SETTINGS)
    assert diag.of > NEAR_FLOOR * diag.floor and diag.best is None
    assert diag.verdict().endswith("the misfit is not one of the known effects")


def test_plugin_effect_is_calibrated_and_ranked(protocol, tmp_path, lab_dir):
    path = tmp_path / "my_effect.py"
    path.write_text(PLUGIN)
    cat = catalog([str(path)])
    base = rig_record(protocol, lab_dir, "cubic")
    K3 = 0.004  # 32 kN at 20 mm
    rec = dataclasses.replace(base, F=base.F + K3 * base.d ** 3, name="cubic")  # its derived v kept
    diag = diagnose(rec, "2", seed=0, settings=SETTINGS, catalog=cat)
    assert diag.candidates[0].effect == "cubic_spring" and diag.candidates[0].significant
    assert len(diag.candidates) == 8
    fit = fit_model(cat.model("2+cubic_spring"), rec, seed=1, settings=SETTINGS)
    assert fit.names[-1] == "cubic_spring.K3"
    assert fit.values[-1] == pytest.approx(K3, rel=0.05)
    assert fit.of <= 2.0 * diag.floor


# ------------------------------------------------------------------ the CLI
@pytest.fixture(scope="module")
def friction_csv(protocol, tmp_path_factory, lab_dir):
    path = tmp_path_factory.mktemp("diag") / "friction_dev.csv"
    write_csv(rig_record(protocol, lab_dir, "friction_dev", **PLANTED["friction"]), str(path))  # t,d,F
    return path


def test_cli_json_report_and_figures(friction_csv, tmp_path, capsys):
    out = tmp_path / "out"
    code = cli.main(["diagnose", str(friction_csv), "--law", "2", "--json", "--out", str(out),
                     "--pop", "8", "--gens", "60", "--quiet"])
    assert code == 0
    report = json.loads(capsys.readouterr().out)
    assert report["model"] == "2"
    assert report["of"] > NEAR_FLOOR * report["noise_floor_of"] > 0  # beyond NEAR_FLOOR: something to explain
    assert report["candidates"][0]["effect"] == "friction"
    assert set(report["candidates"][0]) >= {"effect", "of", "improvement"}
    assert [c["of"] for c in report["candidates"]] == sorted(c["of"] for c in report["candidates"])
    assert {c["effect"] for c in report["all_candidates"]} == set(SEVEN)
    assert (out / "friction_dev_where.png").stat().st_size > 10_000
    page = (out / "report.html").read_text()
    assert "diagnosis of 2 on friction_dev" in page and "data:image/png;base64," in page
    assert json.loads((out / "friction_dev_diagnose.json").read_text())["model"] == "2"
    assert not list(tmp_path.glob(".out.partial*"))
    # diagnose hands over what it found: the top candidate's calibration file, its OF the
    # candidate's, and it exports to what the candidate says
    from fvd_bridge.calibration import Calibration
    from fvd_bridge.export.opensees import opensees_export

    top = next(c for c in report["all_candidates"] if c["effect"] == "friction")
    cal = Calibration.load(report["candidates"][0]["calibration"])
    assert cal.spec == "2+friction" and cal.of == pytest.approx(top["of"], rel=1e-12)
    assert top["calibration"] == report["candidates"][0]["calibration"] and "opensees" in top["exports"]
    assert opensees_export(cal.model, cal.named()).commands


def test_cli_next_step_shows_the_error_fallen(friction_csv, tmp_path, capsys):
    code = cli.main(["diagnose", str(friction_csv), "--law", "2+friction", "--out", str(tmp_path),
                     "--pop", "8", "--gens", "60", "--quiet", "--no-figures"])
    assert code == 0
    out = capsys.readouterr().out
    # the exact model: nothing more is suggested (the OF is near the floor; friction at the
    # rests between levels meets the derived velocity's noise there, which keeps it above 1x)
    assert "with model 2+friction" in out and "suggestion:" not in out and "next:" not in out
    assert "friction.Ff = " in out and "error fell from OF" in out and "(2) to" in out


def test_cli_ladder_prints_table_and_writes_figure(friction_csv, tmp_path, capsys):
    code = cli.main(["diagnose", str(friction_csv), "--law", "2", "--ladder", "--out", str(tmp_path),
                     "--pop", "8", "--gens", "60", "--quiet"])
    assert code == 0
    out = capsys.readouterr().out
    assert "ladder (each rung" in out and "2+friction" in out and "stopped:" in out
    assert (tmp_path / "friction_dev_ladder.png").stat().st_size > 5_000
    report = json.loads((tmp_path / "friction_dev_diagnose.json").read_text())
    assert [r["model"] for r in report["ladder"]["rungs"]] == ["2", "2+friction"]
    assert all(Path(r["calibration"]).is_file() for r in report["ladder"]["rungs"])


@pytest.mark.parametrize("extra, words", [
    (["--law", "2+fricton"], ["unknown effect 'fricton'"]),
    (["--law", "2+friction+friction"], ["appears twice"]),
    (["--law", "2", "--plugin", "PLUGIN_BAD"], ["bad_plugin.py", "syntax error"]),
    (["--law", "2", "--plugin", "PLUGIN_CLASH"], ["clashes with the built-in"]),
    (["--law", "2", "--pop", "0"], ["--pop 0"]),
    (["--law", "2", "--per-test", "C"], ["--per-test needs --device"]),
    (["--law", "2", "--device", "dev", "--per-test", "K"], ["--per-test K", "no parameter 'K'"]),
    (["--law", "2", "--device", "dev", "--per-test", "9:C"], ["--per-test 9:C", "not the model diagnosed"]),
])
def test_cli_bad_input_one_line_exit_2(friction_csv, tmp_path, capsys, extra, words):
    bad = tmp_path / "bad_plugin.py"
    bad.write_text("def f(:\n")
    clash = tmp_path / "clash_plugin.py"
    clash.write_text(PLUGIN.replace('name="cubic_spring"', 'name="gap"'))
    extra = [str(bad) if a == "PLUGIN_BAD" else str(clash) if a == "PLUGIN_CLASH" else a for a in extra]
    code = cli.main(["diagnose", str(friction_csv), "--out", str(tmp_path / "o"), *extra])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1, err
    assert all(w in err for w in words), err
    assert not (tmp_path / "o").exists()  # nothing written


def test_cli_missing_record_in_a_subprocess(tmp_path):
    res = subprocess.run([sys.executable, "-m", "fvd_bridge.cli", "diagnose", str(tmp_path / "nope.csv"),
                          "--law", "2"], capture_output=True, text=True, env=cli_env(), cwd=tmp_path)
    assert res.returncode == 2 and res.stdout == ""
    assert len(res.stderr.strip().splitlines()) == 1 and "no such file" in res.stderr


# ------------------------------------------------------------------ where it fails
def test_where_numbers_point_at_the_effect(protocol, lab_dir):
    fits = {}
    for name, params in (("asymmetry", PLANTED["asymmetry"]), ("thermal_softening", PLANTED["thermal_softening"]),
                         ("gap", dict(gap=1.0))):  # a 1 mm dead band lies within 20% of the peak velocity
        rec = rig_record(protocol, lab_dir, name, **params)
        fits[name] = diagnose(rec, "2", seed=0, settings=SETTINGS, candidates=False).where
    w = fits["asymmetry"]  # r = 0.12: the symmetric model is weaker in tension than in compression
    # (the L1 fit follows one side: signed residuals differ by about r x the mean force)
    assert w.tension.signed - w.compression.signed > 10.0
    w = fits["thermal_softening"]  # softening: the constant model is too weak early, too strong late
    assert w.early.signed > w.late.signed
    w = fits["gap"]  # dead band at the reversals
    assert w.reversal.error_share > 1.2 * w.reversal.time_share
    assert len(w.levels) == 5 and [lv.peak_v for lv in w.levels] == sorted(lv.peak_v for lv in w.levels)


def test_a_diagnosis_keeps_what_it_was_run_on(protocol, lab_dir):
    """``Diagnosis.inputs`` is a frozen DiagnosisInputs: the record, seed,
    settings and catalog given, and the record's noise floor of each test;
    its parameters and units are its fit's, in the fit's order."""
    from fvd_bridge.diagnose.core import DiagnosisInputs
    from fvd_bridge.fit.floor import NoiseFloor

    rec = rig_record(protocol, lab_dir, "inputs", seed=7)
    cat = catalog()
    diag = diagnose(rec, "2", seed=4, settings=SETTINGS, candidates=False, parent=None, catalog=cat)
    i = diag.inputs
    assert isinstance(i, DiagnosisInputs)
    assert i.record is rec and i.seed == 4 and i.settings is SETTINGS and i.catalog is cat
    assert len(i.floors) == 1 and i.floors[0].floor == diag.floor
    # its noise floor is a NoiseFloor: the force-only part is s sqrt(2/pi) / std(F) (floor.py)
    n = diag.noise
    assert isinstance(n, NoiseFloor) and n.sigma_F == diag.noise_std and n.sigma_d > 0 and n.sigma_v > 0
    assert n.force_floor == pytest.approx(n.sigma_F * np.sqrt(2 / np.pi) / np.std(rec.F), rel=1e-12)
    assert diag.as_dict()["noise"] == dataclasses.asdict(n) and diag.parent is None and diag.tests == []
    assert [r.how for r in diag.base_history] == ["fitted as calibrate"] and diag.base_history[0].of == diag.of
    with pytest.raises(dataclasses.FrozenInstanceError):
        i.seed = 5
    # as a Calibration speaks: .params the FittedParameters, .named() their values
    assert diag.params == diag.fit.params and isinstance(diag.params["C"], FittedParameter)
    assert diag.named() == {n: p.value for n, p in diag.params.items()} == diag.as_dict()["params"]
    assert diag.units() == {"C": "kN/(mm/s)^alpha", "alpha": "-"} == diag.as_dict()["units"]
    assert list(diag.named()) == diag.fit.names and diag.named()["C"] == pytest.approx(C, rel=0.03)


@pytest.mark.slow
def test_custom_effect_example_runs():
    res = subprocess.run([sys.executable, str(REPO / "examples" / "custom_effect.py")], capture_output=True,
                         text=True, env=cli_env(), timeout=600)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "ranked first: stribeck" in res.stdout


@pytest.mark.slow
def test_mr_damper_ladder_example(device_files, tmp_path):
    res = subprocess.run([sys.executable, str(REPO / "examples" / "diagnose_mr_damper.py"), "--quick",
                          "--max-rungs", "1", "--out", str(tmp_path / "mr")], capture_output=True, text=True,
                         env=cli_env(), timeout=600, cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    out = res.stdout
    assert out.count("ladder (each rung") == 2 and "what it means" in out
    assert "x the noise floor" in out
    for name in ("mr_0V", "mr_0.88V"):
        assert (tmp_path / "mr" / f"{name}_ladder.png").is_file()


def test_mr_damper_example_without_shared(tmp_path, monkeypatch):
    import importlib.util

    spec = importlib.util.spec_from_file_location("diag_mr", REPO / "examples" / "diagnose_mr_damper.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    monkeypatch.setattr(mod, "DEVICES", tmp_path / "nowhere")
    assert mod.main(["--out", str(tmp_path / "o")]) == 0
    assert not (tmp_path / "o").exists()


def test_next_lines_run_as_printed(friction_csv, tmp_path, capsys):
    """The text report's next: lines are commands that run as printed: export the
    top candidate's calibration file, diagnose it further on the same record."""
    code = cli.main(["diagnose", str(friction_csv), "--law", "2", "--out", str(tmp_path / "d"),
                     "--pop", "8", "--gens", "60", "--quiet", "--no-figures"])
    assert code == 0
    out = capsys.readouterr().out
    lines = [line[len("next: "):] for line in out.splitlines() if line.startswith("next: ")]
    export, again = lines
    assert export.startswith("fvd-bridge export opensees ") and "--law 2+friction --out " in again
    # it writes beside this diagnosis, not over it
    assert shlex.split(again)[-1] == str(tmp_path / "diagnose_2+friction")
    # one test: the verdict says its check was the held-out cycles of that test
    assert "checked on this test's held-out cycles only" in out
    assert str(friction_csv) in again
    # each calibration file it wrote is listed with the OF the file holds (refitted as calibrate fits)
    listed = dict(line.strip().split(": OF ") for line in out.split("calibration files")[1].split("\n\n")[0]
                  .splitlines()[1:])
    assert listed and shlex.split(export)[3] in listed
    for path, of in listed.items():
        assert float(of.split(",")[0]) == pytest.approx(fb.Calibration.load(path).of, rel=1e-3)  # printed to 4 digits
    res = subprocess.run([*CLI, *shlex.split(export)[1:]], capture_output=True, text=True, env=cli_env(),
                         cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert (tmp_path / "damper.py").is_file()


# ------------------------------------------------------------------ --per-test
@pytest.fixture(scope="module")
def disagreeing_tests(tmp_path_factory):
    """Two lab CSVs (t,d,F and their sidecars) of one law-2 device whose C moved
    from 40 to 48 between the tests, and the records read back."""
    folder = tmp_path_factory.mktemp("per_test")
    records = [lab_record(VirtualDamper(C=c, alpha=ALPHA), paper(amplitude=amp, velocity=vel, cycles=3, dt=0.004),
                          0.8, 0.01, seed, folder, name=name)
               for c, amp, vel, seed, name in ((40.0, 20.0, 250.0, 1, "dev_a"), (48.0, 30.0, 450.0, 2, "dev_b"))]
    return [folder / "dev_a.csv", folder / "dev_b.csv"], records


def test_cli_per_test_advice_and_the_command_it_prints(disagreeing_tests, tmp_path, capsys, monkeypatch):
    """diagnose --device says the tests disagree on C and prints next: commands
    with --per-test C; the printed diagnose runs as printed, fits C per test and
    finds nothing left to explain."""
    paths, _ = disagreeing_tests
    monkeypatch.chdir(tmp_path)
    fast = ["--pop", "8", "--gens", "60", "--quiet", "--no-figures"]
    assert cli.main(["diagnose", *map(str, paths), "--device", "dev", "--law", "2", *fast]) == 0
    out = capsys.readouterr().out
    assert "suggestion: the tests disagree: C differs between tests" in out, out
    calibrate, again = [line[len("next: "):] for line in out.splitlines() if line.startswith("next: ")]
    assert calibrate.startswith("fvd-bridge calibrate ") and "--laws 2 --per-test C" in calibrate
    assert again.startswith("fvd-bridge diagnose ") and "--law 2 --per-test C --out " in again
    assert shlex.split(again)[-1] == "results/diagnose_per_test_C"  # beside results/diagnose, not over it
    assert cli.main([*shlex.split(again)[1:], "--json", *fast]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["per_test"] == ["C"] and report["settings"]["per_test"] == ["C"]
    assert report["params"]["C"] == pytest.approx(40.0, rel=0.03)
    assert report["params"]["C@dev_b"] == pytest.approx(48.0, rel=0.03)
    assert report["at_noise_floor"] and report["agreement"]["advice"] is None, report["verdict"]
    assert (tmp_path / "results" / "diagnose" / "dev_diagnose.json").is_file()
    assert (tmp_path / "results" / "diagnose_per_test_C" / "dev_diagnose.json").is_file()


def test_api_diagnose_per_test_and_the_ladder(disagreeing_tests):
    """fb.diagnose(per_test=[...]) fits the parameter per test, the base and every
    candidate; its ladder keeps it; without it the Diagnosis carries the advice."""
    import fvd_bridge as fb

    _, records = disagreeing_tests
    diag = fb.diagnose(records, "2", device="dev")
    assert diag.advice.name == "C" and diag.verdict().startswith("the tests disagree: C")
    stopped = diag.ladder()  # no effect is added to a model whose tests disagree
    assert [r.spec for r in stopped.rungs] == ["2"] and stopped.stop == diag.verdict()
    freed = fb.diagnose(records, "2", device="dev", per_test=["C"])
    assert freed.per_test == ("C",) and freed.advice is None
    assert freed.named()["C@dev_b"] == pytest.approx(48.0, rel=0.03)
    assert all("C@dev_b" in c.fit.names for c in freed.candidates)
    lad = freed.ladder()
    assert [r.spec for r in lad.rungs] == ["2"] and "noise floor" in lad.stop
    assert "C@dev_b" in lad.rungs[0].params
    with pytest.raises(fb.InputError, match="per_test"):
        fb.diagnose(records, "2", device="dev", per_test=["K"])


def test_the_floor_is_the_records_and_what_the_true_model_reaches(protocol, lab_dir):
    """The floor through the fitted law (effects off) estimates the OF the
    true law reaches on the record (its noise alone), and a model with an
    effect gets the same floor: a gap's refit does not move it.  The truth:
    law 2 at the rig's C and alpha on the record, which carries 1 kN force
    and 0.005 mm displacement noise; the floor's 4 Monte Carlo draws and the
    one record's noise make it accurate to about 10%."""
    from fvd_bridge.fit.floor import record_floor
    from fvd_bridge.fit import evaluate_params

    rec = rig_record(protocol, lab_dir, "floor", seed=5)
    law2 = catalog().model("2")
    truth_of = evaluate_params(law2, rec, [C, ALPHA])
    fitted = fit_model(law2, rec, seed=0)
    floor = record_floor(law2, fitted.values, rec).floor
    assert 0.8 * truth_of < floor < 1.25 * truth_of
    gap = catalog().model("2+gap")
    with_gap = fit_model(gap, rec, seed=0)
    assert record_floor(gap, with_gap.values, rec).floor == pytest.approx(floor, rel=0.02)


def test_target_ranks_only_what_reaches_it(friction_csv, tmp_path, capsys):
    """--target sap2000: friction (the planted effect) has no CSI damper link,
    so it is left out, named with its gain and why; nothing that reaches
    SAP2000 helps, so no export is printed; the same diagnosis without a
    target suggests friction and exports it to OpenSees (its verdict, its
    next line)."""
    code = cli.main(["diagnose", str(friction_csv), "--law", "2", "--target", "sap2000", "--out",
                     str(tmp_path / "d"), "--pop", "8", "--gens", "60", "--quiet", "--no-figures"])
    assert code == 0
    out = capsys.readouterr().out
    report = json.loads((tmp_path / "d" / "friction_dev_diagnose.json").read_text())
    assert report["target"] == "sap2000" and report["candidates"] == []
    assert report["left_out"]["spec"] == "2+friction" and "effect 'friction'" in report["left_out"]["why"]
    assert "does not reach SAP2000: effect 'friction'" in out and "next:" not in out
    page = (tmp_path / "d" / "report.html").read_text()
    diagnosis = page.split("<section class='diagnosis'>")[1].split("</section>")[0]
    assert "does not reach SAP2000" in diagnosis and "fvd-bridge export" not in diagnosis  # the page follows it
    assert "<b>Target:</b> SAP2000" in diagnosis and "left out: 2+friction" in diagnosis


def test_target_refuses_an_unknown_one_in_one_line(friction_csv, tmp_path, capsys):
    code = cli.main(["diagnose", str(friction_csv), "--law", "2", "--target", "abaqus", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "abaqus" in err and "sap2000" in err, err
    assert not (tmp_path / "o").exists()
