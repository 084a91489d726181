"""Inputs that lie are caught: loops that generate energy (the force's sign
reversed) and a file in m and N read as mm and kN.

``inspect`` lists such a record's doubt among its warnings; ``calibrate``,
``diagnose`` and ``compare`` refuse it in one line with exit code 2 and
write nothing, until the user flips the force (``--force-sign flip`` or the
sidecar's ``force_sign: flip``), says it is right (``--force-sign keep``)
or gives the units. The real records of ../shared/devices and the rig's
records pass; each of them with its force negated is named as reversed.
"""

from __future__ import annotations

import shutil
import subprocess
import warnings
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest
import scipy.io

from conftest import CLI, cli_env
from fvd_bridge import cli
from fvd_bridge.calibration import Calibration
from fvd_bridge.errors import InputError
from fvd_bridge.records import ReadOptions, RecordWarning, read_record
from fvd_bridge.rig import VirtualDamper, Noise, demo_series, paper, write_series
from lab import lab_record

REVERSED = "the force's sign looks reversed"
MR = ReadOptions(mat_var="x_F", columns={"d": "0", "F": "2"}, units={"F": "N"})


def rewrite(src: Path, dst: Path, d_factor: float = 1.0, F_factor: float = 1.0, sidecar: str | None = None) -> Path:
    """A copy of the t,d,F CSV ``src`` with d and F scaled (F_factor -1: the
    force negated, each cell exactly); ``sidecar``: the copy's NAME.yaml text
    (None: src's sidecar copied when there is one; '': none)."""
    out = []
    for line in src.read_text().splitlines():
        if line.startswith("#") or not line[:1].isdigit() and not line.startswith("-"):
            out.append(line)
            continue
        t, d, F, *rest = line.split(",")
        out.append(",".join([t, f"{float(d) * d_factor:.10g}", f"{float(F) * F_factor:.10g}", *rest]))
    dst.write_text("\n".join(out) + "\n")
    if sidecar is None and src.with_suffix(".yaml").is_file():
        shutil.copy(src.with_suffix(".yaml"), dst.with_suffix(".yaml"))
    elif sidecar:
        dst.with_suffix(".yaml").write_text(sidecar)
    return dst


