"""One cache of the compiled kernels, and the word a cold or stale cache gets."""

from __future__ import annotations

import subprocess
import sys

import numpy as np

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
    index = tmp_path / "warm" / "fvd_bridge" / "laws" / "algebraic._algebraic-25.py311.nbi"
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
