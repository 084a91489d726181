"""Output paths checked before any work, and nothing partial left after a failure.

Every verb that writes checks its output path first (``io.staging.check_output``):
a file where a folder is wanted, a folder where a file is wanted, a path inside
a file, a folder that does not exist or cannot be written: one line naming the
option and the path, exit 2, before any input is read or any fit made. A verb
that fails or is interrupted (Ctrl-C) half-way leaves nothing behind.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np
import pytest

from conftest import REPO
from fvd_bridge import cli
from fvd_bridge.errors import InputError
from fvd_bridge.io.staging import atomic_file, check_output, staged_dir

PARAMS = str(REPO / "tests" / "fixtures" / "calibration_v1" / "law2+friction.yaml")
#: a check before any work: far below what reading a record and fitting take
QUICK = 1.5
ROOT = os.geteuid() == 0  # chmod does not stop root: those cases skip


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    """A lab-like record of a law-2 device, a short ground motion and a campaign file's folder."""
    from lab import lab_record
    from fvd_bridge.rig import VirtualDamper, paper

    root = tmp_path_factory.mktemp("inputs")
    lab_record(VirtualDamper(C=45.0, alpha=0.3, name="dev"), paper(cycles=2), seed=0, tmp_path=root)
    t = np.arange(0.0, 2.0, 0.01)
    (root / "quake.txt").write_text("\n".join(f"{x:.3f} {0.2 * np.sin(2 * np.pi * x):.6f}" for x in t))
    return root


#: verb -> (command line with OUT for the output path, kind of output, the option named)
VERBS = {
    "calibrate": (["calibrate", "{rec}", "--laws", "2", "--runs", "1", "--out", "OUT"], "dir", "--out"),
    "diagnose": (["diagnose", "{rec}", "--law", "2", "--out", "OUT"], "dir", "--out"),
    "compare": (["compare", PARAMS, "{rec}", "--out", "OUT"], "dir", "--out"),
    "frame": (["frame", PARAMS, "--record", "{quake}", "--out", "OUT"], "dir", "--out"),
    "rig": (["rig", "--devices", "2", "--out", "OUT"], "dir", "--out"),
    "demo": (["demo", "--quick", "--out", "OUT"], "dir", "--out"),
    "campaign": (["campaign", "{campaign}"], "dir", "key 'out'"),
    "export-opensees": (["export", "opensees", PARAMS, "-o", "OUT"], "file", "-o"),
    "export-fmu": (["export", "fmu", PARAMS, "-o", "OUT"], "file", "-o"),
    "inspect-plot": (["inspect", "{rec}", "--plot", "OUT"], "file", "--plot"),
    "effects-gap-figure": (["effects", "--gap-figure", "OUT"], "file", "--gap-figure"),
}
#: the output's name for each verb whose name is checked (a suffix)
NAMES = {"export-opensees": "damper.py", "export-fmu": "damper.fmu", "inspect-plot": "look.png",
         "effects-gap-figure": "gap.png"}


def command(verb: str, out: Path, inputs: Path, tmp_path: Path) -> list[str]:
    """The verb's command line writing to ``out``."""
    words, _, _ = VERBS[verb]
    campaign = tmp_path / "campaign.yaml"
    campaign.write_text(f"records: [{inputs / 'dev.csv'}]\nmodels: 2\nruns: 1\nout: {out}\n")
    fill = {"rec": str(inputs / "dev.csv"), "quake": str(inputs / "quake.txt"), "campaign": str(campaign)}
    return [str(out) if w == "OUT" else w.format(**fill) for w in words]


def refused(args: list[str], capsys) -> str:
    """Run the CLI in-process: exit 2 with one line, quickly; that line."""
    t0 = time.perf_counter()
    rc = cli.main(args)
    took = time.perf_counter() - t0
    err = capsys.readouterr().err.strip()
    assert rc == 2, err
    assert err.startswith("fvd-bridge: ") and "\n" not in err and "Traceback" not in err, err
    assert took < QUICK, f"{took:.2f} s: the path was checked after some work"
    return err


def leftovers(folder: Path) -> list[str]:
    """Staging folders and temporary files under ``folder``."""
    return [str(p) for p in folder.rglob("*") if ".partial-" in p.name or p.name.endswith((".part", ".part.png"))]


def wrong_kind(verb: str, tmp_path: Path) -> Path:
    """An existing file where a folder is wanted, or a folder where a file is."""
    _, kind, _ = VERBS[verb]
    if kind == "dir":
        path = tmp_path / "existing_file.txt"
        path.write_text("not a folder\n")
    else:
        path = tmp_path / NAMES[verb]
        path.mkdir()
    return path


@pytest.mark.parametrize("verb", sorted(VERBS))
def test_a_file_for_a_folder_or_a_folder_for_a_file_is_refused_first(verb, inputs, tmp_path, capsys):
    path = wrong_kind(verb, tmp_path)
    args = command(verb, path, inputs, tmp_path)
    before = sorted(os.listdir(tmp_path))
    err = refused(args, capsys)
    _, kind, flag = VERBS[verb]
    assert flag in err and str(path) in err, err
    assert ("is a file, not a folder" if kind == "dir" else "is a folder, not a file") in err, err
    assert sorted(os.listdir(tmp_path)) == before and not leftovers(tmp_path)


@pytest.mark.parametrize("verb", sorted(VERBS))
def test_a_path_inside_a_file_is_refused_first(verb, inputs, tmp_path, capsys):
    blocker = tmp_path / "a_file"
    blocker.write_text("x\n")
    path = blocker / "deeper" / NAMES.get(verb, "out")
    err = refused(command(verb, path, inputs, tmp_path), capsys)
    assert VERBS[verb][2] in err and str(path) in err and f"lies inside {blocker}, which is a file" in err, err
    assert blocker.read_text() == "x\n" and not leftovers(tmp_path)


