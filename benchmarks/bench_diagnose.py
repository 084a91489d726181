"""Wall time of one diagnosis: law 2 fitted, then refitted with each of the
seven built-in effects, on one 3,000-sample record.

The record is demo device 1 of the virtual rig (every effect a little, 1 kN
force noise) under the paper's protocol at dt = 0.002 s (2,866 samples), with
the diagnose defaults (DE population 12 per parameter, 200 generations,
Nelder-Mead polish).  Target on a 2-core machine: at most 60 s.  Also times
the ladder from law 2.

    python benchmarks/bench_diagnose.py [--no-ladder] [--seed 0]
"""

from __future__ import annotations

import argparse
import os
import time

from fvd_bridge.diagnose import climb, diagnose, diagnose_settings, format_ladder
from fvd_bridge.rig import DEMO_NOISE, Noise, demo_series, paper, simulate

TARGET_S = 60.0


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--no-ladder", action="store_true")
    args = ap.parse_args()
    dev = demo_series()[0]
    rec = simulate(dev, paper(), Noise(**DEMO_NOISE), seed=1, name=dev.name)
    settings = diagnose_settings()
    print(f"{dev.name}: {rec.n} samples, {os.cpu_count()} cores; settings {settings}\n")
    diagnose(rec, "2", seed=args.seed, settings=diagnose_settings(4, 2, 10))  # warm the compiled kernels
    t0 = time.perf_counter()
    diag = diagnose(rec, "2", seed=args.seed, settings=settings,
                    progress=lambda m: print(f"  {time.perf_counter() - t0:6.1f} s  {m}", flush=True))
    wall = time.perf_counter() - t0
    print(f"\ndiagnose --law 2 with {len(diag.candidates)} candidates: {wall:.1f} s wall "
          f"(target <= {TARGET_S:.0f} s); {sum(c.fit.evaluations for c in diag.candidates):,} candidate "
          f"evaluations; best: {diag.verdict()}")
    if not args.no_ladder:
        t0 = time.perf_counter()
        lad = climb(rec, "2", seed=args.seed, settings=settings)
        print(f"\nladder from law 2: {time.perf_counter() - t0:.1f} s wall")
        print(format_ladder(lad))


if __name__ == "__main__":
    main()
