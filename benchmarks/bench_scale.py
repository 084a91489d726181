"""Throughput of a production-scale campaign: units per minute on local processes
and on a Dask LocalCluster, and the parallel efficiency against one worker.

A rig series of 200 devices (paper protocol, 2,865 samples; C 45.4 +-5%,
alpha 0.3 +-2%, Ks 150 kN/mm, 3 kN friction, 1 kN / 0.005 mm noise) x laws
2, 6, 9 x 5 runs = 3,000 units, each unit stored durably (campaign/store.py)
as in ``fvd-bridge campaign``.  Small optimizer settings: the paper's GA with
population 30, at most 30 generations, stop after 10 stalled (``--optimizer
ga --pop 30 --gens 30 --stall 10``).  Configurations: local 1 process, local
2 processes, Dask 1 worker, Dask 2 workers (process workers, one thread
each).  Wall time includes starting the pool or cluster; "steady" excludes
the time to the first finished unit.  The peer, measured in the same run: the
parallel efficiency of a pure-Python CPU loop in 1 and 2 processes, the most
this machine gives two workers at that moment (a shared 2-core machine gives
less than 100%).

    python benchmarks/bench_scale.py [--devices 200] [--runs 5] [--laws 2,6,9]
                                     [--configs local1,local2,dask1,dask2]
                                     [--optimizer ga --pop 30 --gens 30 --stall 10]
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time

import numpy as np

from fvd_bridge.campaign.executors import Dask, Processes
from fvd_bridge.campaign.resume import Resumable
from fvd_bridge.campaign.runner import CampaignSettings
from fvd_bridge.campaign.store import UnitStore
from fvd_bridge.calibration.tasks import make_tasks, run_task
from fvd_bridge.rig import VirtualDamper, Noise, paper, production_series, simulate_series


def _burn(n: int) -> int:
    s = 0
    for i in range(n):
        s += i * i
    return s


def machine_ceiling(n: int = 15_000_000) -> float:
    """Parallel efficiency of a pure CPU loop: time of 1 loop / time of 2 loops in 2 processes."""
    import multiprocessing

    t0 = time.perf_counter()
    _burn(n)
    one = time.perf_counter() - t0
    with multiprocessing.get_context("spawn").Pool(2) as pool:
        pool.map(_burn, [1000, 1000])  # started
        t0 = time.perf_counter()
        pool.map(_burn, [n, n], chunksize=1)
        two = time.perf_counter() - t0
    return one / two


def executor(name: str):
    kind, n = name[:-1], int(name[-1])
    return Processes(n) if kind == "local" else Dask(workers=n)


def measure(name: str, records, cs, root: str) -> dict:
    """Run every unit through Resumable(executor, store) into a fresh store."""
    import numba

    threads = numba.get_num_threads()
    if name == "local1":
        numba.set_num_threads(1)  # one worker: one core (Processes(1) runs in this process)
    store = UnitStore(os.path.join(root, name), source=name)
    store.open({"bench": name}, records)
    requests = {q.spec: q for q in cs.requests()}
    items = [(t, records[t.device_index], requests[t.spec]) for t in make_tasks(records, requests.values())]
    of = {}
    t0 = time.perf_counter()
    first = None
    try:
        for (task, _, _), res in Resumable(executor(name), store, progress=True, say=lambda s: None).run(
                run_task, items):
            first = first or time.perf_counter()
            of[task.id] = res.of
    finally:
        store.close()
        numba.set_num_threads(threads)
    wall = time.perf_counter() - t0
    n = len(items)
    return {"wall": wall, "units": n, "per_min": 60 * n / wall,
            "steady_per_min": 60 * (n - 1) / max(time.perf_counter() - first, 1e-9) if n > 1 else float("nan"),
            "startup": first - t0, "of": of}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--devices", type=int, default=200)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--laws", default="2,6,9")
    ap.add_argument("--configs", default="local1,local2,dask1,dask2")
    ap.add_argument("--optimizer", default="ga")
    ap.add_argument("--pop", type=int, default=30)
    ap.add_argument("--gens", type=int, default=30)
    ap.add_argument("--stall", type=int, default=10)
    args = ap.parse_args()
    nominal = VirtualDamper(C=45.4, alpha=0.3, Ks=150.0, friction=3.0)
    t0 = time.perf_counter()
    devices = production_series(args.devices, nominal, {"C": 0.05, "alpha": 0.02}, seed=0)
    records = simulate_series(devices, paper(), Noise(1.0, 0.005), seed=0)
    for r, d in zip(records, devices):
        r.name = d.name
    cs = CampaignSettings(specs=tuple(args.laws.split(",")), runs=args.runs, optimizer=args.optimizer,
                          pop=args.pop, gens=args.gens, stall=args.stall, seed=0)
    n_units = len(records) * len(cs.specs) * cs.runs
    print(f"{len(records)} rig devices x {records[0].n} samples (simulated in {time.perf_counter() - t0:.0f} s) "
          f"x laws {args.laws} x {args.runs} runs = {n_units} units; {args.optimizer} pop {args.pop}, gens <= "
          f"{args.gens}{f', stall {args.stall}' if args.optimizer.startswith('ga') else ''}; {os.cpu_count()} cores\n")
    ceiling = [machine_ceiling()]
    out = {}
    with tempfile.TemporaryDirectory(prefix="bench_scale_") as root:
        for name in args.configs.split(","):
            out[name] = m = measure(name, records, cs, root)
            print(f"{name:<7} {m['wall']:7.1f} s wall, {m['per_min']:8,.0f} units/min "
                  f"(steady {m['steady_per_min']:,.0f}/min after {m['startup']:.1f} s to the first unit)",
                  flush=True)
    ceiling.append(machine_ceiling())
    print(f"\npeer: a pure CPU loop in 2 processes runs at {min(ceiling):.0%}-{max(ceiling):.0%} parallel efficiency "
          f"on this machine now (before and after)")
    for kind in ("local", "dask"):
        one, two = out.get(f"{kind}1"), out.get(f"{kind}2")
        if one and two:
            eff = two["per_min"] / (2 * one["per_min"])
            print(f"{kind}: parallel efficiency with 2 workers {eff:.0%} "
                  f"(steady {two['steady_per_min'] / (2 * one['steady_per_min']):.0%}; {eff / np.mean(ceiling):.0%} "
                  f"of the peer's); speed-up {two['per_min'] / one['per_min']:.2f}x")
    names = list(out)
    same = all(np.array_equal([out[names[0]]["of"][k] for k in sorted(out[names[0]]["of"])],
                              [out[n]["of"][k] for k in sorted(out[n]["of"])]) for n in names[1:])
    print(f"every configuration found the same OF for every unit: {'yes' if same else 'NO'}")


if __name__ == "__main__":
    main()