@pytest.mark.parametrize("verb", sorted(v for v in VERBS if VERBS[v][1] == "file"))
def test_an_output_file_in_a_missing_folder_is_refused_first(verb, inputs, tmp_path, capsys):
    path = tmp_path / "nowhere" / NAMES[verb]
    err = refused(command(verb, path, inputs, tmp_path), capsys)
    assert err.endswith(f"{path}: folder {path.parent} does not exist"), err
    assert not (tmp_path / "nowhere").exists()


@pytest.mark.skipif(ROOT, reason="root writes into a read-only folder: chmod cannot make one here")
@pytest.mark.parametrize("verb", sorted(VERBS))
def test_an_unwritable_folder_is_refused_first(verb, inputs, tmp_path, capsys):
    locked = tmp_path / "locked"
    locked.mkdir()
    path = locked / NAMES.get(verb, "out")
    locked.chmod(0o555)
    try:
        err = refused(command(verb, path, inputs, tmp_path), capsys)
    finally:
        locked.chmod(0o755)
    assert str(path) in err and f"folder {locked} is not writable" in err, err
    assert not os.listdir(locked)


def test_report_refuses_a_folder_it_cannot_write(tmp_path, capsys):
    """``report OUT`` rebuilds OUT/report.html: OUT a file, or inside one, is one line."""
    blocker = tmp_path / "a_file"
    blocker.write_text("x\n")
    for out in (blocker, blocker / "out"):
        assert cli.main(["report", str(out)]) == 2
        err = capsys.readouterr().err.strip()
        assert str(out) in err and "\n" not in err, err


# ------------------------------------------------------------- nothing partial after a failure
def interrupt(*args, **kwargs):
    raise KeyboardInterrupt


def assert_nothing_left(tmp_path: Path, out: Path, capsys) -> None:
    assert "interrupted" in capsys.readouterr().err
    assert not out.exists(), sorted(os.listdir(out))
    assert not leftovers(tmp_path), leftovers(tmp_path)


def test_calibrate_interrupted_while_writing_leaves_nothing(inputs, tmp_path, monkeypatch, capsys):
    """Ctrl-C once the outputs are being staged: no OUT, no staging folder."""
    import fvd_bridge.campaign.outputs as outputs

    monkeypatch.setattr(outputs, "_tables", interrupt)  # called inside the staging folder, after the files
    out = tmp_path / "cal"
    rc = cli.main(["calibrate", str(inputs / "dev.csv"), "--laws", "1", "--runs", "1", "--intervals", "0",
                   "--no-figures", "--jobs", "1", "--quiet", "--out", str(out)])
    assert rc == 130
    assert_nothing_left(tmp_path, out, capsys)


def test_an_interrupted_write_into_an_existing_folder_keeps_it_as_it_was(inputs, tmp_path, monkeypatch, capsys):
    """compare into a folder that holds an earlier result: interrupted while staging, the folder is unchanged."""
    import fvd_bridge.report.page as page

    out = tmp_path / "cmp"
    out.mkdir()
    (out / "earlier.txt").write_text("kept\n")
    monkeypatch.setattr(page, "build_report", interrupt)  # the last step of the staged write
    rc = cli.main(["compare", PARAMS, str(inputs / "dev.csv"), "--no-figures", "--out", str(out)])
    assert rc == 130 and "interrupted" in capsys.readouterr().err
    assert sorted(os.listdir(out)) == ["earlier.txt"] and not leftovers(tmp_path)


def test_rig_interrupted_after_its_records_leaves_nothing(tmp_path, monkeypatch, capsys):
    import fvd_bridge.rig.series as series

    monkeypatch.setattr(series, "_atomic_yaml", interrupt)  # truth.yaml, after every record's CSV
    out = tmp_path / "lab"
    assert cli.main(["rig", "--devices", "2", "--protocol", "acceptance", "--out", str(out)]) == 130
    assert_nothing_left(tmp_path, out, capsys)


def test_demo_interrupted_after_its_records_leaves_nothing(tmp_path, monkeypatch, capsys):
    """demo writes its records first, then fits: interrupted at the fits, its new folder goes."""
    import fvd_bridge.commands.demo as demo

    monkeypatch.setattr(demo, "run_campaign", interrupt)
    out = tmp_path / "demo"
    assert cli.main(["demo", "--quick", "--out", str(out)]) == 130
    assert_nothing_left(tmp_path, out, capsys)


def test_staged_dir_and_atomic_file_clean_up_on_any_failure(tmp_path):
    out, file = tmp_path / "out", tmp_path / "f.txt"
    for error in (KeyboardInterrupt, ValueError):
        with pytest.raises(error):
            with staged_dir(str(out)) as stage:
                Path(stage, "half.csv").write_text("1,2\n")
                raise error
        with pytest.raises(error):
            with atomic_file(str(file)) as fh:
                fh.write("half")
                raise error
    assert os.listdir(tmp_path) == []


def test_check_output_names_the_option_in_the_callers_words(tmp_path):
    blocker = tmp_path / "f"
    blocker.write_text("x\n")
    assert check_output(str(tmp_path / "new" / "deeper"), "dir") == str(tmp_path / "new" / "deeper")
    with pytest.raises(InputError, match=rf"^{blocker}: is a file, not a folder$"):
        check_output(str(blocker), "dir")
    with pytest.raises(InputError, match=r"^path='.*f/x.png': lies inside"):
        check_output(str(blocker / "x.png"), "file", "--plot")  # from Python: plot_record's argument
