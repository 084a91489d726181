"""A gap model on a 27-second earthquake test: what a calibration costs.

The test: El Centro 1940 NS (``../shared/records``) drives a 1 s, 5%
single-degree-of-freedom structure; its relative displacement, the first
27 s scaled to a 30 mm peak, is the actuator's command at 500 Hz (13,500
samples).  ``fvd-bridge rig`` makes the device's test record: an orifice
(C 45.4, alpha 0.3) with a 2 kN/mm accumulator spring and a 2 mm pin gap,
1 kN force and 0.005 mm displacement noise, written as t,d,F.

Timed (wall clock, the machine's cores, the user's warm kernel cache):
``fvd-bridge calibrate REC --laws MODEL`` as a user runs it (20 runs asked,
20 bootstrap replicates), against one run without intervals (``--runs 1
--intervals 0``: the fit alone) and, with ``--all-runs``, against every run
made (as before runs that repeat each other were left out); each row with
the runs' mean and best OF.  Two models: the device's own law with its gap
(``2+parallel_stiffness+gap``, at the noise's OF), and law 9 with the same
effects, which misses the record (its runs need not agree: then all 20 are
made).

    python benchmarks/bench_earthquake_test.py [--keep DIR] [--all-runs]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np
from scipy import signal

from fvd_bridge.records.motions import read_motion

SHARED = os.path.join(os.path.dirname(__file__), "..", "..", "shared", "records")
RECORD = "elcentro_1940_NS_2688pts_g_dt0.02.dat"
DURATION, DT, PEAK = 27.0, 0.002, 30.0
SPECS = ("2+parallel_stiffness+gap", "9+parallel_stiffness+gap")
CLI = [sys.executable, "-m", "fvd_bridge.cli"]


def command_history(path: str) -> None:
    """Write the actuator's command t,d [s, mm]: the SDOF's relative displacement."""
    motion = read_motion(os.path.join(SHARED, RECORD), units="g", dt=0.02)
    w, zeta = 2 * np.pi / 1.0, 0.05
    sdof = signal.StateSpace([[0.0, 1.0], [-w * w, -2 * zeta * w]], [[0.0], [-1.0]], [[1.0, 0.0]], [[0.0]])
    t = np.arange(0.0, DURATION, DT)
    ag = np.interp(t, motion.dt * np.arange(motion.accel.size), motion.accel)
    _, x, _ = signal.lsim(sdof, ag, t)
    d = PEAK * x / np.max(np.abs(x))
    np.savetxt(path, np.column_stack([t, d]), delimiter=",", header="t,d", comments="", fmt="%.6f")


def timed(args: list) -> float:
    t0 = time.perf_counter()
    res = subprocess.run([*CLI, *args], capture_output=True, text=True)
    if res.returncode != 0:
        sys.exit(f"fvd-bridge {' '.join(args)} failed:\n{res.stderr}")
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--keep", help="folder for the record and outputs (default: a temporary one)")
    ap.add_argument("--all-runs", action="store_true", help="also time every run made (about 20 min on 2 cores)")
    args = ap.parse_args()
    if not os.path.exists(os.path.join(SHARED, RECORD)):
        sys.exit(f"skipped: {RECORD} is not in {SHARED}")
    root = args.keep or tempfile.mkdtemp(prefix="fvd_eq_")
    os.makedirs(root, exist_ok=True)
    command_history(os.path.join(root, "command.csv"))
    timed(["rig", "--out", os.path.join(root, "rec"), "--protocol", f"history:{root}/command.csv",
           "--C", "45.4", "--alpha", "0.3", "--Kp", "2", "--gap", "2", "--noise", "1", "--dt", str(DT)])
    rec = os.path.join(root, "rec", "device_01.csv")
    timed(["calibrate", rec, "--laws", "2", "--runs", "1", "--intervals", "0", "--out",
           os.path.join(root, "warm"), "--no-figures", "--quiet"])  # the kernels compiled, if they were not
    cases = [("default (20 runs asked, 20 replicates)", []),
             ("the fit alone (--runs 1 --intervals 0)", ["--runs", "1", "--intervals", "0"])]
    if args.all_runs:
        cases.append(("--all-runs (every run made)", ["--all-runs"]))
    print(f"a {DURATION:.0f} s earthquake test ({round(DURATION / DT)} samples at {1 / DT:.0f} Hz), "
          f"{os.cpu_count()} cores")
    print(f"{'model':<26}{'calibration':<42}{'wall s':>8}{'runs made':>11}{'mean OF':>10}{'best OF':>10}", flush=True)
    for spec in SPECS:
        walls = []
        for k, (label, extra) in enumerate(cases):
            out = os.path.join(root, f"out_{spec}_{k}")
            wall = timed(["calibrate", rec, "--laws", spec, "--out", out, "--no-figures", "--quiet", *extra])
            summary = json.load(open(os.path.join(out, "summary.json")))
            runs = [r["of"] for r in summary["runs"]]
            print(f"{spec:<26}{label:<42}{wall:>8.1f}{len(runs):>11}{np.mean(runs):>10.5f}{min(runs):>10.5f}",
                  flush=True)
            walls.append(wall)
        print(f"{spec}: the default against the fit alone: {walls[0] / walls[1]:.1f}x the time"
              + (f"; against --all-runs: {walls[0] / walls[2]:.2f}x" if args.all_runs else ""))


if __name__ == "__main__":
    main()
