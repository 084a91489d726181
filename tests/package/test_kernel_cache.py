"""One cache of the compiled kernels, the word a cold or stale cache gets,
and no kernel compiled twice."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from conftest import CLI, cli_env


def test_the_package_points_numba_at_one_cache(tmp_path):
    """Without NUMBA_CACHE_DIR the package sets the user's cache folder
    before any kernel compiles; a user's setting wins."""
    env = {k: v for k, v in cli_env().items() if k != "NUMBA_CACHE_DIR"}
    env["XDG_CACHE_HOME"] = str(tmp_path / "xdg")
    code = "import fvd_bridge, numba.core.config as c, os; print(os.environ['NUMBA_CACHE_DIR'], c.CACHE_DIR)"
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert out.stdout.split() == [str(tmp_path / "xdg" / "fvd_bridge" / "numba")] * 2, out.stderr
    env["NUMBA_CACHE_DIR"] = str(tmp_path / "mine")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert out.stdout.split() == [str(tmp_path / "mine")] * 2, out.stderr


def test_a_cold_cache_is_announced_and_a_warm_one_is_not(tmp_path):
    """A verb that runs the kernels, on an empty cache, says it compiles
    first (here it then refuses a missing file, before compiling anything);
    on a cache that holds the marker kernel's index it says nothing of it."""
    env = dict(cli_env(), NUMBA_CACHE_DIR=str(tmp_path / "empty"))
    cold = subprocess.run([*CLI, "calibrate", str(tmp_path / "none.csv")], env=env, capture_output=True, text=True)
    assert cold.returncode == 2 and "compiling the numerical kernels" in cold.stderr, cold.stderr
    index = tmp_path / "warm" / "fvd_bridge" / "laws" / "algebraic._algebraic-16.py311.nbi"
    index.parent.mkdir(parents=True)
    index.touch()
    env["NUMBA_CACHE_DIR"] = str(tmp_path / "warm")
    warm = subprocess.run([*CLI, "calibrate", str(tmp_path / "none.csv")], env=env, capture_output=True, text=True)
    assert warm.returncode == 2 and "compiling" not in warm.stderr, warm.stderr


def test_a_stale_kernel_is_announced_once_when_it_compiles(monkeypatch):
    """On a warm cache the notice waits for numba's compile event: a
    function compiled now (a new one, never cached) triggers it once."""
    from numba import njit
    from numba.core import event

    from fvd_bridge import kernel_cache

    monkeypatch.setattr(kernel_cache, "cold", lambda: False)
    said = []
    listener = kernel_cache.announce(said.append)
    try:
        assert said == []
        fresh = njit(lambda x: x * 2.0 + 1.0)
        assert fresh(np.float64(2.0)) == 5.0 and fresh(np.int64(2)) == 5.0  # two compilations
        assert len(said) == 1 and "compiling the numerical kernels" in said[0]
    finally:
        event.unregister("numba:compile", listener)


def test_a_read_only_record_runs_the_kernels_compiled_for_a_writable_one():
    """numba compiles a kernel once per argument type, and a read-only array
    (a frozen record, a broadcast parameter row) is a type of its own: the
    laws hand their kernels writable arrays (kernel_cache.kernel_array), so
    such a record compiles nothing new (an algebraic and a differential law, and
    the record's reversals)."""
    from fvd_bridge.laws import algebraic, differential, get_law
    from fvd_bridge.records import cycles

    t = np.arange(64) * 0.01
    d, v = 10.0 * np.sin(2 * np.pi * t), 20 * np.pi * np.cos(2 * np.pi * t)
    kernels = (algebraic._algebraic, differential._lugre_force, cycles._reversals)
    for key in ("2", "9"):
        law = get_law(key)
        law.force(d, v, 0.01, np.array([law.reference]))
    expected = cycles.reversals(d)
    before = {k.py_func.__name__: list(k.signatures) for k in kernels}
    frozen_d, frozen_v = d.copy(), v.copy()
    frozen_d.setflags(write=False)
    frozen_v.setflags(write=False)
    for key in ("2", "9"):
        law = get_law(key)
        F = law.force(frozen_d, frozen_v, 0.01, np.broadcast_to(np.array(law.reference), (1, len(law.reference))))
        assert np.array_equal(F, law.force(d, v, 0.01, np.array([law.reference])))
    assert np.array_equal(cycles.reversals(frozen_d), expected)
    assert {k.py_func.__name__: list(k.signatures) for k in kernels} == before


