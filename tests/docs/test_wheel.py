"""An installed package does everything a checkout does: the wheel carries
the FMU's C sources (package data), and installed into a fresh virtual
environment it walks rig, calibrate, diagnose, export opensees --check and
export fmu from a folder outside the checkout (slow).  Building an FMU
without cmake or a C compiler: one line naming the Debian packages, exit 2,
nothing written."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pytest

from conftest import CLI, REPO, cli_env
from fvd_bridge.calibration import Calibration
from fvd_bridge.catalog import parse_model
from fvd_bridge.errors import InputError
from fvd_bridge.export import fmu as fmu_export
from fvd_bridge.export.fmu_toolchain import build_log_problem, missing_tools, toolchain_problem
from fvd_bridge.golden import reference_params

#: what build_fmu copies out of the package into every FMU's sources/
FMU_FILES = fmu_export.SOURCE_FILES + ("buildDescription.xml",)


def law2() -> Calibration:
    model = parse_model("2")
    return Calibration(model, reference_params(model), of=0.0)


def bin_with(tmp_path, *tools) -> str:
    """A PATH holding only links to the given tools of this machine (those it has)."""
    folder = tmp_path / "bin"
    folder.mkdir()
    for tool in tools:
        found = shutil.which(tool)
        if found:
            (folder / tool).symlink_to(found)
    return str(folder)


# ------------------------------------------------------------ where the sources are
def test_the_sources_are_inside_the_package():
    """The C sources sit in the package (fvd_bridge/fmu/, where the wheel puts
    them), not at the repository's top level, which keeps only a pointer."""
    package = Path(fmu_export.__file__).resolve().parents[1]
    assert fmu_export.FMU_SOURCES == package / "fmu"
    assert all((fmu_export.FMU_SOURCES / name).is_file() for name in FMU_FILES)
    top = REPO / "fmu"
    assert sorted(p.name for p in top.iterdir()) == ["README.md"]
    assert "fvd_bridge/fmu/" in (top / "README.md").read_text()


def test_missing_sources_are_one_line(tmp_path, monkeypatch):
    monkeypatch.setattr(fmu_export, "FMU_SOURCES", tmp_path / "gone")
    with pytest.raises(InputError, match=r"C sources are missing from this installation.*reinstall fvd_bridge"):
        fmu_export.build_fmu(law2(), tmp_path / "x.fmu")
    assert [p.name for p in tmp_path.iterdir()] == []


# ------------------------------------------------------------ the toolchain
def test_missing_tools_are_named_with_their_debian_packages(tmp_path):
    """PATH decides: nothing on it, all three missing; cmake and make only, the
    compiler; CC naming a missing program, that program."""
    empty = tmp_path / "empty"
    empty.mkdir()
    line = toolchain_problem({"PATH": str(empty)})
    assert line == ("building an FMU needs cmake, make and a C compiler (cc, gcc or clang), not found on PATH: "
                    "install them (Debian: sudo apt-get install cmake make gcc libc6-dev)")
    if not (shutil.which("cmake") and shutil.which("make")):
        pytest.skip("this machine lacks cmake or make")
    path = bin_with(tmp_path, "cmake", "make")
    assert [what for what, _ in missing_tools({"PATH": path})] == ["a C compiler (cc, gcc or clang)"]
    assert toolchain_problem({"PATH": path}).endswith("install it (Debian: sudo apt-get install gcc libc6-dev)")
    assert missing_tools({"PATH": path, "CC": "/nonexistent/cc -O2"})[0][0] == "the C compiler CC=/nonexistent/cc -O2"
    assert missing_tools({"PATH": path, "CC": shutil.which("cmake")}) == []  # any program CC names, as CMake takes it
    assert [w for w, _ in missing_tools({"PATH": str(empty), "CMAKE_GENERATOR": "Ninja",
                                         "CC": shutil.which("cmake")})] == ["cmake"]


def test_a_missing_c_library_header_is_one_line():
    log = "model.c:1:10: fatal error: math.h: No such file or directory\n    1 | #include <math.h>\n"
    assert build_log_problem(log) == ("compiling the FMU: the C library's header math.h is missing: install it "
                                      "(Debian: sudo apt-get install libc6-dev)")
    assert build_log_problem("laws.c:3:10: fatal error: config.h: No such file or directory") is None
    assert build_log_problem("laws.c:40:5: error: expected ';' before '}' token") is None


def test_export_fmu_without_a_compiler_is_one_line_and_exit_2(tmp_path):
    """The verb on a machine with cmake and make but no C compiler: exit 2, one
    line naming gcc and libc6-dev, no traceback, no FMU and no partial file."""
    params = law2().save(str(tmp_path / "law2.yaml"))
    env = cli_env()
    env["PATH"] = bin_with(tmp_path, "cmake", "make")
    env.pop("CC", None)
    out = tmp_path / "out"
    out.mkdir()
    res = subprocess.run(CLI + ["export", "fmu", params, "-o", str(out / "damper.fmu")],
                         capture_output=True, text=True, env=env)
    assert res.returncode == 2, res.stderr[-2000:]
    errors = [line for line in res.stderr.splitlines() if not line.startswith("warning:")]
    assert len(errors) == 1 and "Traceback" not in res.stderr
    assert "a C compiler" in errors[0] and "sudo apt-get install" in errors[0] and "gcc libc6-dev" in errors[0]
    assert list(out.iterdir()) == []


