"""`make demo` on a fresh clone: the demo from an empty kernel cache and warm.

A fresh clone has no compiled kernels: its first `fvd-bridge demo` compiles
them (numba, cached on disk, ``fvd_bridge/kernel_cache.py``).  Each repeat
runs the demo as `make demo` does, in a subprocess, first with an empty
NUMBA_CACHE_DIR (a new temporary folder: cold), then again on the cache that
run filled (warm), and prints both wall times, their ratio, the time of the
demo's stages (its ``--profile``) and the kernels each run compiled (new
files in the cache: the warm run should compile none).  Targets (issue 42):
cold at most 60 s on 2 cores, and at most 3x warm.  A shared machine's load
changes from minute to minute, so cold and warm are compared within a
repeat, never across sessions.

    python benchmarks/bench_cold_start.py [--repeats 2] [--jobs 0]
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: the demo's stages (``--profile``) printed beside each run, by the start of their names
STAGES = ("kernels", "fits", "outputs")
COLD_LIMIT_S, RATIO_LIMIT = 60.0, 3.0


def cached(cache: Path) -> set[str]:
    """The compiled kernels in the cache: its data files (one per kernel and signature)."""
    return {str(p.relative_to(cache)) for p in cache.rglob("*.nbc")}


def demo(out: Path, cache: Path, jobs: int) -> tuple[float, dict]:
    """Wall time [s] of `fvd-bridge demo --out out` on the kernel cache ``cache``,
    and its stages {name: seconds}."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), MPLBACKEND="Agg")
    cmd = [sys.executable, "-m", "fvd_bridge.cli", "demo", "--out", str(out), "--profile"]
    if jobs:
        cmd += ["--jobs", str(jobs)]
    t0 = time.perf_counter()
    run = subprocess.run(cmd, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if run.returncode != 0:
        sys.exit(f"demo failed (exit {run.returncode}):\n{run.stderr[-3000:]}")
    stages = {}
    for line in run.stderr.splitlines():
        m = re.match(r"  (\S.*?)\s+(\d+\.\d+)\s+[\d.]+%\s+\d+$", line)
        if m and m.group(1).startswith(STAGES):
            stages[m.group(1).split(" ")[0].strip(",")] = float(m.group(2))
    return wall, stages


def stage_text(stages: dict) -> str:
    return ", ".join(f"{name} {seconds:.1f}" for name, seconds in stages.items())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=1, help="cold-then-warm pairs (default 1)")
    ap.add_argument("--jobs", type=int, default=0, help="the demo's processes (default: one per core)")
    args = ap.parse_args()
    print(f"`fvd-bridge demo` from an empty kernel cache (cold) and on the cache it filled (warm); "
          f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f} at the start")
    pairs = []
    for k in range(args.repeats):
        with tempfile.TemporaryDirectory(prefix="bench_cold_start_") as tmp:
            cache = Path(tmp) / "numba"
            cold, cold_stages = demo(Path(tmp) / "cold", cache, args.jobs)
            compiled = cached(cache)
            warm, warm_stages = demo(Path(tmp) / "warm", cache, args.jobs)
            new = cached(cache) - compiled
        pairs.append((cold, warm))
        print(f"repeat {k + 1}: cold {cold:.1f} s ({stage_text(cold_stages)}; {len(compiled)} kernels compiled), "
              f"warm {warm:.1f} s ({stage_text(warm_stages)}; {len(new)} compiled): cold/warm {cold / warm:.2f}; "
              f"load average {os.getloadavg()[0]:.1f}", flush=True)
    cold = min(c for c, _ in pairs)
    ratio = max(c / w for c, w in pairs)
    print(f"best cold {cold:.1f} s (target <= {COLD_LIMIT_S:.0f} s: {'met' if cold <= COLD_LIMIT_S else 'NOT met'}); "
          f"worst cold/warm {ratio:.2f} (target <= {RATIO_LIMIT:.0f}: {'met' if ratio <= RATIO_LIMIT else 'NOT met'})")


if __name__ == "__main__":
    main()
