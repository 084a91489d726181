"""A calibration file is checked as a whole.

Real calibration files (a lab-like law-2 damper with seal friction, and two
tests of one device with C fitted per test), edited by hand the ways people
do: a typo in the model line, an effect added or removed on one line only,
another law number, a parameter renamed, a unit changed, a per-test value
changed in one place, a bad indentation.  Each is refused in one line
naming the file and the key (or the line and column), exit 2 on the command
line, nothing written; the files of earlier versions still load.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest
import yaml

import fvd_bridge as fb
from fvd_bridge import cli
from fvd_bridge.rig import VirtualDamper, paper

from lab import lab_record

FIXTURES = Path(__file__).parents[1] / "fixtures"


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """{'friction': law2+friction.yaml of one test, 'per_test': law2.yaml of tests A, B with C per test}."""
    folder = tmp_path_factory.mktemp("file_check")
    protocol = paper(amplitude=20, velocity=300, cycles=2, dt=0.005)
    one = lab_record(VirtualDamper(C=40.0, alpha=0.3, friction=3.0), protocol, 0.5, 0.005, seed=0, tmp_path=folder,
                     name="sn1")
    friction = fb.calibrate(one, "2+friction", intervals=0).save(str(folder / "law2+friction.yaml"))
    tests = [lab_record(VirtualDamper(C=C, alpha=0.3), protocol, 0.5, 0.005, seed=k, tmp_path=folder, name=name)
             for k, (name, C) in enumerate((("A", 40.0), ("B", 52.0)))]
    per_test = fb.calibrate(tests, "2", device="D", per_test=["C"], intervals=3).save(str(folder / "law2.yaml"))
    return {"friction": Path(friction), "per_test": Path(per_test)}


def edited(path: Path, tmp_path: Path, change) -> Path:
    """The calibration file with ``change(data)`` applied to its mapping, written beside the test."""
    data = yaml.safe_load(path.read_text())
    change(data)
    out = tmp_path / path.name
    out.write_text(yaml.safe_dump(data, sort_keys=False))
    return out


def refused(path: Path, tmp_path: Path, capsys) -> str:
    """The one line `export opensees` refuses the file with (exit 2, no script written)."""
    out = tmp_path / "damper.py"
    assert cli.main(["export", "opensees", str(path), "-o", str(out), "--test", "B"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith(f"fvd-bridge: {path}: ") and not out.exists()
    with pytest.raises(fb.InputError):
        fb.Calibration.load(str(path))
    return err


def set_model(spec):
    def change(data):
        data["model"] = spec
    return change


def add_friction(data):
    """The model line, the effects list and the parameter, as the model 2+friction has them."""
    data["model"] = "2+friction"
    data["effects"] = [{"name": "friction"}]
    data["parameters"]["friction.Ff"] = {"value": 2.0, "unit": "kN", "bounds": [0.0, 50.0]}


def rename_alpha(data):
    data["parameters"]["alfa"] = data["parameters"].pop("alpha")


def per_test_value(data):
    data["parameters"]["C"]["per_test"]["B"] = 60.0  # the tests' block still holds B's fitted C


CASES = {  # name: (file, change, the words of the one line)
    "typo in the model line": ("friction", set_model("2+frictoin"), "key 'model': 2+frictoin: effect 'frictoin'"),
    "effect left out of the model line": ("friction", set_model("2"), "key 'effects' lists friction, key 'model' '2'"),
    "effect added to the model line": ("friction", set_model("2+friction+asymmetry"), "key 'effects' lists friction,"),
    "law number of another law": ("friction", lambda d: d["law"].update(number=9), "key 'law.number': 9"),
    "units of another system": ("friction", lambda d: d["units"].update(force="N"), "key 'units'"),
    "unit of a parameter": ("friction", lambda d: d["parameters"]["C"].update(unit="kN*s/mm"),
                            "key 'parameters.C.unit': 'kN*s/mm', expected 'kN/(mm/s)^alpha'"),
    "parameter renamed": ("friction", rename_alpha, "key 'parameters.alpha' is missing"),
    "parameter of no effect listed": ("per_test", lambda d: d["parameters"].update({"friction.Ff": {
        "value": 2.0, "unit": "kN"}}), "key 'parameters.friction.Ff' is not a parameter of model 2"),
    "per-test value changed in one place": ("per_test", per_test_value, "key 'parameters.C.per_test.B': 60.0"),
    "per-test parameter of another name": ("per_test", lambda d: d["tests"][1]["parameters"].update(K=1.0),
                                           "key 'tests[B].parameters.K' is not a parameter of model 2"),
}


@pytest.mark.parametrize("case", list(CASES))
def test_a_hand_edit_that_disagrees_is_refused_naming_the_key(case, files, tmp_path, capsys):
    which, change, words = CASES[case]
    assert words in refused(edited(files[which], tmp_path, change), tmp_path, capsys)


def test_a_consistent_hand_edit_loads(files, tmp_path):
    """The model line, its effects and parameters changed together: a file that says what it is."""
    def change(data):
        add_friction(data)
        data["parameters"]["friction.Ff"]["value"] = 0.0

    def without_friction(data):
        data.update(model="2", effects=[])
        data["parameters"].pop("friction.Ff")

    cal = fb.Calibration.load(str(edited(files["per_test"], tmp_path, change)))
    assert cal.spec == "2+friction" and cal.named()["friction.Ff"] == 0.0
    assert fb.Calibration.load(str(edited(files["friction"], tmp_path, without_friction))).spec == "2"


@pytest.mark.parametrize("bad, line, column, problem", [
    ("  alpha:", 0, 2, "expected <block end>"),  # one space too few before a parameter
    ("  alpha: value: 0.3", 0, 15, "mapping values are not allowed here"),  # two keys on one line
])
def test_a_yaml_error_names_its_line_and_column(files, tmp_path, capsys, bad, line, column, problem):
    text = files["friction"].read_text().splitlines()
    k = text.index("  alpha:")
    text[k] = " alpha:" if bad == "  alpha:" else bad
    path = tmp_path / "law2+friction.yaml"
    path.write_text("\n".join(text) + "\n")
    err = refused(path, tmp_path, capsys)
    assert f"line {k + 1 + line}, column {column}: not valid YAML: {problem}" in err


@pytest.mark.parametrize("path", sorted((FIXTURES / "calibration_v1").glob("*.yaml"))
                         + sorted((FIXTURES / "calibration_v3").glob("*.yaml")), ids=lambda p: p.name)
def test_files_of_earlier_versions_still_load(path):
    cal = fb.Calibration.load(str(path))
    raw = yaml.safe_load(path.read_text())
    assert cal.spec == str(raw["model"]) and list(cal.named()) == list(raw["parameters"])


def test_an_edited_value_loads_flagged_as_not_the_fits(files, tmp_path, capsys):
    """alpha changed by hand, consistently (it has no per-test copy): the file
    loads, as a value set on purpose should, but its OF and intervals
    describe the fit's alpha: one warning line on loading, kept among the
    calibration's warnings (once, also after saving it again), and the
    export still written."""
    def change(data):
        data["parameters"]["alpha"]["value"] = 0.5

    path = edited(files["friction"], tmp_path, change)
    with pytest.warns(fb.FitWarning, match="the parameter values are not those the fit wrote"):
        cal = fb.Calibration.load(str(path))
    assert cal.named()["alpha"] == 0.5
    flagged = [w for w in cal.warnings if "not those the fit wrote" in w]
    assert len(flagged) == 1 and flagged[0].startswith(f"{path}: ")
    with warnings.catch_warnings():
        warnings.simplefilter("error", fb.FitWarning)  # saved by the tool: its values are the file's again
        again = fb.Calibration.load(cal.save(str(tmp_path / "again.yaml")))
    assert [w for w in again.warnings if "not those the fit wrote" in w] == flagged
    out = tmp_path / "damper.py"
    assert cli.main(["export", "opensees", str(path), "-o", str(out)]) == 0 and out.exists()
    assert "warning: " in capsys.readouterr().err


def test_the_file_as_written_loads_again_unchanged(files, tmp_path):
    for path in files.values():
        with warnings.catch_warnings():
            warnings.simplefilter("error", fb.FitWarning)  # the values are the fit's: no edit to flag
            cal = fb.Calibration.load(str(path))
        again = fb.Calibration.load(cal.save(str(tmp_path / path.name)))
        assert again.named() == cal.named() and again.tests == cal.tests
        assert yaml.safe_load(path.read_text())["parameters"] == \
            yaml.safe_load((tmp_path / path.name).read_text())["parameters"]
