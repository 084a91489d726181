"""Units known, or the record refused (records/plausible.py).

A file without unit information whose magnitudes no damper test has (a
peak force above 10,000 kN, a stroke outside 0.5-1,000 mm, a force per
stroke outside 1e-4-2,000 kN/mm) is refused in one line naming the likely
unit and how to give it; a file whose header or sidecar names its units is
never second-guessed. Built from the shared friction damper's real test
(in, kip) and a lab-like law-2 record, rewritten in N and m.
"""

from __future__ import annotations

import subprocess
import warnings
from pathlib import Path

import numpy as np
import pytest

from conftest import CLI, cli_env, csv_text
from fvd_bridge import calibrate
from fvd_bridge.errors import InputError
from fvd_bridge.records import ReadOptions, RecordWarning, read_record
from fvd_bridge.records.plausible import FORCE_MAX_KN, implausible, peaks
from fvd_bridge.rig import VirtualDamper, demo_series, paper
from fvd_bridge.units import factor, unit_name
from lab import lab_record

KIP, INCH = factor("F", "kip"), factor("d", "in")
FRICTION = "arts_brfd_1Hz_35lb.csv"


@pytest.fixture(scope="module")
def friction(tmp_path_factory):
    """The shared friction damper's 1 Hz test (t [s], d [in], F [kip]) as
    (t, d [mm], F [kN]), and a folder for its rewritings."""
    path = Path(__file__).resolve().parents[2] / ".." / "shared" / "devices" / FRICTION
    if not path.is_file():
        pytest.skip(f"{path} is absent")
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    return {"t": data[:, 0], "d": data[:, 1] * INCH, "F": data[:, 2] * KIP,
            "dir": tmp_path_factory.mktemp("units")}


def write(folder: Path, name: str, header: str, t, d, F, sidecar: str | None = None) -> Path:
    path = folder / name
    path.write_text(csv_text(header, [t, d, F]))
    if sidecar is not None:
        path.with_suffix(".yaml").write_text(sidecar)
    return path


def read(path, opts=None, refuse=False):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RecordWarning)
        return read_record(str(path), opts, refuse_doubts=refuse)


CASES = {  # name: (d factor from mm, F factor from kN, the refusal's words)
    "newton": (1.0, 1e3, ["column 'F'", "peak force 14,939 kN over a 25.55 mm stroke", "above 10,000 kN", "is F in N?",
                          "units={'F': 'N'}", "newton.yaml with 'units: {F: N}'", "'F [N]'"]),
    "metre": (1e-3, 1.0, ["column 'd'", "0.02", "mm stroke", "outside 0.5-1,000 mm", "is d in m?",
                          "units={'d': 'm'}", "'d [m]'"]),
    "both": (1e-3, 1e3, ["columns 'd' and 'F'", "is d in m and F in N?", "units={'d': 'm', 'F': 'N'}"]),
}


@pytest.mark.parametrize("case", tuple(CASES))
def test_a_real_test_in_other_units_is_refused_naming_the_unit(friction, case):
    fd, fF, words = CASES[case]
    path = write(friction["dir"], f"{case}.csv", "t,d,F", friction["t"], friction["d"] * fd, friction["F"] * fF)
    with pytest.raises(InputError) as err:
        read(path, refuse=True)
    text = str(err.value)
    assert "\n" not in text and text.startswith(f"{path}: ")
    for w in words:
        assert w in text, (w, text)
    assert "--units" not in text  # Python reads its own words
    # inspect's path: the doubt comes first among the notes
    assert read(path).warnings[0] == text


@pytest.mark.parametrize("case", tuple(CASES))
def test_the_command_line_refuses_in_its_words(friction, case):
    fd, fF, _ = CASES[case]
    folder = friction["dir"]
    write(folder, f"cli_{case}.csv", "t,d,F", friction["t"], friction["d"] * fd, friction["F"] * fF)
    res = subprocess.run([*CLI, "calibrate", f"cli_{case}.csv", "--laws", "2", "--out", f"out_{case}"],
                         capture_output=True, text=True, env=cli_env(), cwd=folder)
    assert res.returncode == 2, res.stdout + res.stderr
    assert res.stderr.count("\n") == 1 and "Traceback" not in res.stderr
    units = {"newton": "F=N", "metre": "d=m", "both": "d=m,F=N"}[case]
    assert f"give the units with --units {units}, a sidecar" in res.stderr
    assert not (folder / f"out_{case}").exists()