# ------------------------------------------------------------ the wheel, installed (slow)
def source_tree(dest: Path) -> Path:
    """A copy of the checkout's files (tracked and new, not ignored; the whole
    tree less the usual build and cache folders without git): the wheel is
    built there, leaving no build/ or egg-info in the checkout."""
    try:
        listed = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
                                cwd=REPO, capture_output=True, check=True).stdout.decode().split("\0")
    except (OSError, subprocess.CalledProcessError):
        skip = shutil.ignore_patterns(".git", ".venv", "build", "*.egg-info", "__pycache__", ".numba_cache",
                                      "results", "demo_out", "site", "test-artifacts", ".pytest_cache")
        shutil.copytree(REPO, dest, ignore=skip)
        return dest
    for name in filter(None, listed):
        src = REPO / name
        if src.is_file():  # a file deleted but not yet committed is listed, and absent
            (dest / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dest / name)
    return dest


def fresh_venv(folder: Path) -> Path:
    """A virtual environment without this one's packages in its site-packages;
    fvd_bridge's dependencies reached through a .pth line to this environment's
    site-packages (after its own: the wheel's fvd_bridge comes first; .pth
    files there, such as an editable install's finder, do not run)."""
    subprocess.run([sys.executable, "-m", "venv", str(folder)], check=True)
    python = folder / ("Scripts/python.exe" if os.name == "nt" else "bin/python")
    own = subprocess.run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                         capture_output=True, text=True, check=True).stdout.strip()
    parents = dict.fromkeys(sysconfig.get_paths()[k] for k in ("purelib", "platlib"))
    Path(own, "_fvd_bridge_dependencies.pth").write_text("\n".join(parents) + "\n")
    return python


@pytest.mark.slow
def test_an_installed_wheel_walks_the_quick_start(tmp_path):
    """Build the wheel, install it into a fresh environment and walk the
    README's quick start from a folder outside the checkout: rig, calibrate,
    diagnose, export opensees --check, export fmu (validated by FMPy)."""
    from fmpy import read_model_description, sharedLibraryExtension
    from fmpy.validation import validate_fmu

    src = source_tree(tmp_path / "src")
    # pip's isolated build fetches setuptools from the index (or its cache), as `pip install -e .` did
    built = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(tmp_path / "dist"),
                            str(src)], capture_output=True, text=True)
    assert built.returncode == 0, built.stderr[-3000:]
    wheel = next((tmp_path / "dist").glob("fvd_bridge-*.whl"))
    names = zipfile.ZipFile(wheel).namelist()
    assert all(f"fvd_bridge/fmu/{name}" in names for name in FMU_FILES)
    assert "fvd_bridge/records/data/elcentro_1940_NS.txt" in names  # the README's frame example's record
    assert not [n for n in names if n.startswith(("fmu/", "tests/"))]

    python = fresh_venv(tmp_path / "env")
    installed = subprocess.run([str(python), "-m", "pip", "install", "-q", "--no-deps", "--no-index", str(wheel)],
                               capture_output=True, text=True)
    assert installed.returncode == 0, installed.stderr[-3000:]
    work = tmp_path / "work"
    work.mkdir()
    env = {k: v for k, v in cli_env().items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env["PATH"] = str(python.parent) + os.pathsep + env.get("PATH", "")
    env["NUMBA_CACHE_DIR"] = str(tmp_path / "kernels")  # a fresh user's cache, not the checkout's
    where = subprocess.run([str(python), "-c", "import fvd_bridge; print(fvd_bridge.__file__)"],
                           cwd=work, env=env, capture_output=True, text=True, check=True).stdout.strip()
    assert Path(where).is_relative_to(tmp_path / "env") and not Path(where).is_relative_to(REPO), where

    fvd_bridge = str(python.parent / "fvd-bridge")

    def run(*args):
        res = subprocess.run([fvd_bridge, *args], cwd=work, env=env, capture_output=True, text=True)
        assert res.returncode == 0, f"fvd-bridge {' '.join(args)}: exit {res.returncode}\n{res.stderr[-3000:]}"
        assert "Traceback" not in res.stderr
        return res

    run("rig", "--out", "lab", "--C", "45", "--alpha", "0.3", "--Ks", "150", "--noise", "1", "--seed", "3")
    record = "lab/device_01.csv"
    run("calibrate", record, "--laws", "2", "--runs", "4", "--intervals", "20", "--out", "cal")
    run("diagnose", record, "--law", "2", "--out", "diag")
    best = json.loads((work / "diag" / "device_01_diagnose.json").read_text())["candidates"][0]
    assert best["effect"] == "series_stiffness"  # the rig's planted Ks
    params = best["calibration"]
    run("export", "opensees", params, "-o", "damper.py", "--units", "kN,m,s", "--check")
    assert (work / "damper.py").is_file()
    res = run("export", "fmu", params, "-o", "damper.fmu")
    fmu = work / "damper.fmu"
    assert "validated" in res.stderr and fmu.is_file()
    assert validate_fmu(str(fmu)) == []
    assert read_model_description(str(fmu)).fmiVersion == "3.0"
    inside = zipfile.ZipFile(fmu).namelist()
    assert all(f"sources/{name}" in inside for name in FMU_FILES)
    assert [n for n in inside if n.startswith("binaries/") and n.endswith(sharedLibraryExtension)]
    assert not list(work.rglob("*.partial-*"))