def _cache_files(cache):
    return {str(p.relative_to(cache)): p.stat().st_mtime_ns for p in cache.rglob("*") if p.suffix in (".nbi", ".nbc")}


@pytest.mark.slow
@pytest.mark.parametrize("models", ["2+series_stiffness,2+thermal_softening",
                                    "2+series_stiffness,2+asymmetry+thermal_softening"])
def test_diagnose_after_calibrate_compiles_nothing_again(tmp_path, models):
    """After a calibration that ran a law, its connection and its heating, a
    diagnosis of the same law on another record of the same kind (its
    candidates: the same kernels) compiles nothing: no notice, and numba's
    cache files (index and compiled code) are the calibration's, unchanged.
    The heating behind the asymmetry gets a read-only view of its output,
    the heating alone a writable array: the kernel is handed one type
    (``kernel_cache.kernel_array``) either way."""
    env = dict(cli_env(), NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    run = lambda *args: subprocess.run([*CLI, *args], env=env, capture_output=True, text=True, cwd=tmp_path)
    rig = run("rig", "--out", "lab", "--devices", "2", "--C", "45", "--alpha", "0.3", "--Ks", "150",
              "--heating", "0.05", "--noise", "1")
    assert rig.returncode == 0, rig.stderr
    cal = run("calibrate", "lab/device_01.csv", "--laws", models, "--runs", "1",
              "--jobs", "1", "--intervals", "0", "--no-figures", "--quiet", "--out", "cal")
    assert cal.returncode == 0, cal.stderr
    compiled = _cache_files(tmp_path / "numba")
    diag = run("diagnose", "lab/device_02.csv", "--law", "2", "--intervals", "0", "--no-figures", "--out", "diag")
    assert diag.returncode == 0, diag.stderr
    assert "compiling" not in diag.stderr, diag.stderr
    assert _cache_files(tmp_path / "numba") == compiled


CONCURRENT_SAVE = '''
import pathlib, sys, time
import fvd_bridge  # noqa: F401 (locks numba's index updates)
from numba.core.caching import IndexDataCacheFile

load = IndexDataCacheFile._load_index


def slow_load(self):  # widen the window between reading the index and writing it back
    overloads = load(self)
    time.sleep(0.5)
    return overloads


IndexDataCacheFile._load_index = slow_load
here = pathlib.Path(sys.argv[1])
sys.path.insert(0, str(here))
import kernel

(here / f"ready{sys.argv[2]}").touch()
while not (here / "go").exists():
    time.sleep(0.01)
kernel.twice([1, 2.0, 3j][int(sys.argv[2])])
'''


def test_processes_that_compile_one_kernel_at_once_keep_each_others_entries(tmp_path):
    """Three processes save three specializations of one kernel into its
    cache index at the same time (each slowed between reading the index and
    writing it back): every entry survives, each under its own data file."""
    import pickle
    import time

    (tmp_path / "kernel.py").write_text("from numba import njit\n\n\n@njit(cache=True)\ndef twice(x):\n"
                                        "    return 2 * x\n")
    (tmp_path / "save.py").write_text(CONCURRENT_SAVE)
    env = dict(cli_env(), NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    procs = [subprocess.Popen([sys.executable, str(tmp_path / "save.py"), str(tmp_path), str(k)], env=env,
                              stderr=subprocess.PIPE, text=True) for k in range(3)]
    while not all((tmp_path / f"ready{k}").exists() for k in range(3)):
        assert all(p.poll() is None for p in procs), [p.communicate()[1] for p in procs]
        time.sleep(0.05)
    (tmp_path / "go").touch()
    assert all(p.wait() == 0 for p in procs), [p.communicate()[1] for p in procs]
    (index,) = (tmp_path / "numba").rglob("kernel.twice-*.nbi")
    with open(index, "rb") as f:
        pickle.load(f)  # numba's version
        _, overloads = pickle.loads(f.read())
    assert len(overloads) == 3 and len(set(overloads.values())) == 3
