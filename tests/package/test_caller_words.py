"""Errors in the caller's words: from Python no message names a command-line
option or a command (``errors.option``, ``errors.command``); the command line's
equivalent names its flag."""

from __future__ import annotations

import copy
import warnings

import numpy as np
import pytest
import scipy.io

import fvd_bridge as fb
from conftest import csv_text, sine
from fvd_bridge import cli
from fvd_bridge.export.opensees import opensees_export
from fvd_bridge.golden import GOLDEN_DIR, read_golden
from fvd_bridge.records import ReadOptions

S = sine()


def law2() -> dict:
    """Law 2's golden parameters."""
    return read_golden(GOLDEN_DIR / "law2.csv")[0]


def cli_words(message: str) -> list[str]:
    """The command-line words in ``message``: options and commands."""
    return [w for w in ("--", "fvd-bridge") if w in message]


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    """A lab-like law-2 record (kN, mm, s), its CSV, and the same columns unnamed and in a .mat."""
    from lab import lab_record
    from fvd_bridge.rig import VirtualDamper, paper

    root = tmp_path_factory.mktemp("words")
    rec = lab_record(VirtualDamper(C=45.0, alpha=0.3, name="dev"), paper(cycles=2), seed=0, tmp_path=root)
    (root / "unnamed.csv").write_text(csv_text("time,x,load", [S["t"], S["d"], S["F"]]))
    scipy.io.savemat(root / "rig.mat", {"x_F": np.column_stack([S["d"], S["F"]]), "Ts": 0.01})
    return rec, root


def renamed(rec, name: str):
    """A copy of ``rec`` named ``name`` (a second test of the device)."""
    other = copy.copy(rec)
    other.name = name
    return other


def python_errors(lab) -> dict:
    """{case: call} of bad input a Python caller can give."""
    rec, root = lab
    gap_law = fb.parse_model("2+thermal_softening")
    pars = {**law2(), "thermal_softening.theta": 0.1}
    return {
        "bound name": lambda: fb.calibrate(rec, "2", bounds={"nope": (0, 1)}),
        "optimizer": lambda: fb.calibrate(rec, "2", optimizer="newton"),
        "per_test": lambda: fb.calibrate([rec, renamed(rec, "dev_b")], "2", device="d", per_test=["nope"]),
        "law": lambda: fb.calibrate(rec, "99"),
        "effect": lambda: fb.calibrate(rec, "2+frictoin"),
        "plugin": lambda: fb.calibrate(rec, "2", plugins=[str(root / "none.py")]),
        "unnamed columns": lambda: fb.read_record(str(root / "unnamed.csv")),
        "unknown unit": lambda: fb.read_record(str(rec.provenance["file"]), ReadOptions(units={"F": "furlong"})),
        "sg window": lambda: fb.read_record(str(rec.provenance["file"]), ReadOptions(sg_window=4)),
        "sg order": lambda: fb.read_record(str(rec.provenance["file"]), ReadOptions(sg_window=3, sg_order=3)),
        "mat without mapping": lambda: fb.read_record(str(root / "rig.mat")),
        "mat matrix as a column": lambda: fb.read_record(str(root / "rig.mat"), ReadOptions(columns={"d": "x_F", "F": "x_F"})),
        "test weights": lambda: fb.Device("d", [rec, rec], [1.0]),
        "not in OpenSees": lambda: opensees_export(gap_law, pars),
        "export units": lambda: opensees_export(fb.parse_model("2"), law2(), units="kN,furlong,s"),
    }


CASES = ("bound name", "optimizer", "per_test", "law", "effect", "plugin", "unnamed columns", "unknown unit",
         "sg window", "sg order", "mat without mapping", "mat matrix as a column", "test weights", "not in OpenSees",
         "export units")


@pytest.mark.parametrize("case", CASES)
def test_python_errors_name_no_option_and_no_command(case, lab):
    with pytest.raises(fb.InputError) as err:
        python_errors(lab)[case]()
    message = str(err.value)
    assert not cli_words(message), message
    assert "\n" not in message


def test_python_advice_speaks_python(lab):
    """A fit warning's remedy, the OpenSees refusal and a diagnosis' next step name Python arguments."""
    rec, _ = lab
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        cal = fb.calibrate(rec, "2", bounds={"alpha": (0.5, 0.6)}, intervals=0)
    notes = [str(w.message) for w in caught if issubclass(w.category, fb.FitWarning)] + list(cal.warnings)
    assert any("bounds={'alpha': (" in n for n in notes), notes
    assert not [n for n in notes if cli_words(n)], notes
    with pytest.raises(fb.InputError, match=r"Calibration\.to_fmu\(\)"):
        opensees_export(fb.parse_model("2+thermal_softening"), {**law2(), "thermal_softening.theta": 0.1})


#: the command line's equivalents: (arguments, the words its one line names)
CLI_CASES = {
    "sg window": (["inspect", "{csv}", "--sg-window", "4"], "--sg-window 4"),
    "unknown unit": (["inspect", "{csv}", "--units", "F=furlong"], "--units F=furlong"),
    "mat without mapping": (["inspect", "{mat}"], "--mat-var x_F --columns d=0,F=2"),
    "unnamed columns": (["inspect", "{unnamed}"], "--columns"),
    "law": (["calibrate", "{csv}", "--laws", "99", "--out", "{out}"], "fvd-bridge laws"),
    "effect": (["calibrate", "{csv}", "--laws", "2+frictoin", "--out", "{out}"], "fvd-bridge effects"),
    "per_test": (["calibrate", "{csv}", "{csv}", "--device", "d", "--laws", "2", "--per-test", "nope",
                  "--out", "{out}"], "--per-test nope"),
    "export units": (["export", "opensees", "{params}", "--units", "kN,furlong,s"], "--units kN,furlong,s"),
}


@pytest.mark.parametrize("case", sorted(CLI_CASES))
def test_the_command_line_names_its_flag(case, lab, tmp_path, capsys):
    from conftest import REPO

    rec, root = lab
    fill = {"csv": str(rec.provenance["file"]), "mat": str(root / "rig.mat"), "unnamed": str(root / "unnamed.csv"),
            "out": str(tmp_path / "out"),
            "params": str(REPO / "tests" / "fixtures" / "calibration_v1" / "law2+friction.yaml")}
    args, named = CLI_CASES[case]
    assert cli.main([a.format(**fill) for a in args]) == 2
    err = capsys.readouterr().err.strip()
    assert named in err and "\n" not in err, err


def test_one_replicate_is_refused_in_each_callers_words(lab, tmp_path, capsys):
    """One bootstrap replicate has no spread: fb.calibrate, calibrate and diagnose each refuse it in one line."""
    lab = lab[0]
    with pytest.raises(fb.InputError, match=r"^intervals=1: 0 \(none\) or at least 2 replicates$"):
        fb.calibrate(lab, "2", intervals=1)
    for verb in (["calibrate", lab.provenance["file"], "--laws", "2"], ["diagnose", lab.provenance["file"], "--law", "2"]):
        assert cli.main([*verb, "--intervals", "1", "--out", str(tmp_path / verb[0])]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "--intervals 1: 0 (none) or at least 2 replicates" in err
        assert not (tmp_path / verb[0]).exists()
