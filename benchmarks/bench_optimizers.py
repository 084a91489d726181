"""The paper's GA against the default optimizer on the same records.

For laws 2, 5, 6, 8 and 9 on demo device 1 (paper protocol, 1 kN noise): 20
seeded runs of each optimizer (``local`` the default, ``local+de`` the
same with a DE check after it); prints the median OF reached, how often a run
finds the best known OF (within 1%), median evaluations and wall time, and
the ratios against the paper's GA measured in the same run.

    python benchmarks/bench_optimizers.py [--runs 20] [--laws 2,5,6,8,9]

``--broad``: the default optimizer and ``de`` on varied records instead:
six rig devices (seal friction, pin gap, a soft oil column, heating with
asymmetry, a preloaded accumulator, a moving mass behind a stiff column;
1 kN and 0.005 mm noise, written as t,d,F and read back) under the paper's
protocol and an acceptance protocol, and the shared lab records (the
friction damper at 0.5 and 1 Hz, the MR damper at 0 and 0.88 V) when
../shared is there; laws 1-6 and 8-10, ``--runs`` seeds each.  Prints, per
optimizer, the fits that end more than 1% (and 10%) above the best OF any
run found on that (law, record), and the wall time.

    python benchmarks/bench_optimizers.py --broad [--runs 2]
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

import numpy as np

from fvd_bridge.fit import fit_model, noise_floor
from fvd_bridge.catalog import parse_model
from fvd_bridge.records.cycles import force_noise
from fvd_bridge.records import read_record
from fvd_bridge.records.writers import write_csv
from fvd_bridge.rig import DEMO_NOISE, VirtualDamper, Noise, acceptance, demo_series, paper, simulate

SHARED = Path(__file__).resolve().parents[1] / ".." / "shared" / "devices"
#: the broad check's rig devices: each effect once, on a law-2 dashpot
BROAD_DEVICES = (VirtualDamper(C=45, alpha=0.3, friction=12, name="seal"), VirtualDamper(C=45, alpha=0.3, gap=1.0, name="gap"),
                 VirtualDamper(C=45, alpha=0.3, Ks=60, name="soft"),
                 VirtualDamper(C=45, alpha=0.6, heating=1.0, asymmetry=0.1, name="hot"),
                 VirtualDamper(C=20, alpha=0.15, Kp=2.0, preload=10, name="accumulator"),
                 VirtualDamper(C=45, alpha=0.3, mass=2000, Ks=200, name="mass"))

OPTIMIZERS = ("ga", "ga+polish", "de", "local+de", "local")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=20)
    ap.add_argument("--laws", default="2,5,6,8,9")
    ap.add_argument("--broad", action="store_true", help="varied records, the default optimizer against de")
    args = ap.parse_args()
    if args.broad:
        broad(args.runs if args.runs != 20 else 2)
        return
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


def broad_records() -> list:
    """The broad check's records (module docstring)."""
    folder, records = tempfile.mkdtemp(prefix="fvd_bench_"), []
    for k, dev in enumerate(BROAD_DEVICES):
        for name, protocol in (("paper", paper()), ("acceptance", acceptance())):
            path = os.path.join(folder, f"{dev.name}_{name}.csv")
            write_csv(simulate(dev, protocol, Noise(1.0, 0.005), seed=k, name=f"{dev.name}_{name}"), path)
            records.append(read_record(path))
    if SHARED.is_dir():
        import fvd_bridge as fb
        from scipy.io import loadmat

        records += [read_record(str(SHARED / f"arts_brfd_{f}.csv")) for f in ("0.5Hz_25lb", "1Hz_35lb")]
        for f in ("4.1_0V", "4.2_0.88V"):  # the README's reading: d column 0 [mm], F column 2 [N], dt 0.01 s
            x = loadmat(str(SHARED / f"labcontrol_mrdamper_{f}.mat"))["x_F"]
            t = np.arange(len(x)) * 0.01
            keep = (t >= 1.85) & (t <= 30.0)
            records.append(fb.Record.from_arrays(t[keep] - t[keep][0], x[keep, 0], x[keep, 2],
                                                 units=("N", "mm", "s"), name=f"mr_{f}"))
    return records


def broad(runs: int) -> None:
    records = broad_records()
    print(f"{len(records)} records, laws 1-6 and 8-10, {runs} seed(s) each\n")
    of, wall = {}, {}
    for opt in ("local", "de"):
        t0 = time.perf_counter()
        for law in ("1", "2", "3", "4", "5", "6", "8", "9", "10"):
            model = parse_model(law)
            for rec in records:
                of[(opt, law, rec.name)] = [fit_model(model, rec, optimizer=opt, seed=s).of for s in range(runs)]
        wall[opt] = time.perf_counter() - t0
    best = {key[1:]: min(min(v) for (o, *k), v in of.items() if tuple(k) == key[1:]) for key in of}
    print(f"{'optimizer':>10} {'fits':>5} {'> 1% above best':>16} {'> 10% above best':>17} {'wall s':>8}")
    for opt in ("local", "de"):
        ofs = [(k, x) for k, v in of.items() if k[0] == opt for x in v]
        miss = [(k, x) for k, x in ofs if x > 1.01 * best[k[1:]]]
        big = [1 for k, x in ofs if x > 1.10 * best[k[1:]]]
        print(f"{opt:>10} {len(ofs):5d} {len(miss):16d} {len(big):17d} {wall[opt]:8.1f}")
        for (o, law, rec), x in miss:
            print(f"{'':>12}law {law} on {rec}: OF {x:.4f}, best {best[(law, rec)]:.4f}")


if __name__ == "__main__":
    main()
