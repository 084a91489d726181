"""What a device's tests and honest intervals cost.

1. Joint fits scale with the samples: the default fit of law 2 and of
   2+series_stiffness+friction on each of three lab-like tests of one
   virtual device alone, then on the three together (``--device``); the
   ratio of the joint fit's time to the sum of the single fits' times.
2. Intervals against the calibration they belong to: the 20-replicate
   bootstrap (fit.intervals) beside a calibration of 1 run and of calibrate's
   default 20 runs, on one test.

The tests are lab-like CSVs (t,d,F with 0.5 kN and 0.005 mm noise, velocity
derived on reading) of a device with an oil column (Ks 120 kN/mm) and a
12 kN seal: 10 mm at 50 mm/s, 20 mm at 200 mm/s, 30 mm at 450 mm/s (3
cycles each, dt 0.002 s). Best of ``--repeat`` for every time.

    python benchmarks/bench_device.py [--repeat 3]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time

import numpy as np

from fvd_bridge.api import calibrate
from fvd_bridge.catalog import catalog
from fvd_bridge.fit import fit_model
from fvd_bridge.fit.intervals import REPLICATES, intervals
from fvd_bridge.records import read_record
from fvd_bridge.records.device import Device
from fvd_bridge.records.writers import write_csv
from fvd_bridge.rig import VirtualDamper
from fvd_bridge.rig import Noise, paper, simulate

LEVELS = ((10.0, 50.0), (20.0, 200.0), (30.0, 450.0))


def best_of(repeat: int, fn):
    """(best wall time [s], the last result)."""
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def lab_tests(folder: str) -> list:
    dev = VirtualDamper(C=40.0, alpha=0.3, Ks=120.0, friction=12.0, name="sn101")
    out = []
    for k, (amp, vel) in enumerate(LEVELS):
        rec = simulate(dev, paper(amplitude=amp, velocity=vel, cycles=3, dt=0.002), Noise(0.5, 0.005), seed=k,
                       name=f"sn101_{amp:g}mm")
        path = os.path.join(folder, f"{rec.name}.csv")
        write_csv(rec, path)
        out.append(read_record(path))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        tests = lab_tests(folder)
    cat = catalog()
    print(f"tests: {', '.join(f'{t.name} ({t.n} samples)' for t in tests)}; best of {args.repeat}")
    print("\n1. joint fits (default optimizer, seed 0)")
    print(f"  {'model':<30}{'sum of single fits':>20}{'joint fit':>12}{'ratio':>8}{'joint OF':>10}")
    for spec in ("2", "2+series_stiffness+friction"):
        model = cat.model(spec)
        single = sum(best_of(args.repeat, lambda t=t: fit_model(model, t, seed=0))[0] for t in tests)
        joint_s, fit = best_of(args.repeat, lambda: fit_model(model, Device("sn101", tests), seed=0))
        print(f"  {spec:<30}{single:>19.2f}s{joint_s:>11.2f}s{joint_s / single:>8.2f}{fit.of:>10.4f}")
    print(f"\n2. intervals ({REPLICATES} replicates) beside the calibration, on {tests[1].name}")
    print(f"  {'model':<30}{'1 run':>9}{'20 runs':>10}{'intervals':>11}{'/1 run':>8}{'/20 runs':>10}")
    for spec in ("2", "9", "2+series_stiffness+friction"):
        model = cat.model(spec)
        one, cal = best_of(args.repeat, lambda: calibrate(tests[1], model, runs=1, intervals=0))
        twenty, _ = best_of(1, lambda: calibrate(tests[1], model, runs=20, intervals=0))
        iv, _ = best_of(args.repeat, lambda: intervals(model, tests[1], cal.values, bounds=cal.bounds))
        print(f"  {spec:<30}{one:>8.2f}s{twenty:>9.2f}s{iv:>10.2f}s{iv / one:>8.1f}{iv / twenty:>10.2f}")
    sys.stdout.flush()


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