def doubts(path, opts=None) -> list:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RecordWarning)
        return read_record(str(path), opts).provenance["doubts"]


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A lab-like law-2 record (C 40, alpha 0.3; 40 mm at 500 mm/s; 0.8 kN and
    0.01 mm noise; velocity derived by the reader), the same with its force
    negated (with the unit sidecar; and with a sidecar saying force_sign:
    flip), a law-2 calibration of the original, and a 20 kN device's record
    written in m and N without units."""
    root = tmp_path_factory.mktemp("lie")
    lab_record(VirtualDamper(C=40.0, alpha=0.3, name="fvd"), paper(cycles=3), 0.8, 0.01, seed=0, tmp_path=root)
    lab_record(VirtualDamper(C=3.1, alpha=0.3, name="small"), paper(cycles=3), 0.05, 0.01, seed=0, tmp_path=root)
    src = root / "fvd.csv"
    negated = rewrite(src, root / "negated.csv", F_factor=-1.0)
    flipped = rewrite(src, root / "flipped.csv", F_factor=-1.0,
                      sidecar="units: {t: s, d: mm, F: kN}\nforce_sign: flip\n")
    si = rewrite(root / "small.csv", root / "si.csv", d_factor=1e-3, F_factor=1e3, sidecar="")
    from fvd_bridge import calibrate

    cal = calibrate(read_record(str(src)), "2", intervals=0).save(str(root / "law2.yaml"))
    return {"root": root, "original": src, "negated": negated, "flipped": flipped, "si": si, "cal": cal}


def run_cli(args, cwd) -> subprocess.CompletedProcess:
    return subprocess.run([*CLI, *args], capture_output=True, text=True, env=cli_env(), cwd=cwd)


@pytest.fixture(scope="module")
def refusals(files):
    """Every verb on every lying file, run concurrently: {(verb, file): result}."""
    root = files["root"]
    cases = {("calibrate", "negated"): ["calibrate", "negated.csv", "--laws", "2", "--out", "out_cal_neg"],
             ("diagnose", "negated"): ["diagnose", "negated.csv", "--law", "2", "--out", "out_diag_neg"],
             ("compare", "negated"): ["compare", "law2.yaml", "negated.csv", "--out", "out_cmp_neg"],
             ("calibrate", "si"): ["calibrate", "si.csv", "--laws", "2", "--out", "out_cal_si"],
             ("diagnose", "si"): ["diagnose", "si.csv", "--law", "2", "--out", "out_diag_si"]}
    with ThreadPoolExecutor(len(cases)) as pool:
        done = {key: pool.submit(run_cli, args, root) for key, args in cases.items()}
    return {key: (cases[key], f.result()) for key, f in done.items()}


def test_inspect_names_the_reversed_sign(files, capsys):
    assert cli.main(["inspect", str(files["negated"])]) == 0
    out = capsys.readouterr().out
    assert "warnings     1" in out and REVERSED in out and "loops generate energy" in out
    assert "--force-sign flip" in out and "force_sign: flip" in out and "--force-sign keep" in out
    assert cli.main(["inspect", str(files["original"])]) == 0
    assert "warnings     none" in capsys.readouterr().out
    assert cli.main(["inspect", str(files["flipped"])]) == 0  # the sidecar says so
    assert "warnings     none" in capsys.readouterr().out


@pytest.mark.parametrize("verb", ["calibrate", "diagnose", "compare"])
def test_a_reversed_record_is_refused(refusals, files, verb):
    args, res = refusals[(verb, "negated")]
    assert res.returncode == 2, res.stdout + res.stderr
    assert res.stderr.count("\n") == 1 and "Traceback" not in res.stderr
    assert res.stderr.startswith("fvd-bridge: negated.csv: column 'F'") and REVERSED in res.stderr
    assert "--force-sign flip" in res.stderr and "force_sign: flip" in res.stderr
    assert not (files["root"] / args[args.index("--out") + 1]).exists()


@pytest.mark.parametrize("verb", ["calibrate", "diagnose"])
def test_metres_and_newtons_are_refused(refusals, files, verb):
    args, res = refusals[(verb, "si")]
    assert res.returncode == 2, res.stdout + res.stderr
    assert res.stderr.count("\n") == 1 and "Traceback" not in res.stderr
    assert res.stderr.startswith("fvd-bridge: si.csv: columns 'd' and 'F'") and "is d in m and F in N?" in res.stderr
    assert "--units d=m,F=N" in res.stderr
    assert not (files["root"] / args[args.index("--out") + 1]).exists()


def test_flipped_force_calibrates_as_the_original(files):
    """--force-sign flip, and the sidecar's force_sign: flip, give the
    original record's parameters; the calibration file keeps the option, so
    that compare and export read the record again as it was read."""
    root = files["root"]
    common = ["--laws", "2", "--runs", "1", "--intervals", "0", "--no-figures", "--quiet"]
    with ThreadPoolExecutor(2) as pool:
        both = pool.submit(run_cli, ["calibrate", "fvd.csv", "flipped.csv", *common, "--out", "c_side"], root)
        option = pool.submit(run_cli, ["calibrate", "negated.csv", "--force-sign", "flip", *common,
                                       "--out", "c_flag"], root)
        for res in (both.result(), option.result()):
            assert res.returncode == 0, res.stderr
    cals = {name: Calibration.load(str(root / out / "params" / name / "law2.yaml"))
            for out, name in (("c_side", "fvd"), ("c_side", "flipped"), ("c_flag", "negated"))}
    C0, alpha0 = cals["fvd"].values
    assert C0 == pytest.approx(40.0, rel=0.02) and alpha0 == pytest.approx(0.3, rel=0.02)
    for name in ("flipped", "negated"):
        np.testing.assert_allclose(cals[name].values, cals["fvd"].values, rtol=1e-9)
        assert cals[name].of == pytest.approx(cals["fvd"].of, rel=1e-9)
    assert cals["negated"].record.reading == {"force_sign": "flip"}


def test_keep_says_the_sign_is_right(files):
    """--force-sign keep: read as it is, not doubted (a device that does give energy back)."""
    assert doubts(files["negated"], ReadOptions(force_sign="keep")) == []
    assert len(doubts(files["negated"])) == 1


def test_a_bad_force_sign_is_one_line(files, tmp_path):
    side = rewrite(files["original"], tmp_path / "bad.csv", sidecar="force_sign: reversed\n")
    with pytest.raises(InputError, match=r"bad\.yaml: row 1, key 'force_sign': expected flip or keep"):
        read_record(str(side))


def test_rig_records_pass_and_negated_they_trip(tmp_path):
    """The rig's demo series (effects and noise) and a paper-protocol device
    with series stiffness, friction, a gap, a parallel spring and preload:
    no doubt; each with its force negated: named as reversed."""
    paths = write_series(str(tmp_path / "demo"), demo_series(0), paper(cycles=3), Noise(force=1.0), seed=0)
    paths += write_series(str(tmp_path / "fx"), [VirtualDamper(C=45.4, alpha=0.3, Ks=50.0, friction=10.0, gap=0.5,
                                                        Kp=2.0, preload=20.0, name="fx")],
                          paper(cycles=3), Noise(force=1.0), seed=1)
    for path in (Path(p) for p in paths if p.endswith(".csv")):
        assert doubts(path) == [], path.name
        assert REVERSED in " ".join(doubts(rewrite(path, tmp_path / f"neg_{path.name}", F_factor=-1.0))), path.name


def test_shared_friction_damper_passes_and_negated_trips(shared_dir, tmp_path):
    for name in ("arts_brfd_0.5Hz_25lb.csv", "arts_brfd_1Hz_35lb.csv"):
        path = shared_dir / "devices" / name
        if not path.is_file():
            pytest.skip(f"../shared/devices lacks {name}")
        assert doubts(path) == [], name
        neg = rewrite(path, tmp_path / name, F_factor=-1.0)
        with pytest.raises(InputError, match=REVERSED):
            read_record(str(neg), refuse_doubts=True)


def test_shared_mr_damper_passes_and_negated_trips(device_files, tmp_path):
    for path in device_files:
        assert doubts(path, MR) == [], path.name
        data = scipy.io.loadmat(str(path))
        x_F = np.array(data["x_F"], dtype=float)
        x_F[:, 2] *= -1.0
        neg = tmp_path / path.name
        scipy.io.savemat(str(neg), {"x_F": x_F, "Ts": data["Ts"]})
        assert REVERSED in " ".join(doubts(neg, MR)), path.name
