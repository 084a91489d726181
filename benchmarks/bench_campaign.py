"""Wall time of the paper's full protocol on the demo series.

9 laws x 5 devices x 20 runs with the paper's GA (population 200, up to 200
generations, stop after 20 stalled generations), spread over every core, and
the same campaign with the default optimizer (DE + polish) for comparison.
Target on a 2-core machine: at most 5 minutes for the paper's protocol.

    python benchmarks/bench_campaign.py [--runs 20] [--optimizers ga,de]
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from fvd_bridge.campaign.runner import CampaignSettings, run_campaign
from fvd_bridge.rig import DEMO_NOISE, Noise, demo_series, paper, simulate_series


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=20)
    ap.add_argument("--optimizers", default="ga,de")
    ap.add_argument("--jobs", type=int, default=0)
    args = ap.parse_args()
    records = simulate_series(demo_series(), paper(), Noise(**DEMO_NOISE), seed=0)
    for r, dev in zip(records, demo_series()):
        r.name = dev.name
    specs = tuple(str(k) for k in range(1, 10))
    print(f"demo series: {len(records)} devices x {records[0].n} samples; 9 laws x {args.runs} runs; "
          f"{os.cpu_count()} cores\n")
    times = {}
    for opt in args.optimizers.split(","):
        cs = CampaignSettings(specs=specs, runs=args.runs, optimizer=opt, jobs=args.jobs)
        t0 = time.perf_counter()
        res = run_campaign(records, cs, progress=True)
        times[opt] = time.perf_counter() - t0
        evals = sum(r.evaluations for runs in res.values() for r in runs)
        mean_of = {s: np.mean([r.of for (dev, sp), runs in res.items() if sp == s for r in runs]) for s in specs}
        print(f"optimizer {opt:<4}: {times[opt]:7.1f} s wall, {evals:,} evaluations "
              f"({evals / times[opt]:,.0f} per s); mean OF per law: "
              + " ".join(f"{s}:{mean_of[s]:.4f}" for s in specs))
    if "ga" in times:
        print(f"\npaper protocol (GA) took {times['ga'] / 60:.1f} min (target <= 5 min)")
        for opt, t in times.items():
            if opt != "ga":
                print(f"{opt} / ga wall-time ratio: {t / times['ga']:.2f}")


if __name__ == "__main__":
    main()
