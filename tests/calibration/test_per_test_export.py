"""A parameter fitted per test is never one test's value in silence.

Two lab-like tests (t,d,F CSVs with force and displacement noise) of one
law-2 device whose damping changed between them (C 40, then 52
kN/(mm/s)^alpha: a temperature), calibrated with C per test: export,
compare and frame refuse the calibration without a test named, naming the
tests and their values in one line (exit 2, nothing written); with
``--test B`` / ``test="B"`` they take test B's values from the file, and
the export says so.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
import yaml

import fvd_bridge as fb
from fvd_bridge import cli
from fvd_bridge.rig import VirtualDamper, paper

from lab import lab_record

TRUE_C = {"A": 40.0, "B": 52.0}  # kN/(mm/s)^alpha; alpha 0.3 on both


@pytest.fixture(scope="module")
def per_test_file(tmp_path_factory):
    """calibrate A.csv B.csv --device D --per-test 2:C: the calibration file and its raw mapping."""
    folder = tmp_path_factory.mktemp("per_test_export")
    paths = []
    for k, (name, C) in enumerate(TRUE_C.items()):
        rec = lab_record(VirtualDamper(C=C, alpha=0.3), paper(amplitude=20, velocity=300, cycles=2, dt=0.005), 0.5,
                         0.005, seed=k, tmp_path=folder, name=name)
        paths.append(rec.provenance["file"])
    out = folder / "cal"
    assert cli.main(["calibrate", *paths, "--device", "D", "--laws", "2", "--per-test", "2:C", "--runs", "1",
                     "--intervals", "5", "--out", str(out), "--jobs", "1", "--quiet", "--no-figures"]) == 0
    path = out / "params" / "D" / "law2.yaml"
    return path, yaml.safe_load(path.read_text())


def one_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    return lines[0]


def test_the_file_keeps_every_tests_value_and_interval(per_test_file):
    """Both tests' C near the truth, each with its 95% interval in the file."""
    _, raw = per_test_file
    C = raw["parameters"]["C"]
    assert C["per_test"] == {name: pytest.approx(c, rel=0.03) for name, c in TRUE_C.items()}
    assert list(C["per_test_ci95"]) == ["A", "B"] and C["per_test_ci95"]["A"] == C["ci95"]
    for name, (lo, hi) in C["per_test_ci95"].items():
        assert lo <= C["per_test"][name] <= hi


def test_export_without_a_test_is_refused_naming_the_tests(per_test_file, tmp_path, capsys):
    path, raw = per_test_file
    values = raw["parameters"]["C"]["per_test"]
    for target, out in (("opensees", tmp_path / "d.py"), ("fmu", tmp_path / "d.fmu")):
        assert cli.main(["export", target, str(path), "-o", str(out)]) == 2
        line = one_line(capsys.readouterr().err)
        assert "C was fitted per test" in line and "--test A or --test B" in line
        assert f"A: {values['A']:.4g}" in line and f"B: {values['B']:.4g}" in line
        assert not out.exists()
    assert cli.main(["export", "opensees", str(path), "-o", str(tmp_path / "d.py"), "--test", "X"]) == 2
    assert one_line(capsys.readouterr().err).endswith(f"--test X: {path} has tests A, B")
    assert list(tmp_path.iterdir()) == []


def test_export_with_a_test_takes_its_values_and_says_so(per_test_file, tmp_path, capsys):
    """The script's dashpot is test B's C (the file's), alpha the shared one; its header names the test."""
    path, raw = per_test_file
    C_B, alpha = raw["parameters"]["C"]["per_test"]["B"], raw["parameters"]["alpha"]["value"]
    out = tmp_path / "d.py"
    assert cli.main(["export", "opensees", str(path), "-o", str(out), "--test", "B"]) == 0
    script = out.read_text()
    assert "# calibrated on device D, test B (C fitted per test: test B's value)" in script
    (args,) = re.findall(r"ops\.uniaxialMaterial\('Viscous', tag, ([^)]*)\)", script)
    numbers = [float(x) for x in args.split(",")]
    assert numbers == pytest.approx([C_B, alpha], rel=1e-12)
    assert numbers[0] == pytest.approx(TRUE_C["B"], rel=0.03)


