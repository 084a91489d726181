"""The paper's GA against the default optimizer on the same records.

For laws 2, 5, 6, 8 and 9 on demo device 1 (paper protocol, 1 kN noise): 20
seeded runs of each optimizer (``local`` the default, ``local+de`` the
same with a DE check after it); prints the median OF reached, how often a run
finds the best known OF (within 1%), median evaluations and wall time, and
the ratios against the paper's GA measured in the same run.

    python benchmarks/bench_optimizers.py [--runs 20] [--laws 2,5,6,8,9]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from fvd_bridge.fit import fit_model, noise_floor
from fvd_bridge.catalog import parse_model
from fvd_bridge.records.cycles import force_noise
from fvd_bridge.rig import DEMO_NOISE, Noise, demo_series, paper, simulate

OPTIMIZERS = ("ga", "ga+polish", "de", "local+de", "local")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=20)
    ap.add_argument("--laws", default="2,5,6,8,9")
    args = ap.parse_args()
    rec = simulate(demo_series()[0], paper(), Noise(**DEMO_NOISE), seed=0)
    floor = noise_floor(force_noise(rec.F), rec.F)
    print(f"record: demo device 1, {rec.n} samples; noise-floor OF ~ {floor:.4f}; {args.runs} runs each\n")
    print(f"{'law':>4} {'optimizer':>10} {'median OF':>10} {'best OF':>9} {'hit best':>9} "
          f"{'med. evals':>11} {'med. wall s':>11} {'OF/GA':>7} {'evals/GA':>9}")
    for law in args.laws.split(","):
        model = parse_model(law)
        model.force(rec, model.bounds("auto", rec.scales()).mean(axis=1)[None, :])  # compile first
        runs = {}
        for opt in OPTIMIZERS:
            out = []
            for seed in range(args.runs):
                t0 = time.perf_counter()
                r = fit_model(model, rec, optimizer=opt, seed=seed)
                out.append((r.of, r.evaluations, time.perf_counter() - t0))
            runs[opt] = np.array(out)
        best = min(r[:, 0].min() for r in runs.values())
        ga = runs["ga"]
        for opt, r in runs.items():
            hit = np.mean(r[:, 0] <= best * 1.01)
            print(f"{law:>4} {opt:>10} {np.median(r[:, 0]):10.4f} {r[:, 0].min():9.4f} {hit:9.0%} "
                  f"{np.median(r[:, 1]):11.0f} {np.median(r[:, 2]):11.2f} "
                  f"{np.median(r[:, 0]) / np.median(ga[:, 0]):7.2f} {np.median(r[:, 1]) / np.median(ga[:, 1]):9.2f}")
        print()


if __name__ == "__main__":
    main()