def test_header_units_are_read_and_never_second_guessed(friction):
    """'t [s],d [mm],F [N]' reads as N, converted; so do '(unit)' and a
    sidecar stating N; the same file without units is refused."""
    t, d, F, folder = friction["t"], friction["d"], friction["F"], friction["dir"]
    reference = read(write(folder, "kn.csv", "t,d,F", t, d, F, sidecar="units: {t: s, d: mm, F: kN}\n"))
    for name, header, side in (("bracket.csv", "t [s],d [mm],F [N]", None),
                               ("paren.csv", "t (s),d (mm),F (N)", None),
                               ("sidecar.csv", "t,d,F", "units: {F: N}\n")):
        rec = read(write(folder, name, header, t, d, F * 1e3, sidecar=side), refuse=True)
        assert rec.provenance["units"]["F"] == "N", name
        np.testing.assert_allclose(rec.F, reference.F, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(rec.d, reference.d, rtol=1e-9)
        assert not [w for w in rec.warnings if "unit" in w], (name, rec.warnings)
    # a stated unit is believed even where its magnitudes look odd (22,700 kN said to be kN)
    odd = read(write(folder, "said_kn.csv", "t,d,F [kN]", t, d, F * 1e3), refuse=True)
    assert odd.scales()["F"] > FORCE_MAX_KN
    # the caller's --units wins over the header
    rec = read(folder / "bracket.csv", ReadOptions(units={"F": "kN"}))
    assert rec.scales()["F"] == pytest.approx(1e3 * reference.scales()["F"])
    assert [w for w in rec.warnings if "column 'F [N]' read in kN" in w and "its header says N, a factor 0.001" in w]


def test_a_header_unit_the_table_does_not_know_is_one_line(friction, tmp_path):
    path = write(tmp_path, "furlong.csv", "t [s],d [furlong],F [kN]", friction["t"][:50], friction["d"][:50],
                 friction["F"][:50])
    with pytest.raises(InputError, match=r"row 1, column 'd \[furlong\]': unknown unit 'furlong' for d "
                                         r"\(known: mm, m, cm, in, um\); give it with units=\{'d': 'UNIT'\}"):
        read(path)
    assert unit_name("F", "KN") == "kN" and unit_name("t", "sec") == "s" and unit_name("d", "inch") == "in"


def test_a_newton_file_with_header_units_calibrates(tmp_path):
    """A lab-like law-2 record (C 40, alpha 0.3) written in N with its header
    't [s],d [mm],F [N]' calibrates to the truth; without the header's units
    it is refused."""
    rec = lab_record(VirtualDamper(C=40.0, alpha=0.3, name="fvd"), paper(cycles=3), 0.8, 0.01, seed=0, tmp_path=tmp_path)
    newton = write(tmp_path, "newton.csv", "t [s],d [mm],F [N]", rec.t, rec.d, rec.F * 1e3)
    cal = calibrate(read(newton, refuse=True), "2", intervals=0)
    C, alpha = cal.values
    assert C == pytest.approx(40.0, rel=0.03) and alpha == pytest.approx(0.3, rel=0.03)
    bare = write(tmp_path, "bare.csv", "t,d,F", rec.t, rec.d, rec.F * 1e3)
    with pytest.raises(InputError, match="is F in N"):
        read(bare, refuse=True)


def test_real_and_rig_records_are_plausible(friction, device_files):
    """The ranges hold every record here: the shared friction damper (kN,
    mm), the MR dampers (N converted), the rig's five demo devices."""
    assert implausible(peaks(friction["d"], friction["F"])) == []
    for path in device_files:
        rec = read(path, ReadOptions(mat_var="x_F", columns={"d": "0", "F": "2"}, units={"F": "N"}))
        assert implausible(peaks(rec.d, rec.F)) == [], path.name
    for k, device in enumerate(demo_series(0)):
        rec = lab_record(device, paper(cycles=3), 1.0, 0.005, seed=k, tmp_path=friction["dir"], name=f"demo{k}")
        assert implausible(peaks(rec.d, rec.F)) == [], device.name