def test_the_python_api_takes_test_and_speaks_its_words(per_test_file):
    path, raw = per_test_file
    cal = fb.Calibration.load(str(path))
    with pytest.raises(fb.InputError, match=r"C was fitted per test .*; name one with test='A' or test='B'$"):
        cal.to_opensees()
    with pytest.raises(fb.InputError, match=r"^test='X': .* has tests A, B$"):
        cal.to_opensees(test="X")
    with pytest.raises(fb.InputError, match="test='A' or test='B'"):
        cal.to_fmu("never.fmu")
    for name in TRUE_C:
        one = cal.for_test(name)
        assert one.named()["C"] == raw["parameters"]["C"]["per_test"][name]
        assert one.of == next(t["of"] for t in raw["tests"] if t["name"] == name)
        assert one.params["C"].ci95 == tuple(raw["parameters"]["C"]["per_test_ci95"][name])
        (material,) = [c for c in cal.to_opensees(test=name) if c[0] == "uniaxialMaterial"]
        assert material[:3] == ("uniaxialMaterial", "Viscous", 1)
        assert material[3] == pytest.approx(raw["parameters"]["C"]["per_test"][name], rel=1e-12)
    assert cal.for_test("B").per_test == {}  # one test's calibration is no longer per test


def test_compare_and_frame_refuse_without_a_test(per_test_file, tmp_path, capsys):
    path, raw = per_test_file
    record = raw["tests"][1]["record"]["file"]
    out = tmp_path / "cmp"
    assert cli.main(["compare", str(path), record, "--out", str(out), "--no-figures"]) == 2
    assert "--test A or --test B" in one_line(capsys.readouterr().err) and not out.exists()
    assert cli.main(["compare", str(path), record, "--out", str(out), "--no-figures", "--json", "--test", "B"]) == 0
    printed = capsys.readouterr().out
    assert yaml.safe_load(printed)["models"][0]["of"] == pytest.approx(raw["tests"][1]["of"], rel=1e-9)
    t = np.arange(0.0, 4.0, 0.02)
    quake = tmp_path / "quake.txt"
    np.savetxt(quake, np.column_stack([t, 0.2 * np.sin(2 * np.pi * t)]))
    frame_out = tmp_path / "frame"
    assert cli.main(["frame", str(path), "--record", str(quake), "--out", str(frame_out), "--quiet"]) == 2
    assert "--test A or --test B" in one_line(capsys.readouterr().err) and not frame_out.exists()


def test_frames_refuse_a_per_test_calibration_from_python(per_test_file):
    from fvd_bridge.frames.compare import run_cases

    cal = fb.Calibration.load(str(per_test_file[0]))
    with pytest.raises(fb.InputError, match="name one with test='A' or test='B'"):
        run_cases(None, None, [cal])


def test_the_fmu_of_one_test_holds_its_values_and_names_it(per_test_file, tmp_path, capsys):
    """`export fmu --test B`: the start value of C is test B's (the file's), checked on B's record; the
    description and the annotation name the test."""
    import xml.etree.ElementTree as ET
    import zipfile

    from fvd_bridge.export.fmu_toolchain import toolchain_problem

    if toolchain_problem():
        pytest.skip(toolchain_problem())
    path, raw = per_test_file
    out = tmp_path / "d.fmu"
    assert cli.main(["export", "fmu", str(path), "-o", str(out), "--test", "B"]) == 0
    assert "check on B:" in capsys.readouterr().err
    root = ET.fromstring(zipfile.ZipFile(out).read("modelDescription.xml"))
    start = {v.get("name"): v.get("start") for v in root.find("ModelVariables")}
    assert float(start["law2.C"]) == raw["parameters"]["C"]["per_test"]["B"]
    assert "on device D, test B (C fitted per test: test B's value)" in root.get("description")
    assert root.find("Annotations/Annotation/Calibration").get("tests") == "B"
