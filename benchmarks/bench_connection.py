"""What the connection's kernels cost: a model with a series spring and a gap.

1. The population evaluator a fit calls (``Model.force``) for
   ``9+gap+series_stiffness``: members spread around the golden law 9
   (C 0.2, alpha 0.15, beta 27) with gaps 0.5-3 mm and springs 50-300
   kN/mm, on a 40 mm, 0.5 Hz sine (2 cycles, dt 0.002 s, 2,001 samples),
   populations of 1 (a polish step) and 64; evaluations/s.
2. The rig's Maxwell integrator (``rig.simulate``) for a device with an
   oil column (Ks 120 kN/mm), a seal and heating: the paper's protocol, 3
   cycles at dt 0.002 s; records/s.

Best of ``--repeat`` for every figure, after one warm-up call (which
compiles the kernels on an empty cache); wall time, or with ``--cpu`` the
process's CPU time on one thread (steadier on a loaded machine).

    python benchmarks/bench_connection.py [--repeat 3] [--cpu]
"""

from __future__ import annotations

import argparse
import time

import numba
import numpy as np

from fvd_bridge.catalog import parse_model
from fvd_bridge.records import Record
from fvd_bridge.rig import VirtualDamper, paper, simulate

SPEC = "9+gap+series_stiffness"
LAW9 = (0.2, 0.15, 27.0)  # C, alpha, beta (the golden set)


def sine(amp=40.0, freq=0.5, n_cycles=2.0, dt=0.002) -> Record:
    """d = amp sin(w t) [mm] with exact v, a."""
    t = np.arange(int(round(n_cycles / freq / dt)) + 1) * dt
    w = 2 * np.pi * freq
    d, v, a = amp * np.sin(w * t), amp * w * np.cos(w * t), -amp * w * w * np.sin(w * t)
    return Record(t, d, np.sign(v), v, a, name="sine")


def members(pop: int, seed: int = 0) -> np.ndarray:
    """(pop, 5) rows C, alpha, beta, g [mm], Ks [kN/mm] around the golden law 9."""
    rng = np.random.default_rng(seed)
    law = np.asarray(LAW9) * rng.uniform(0.8, 1.25, (pop, 3))
    return np.column_stack([law, rng.uniform(0.5, 3.0, pop), rng.uniform(50.0, 300.0, pop)])


def best_of(repeat: int, fn, clock=time.perf_counter) -> float:
    """Best time [s] of ``repeat`` calls by ``clock``, after one warm-up call."""
    fn()
    times = []
    for _ in range(repeat):
        t0 = clock()
        fn()
        times.append(clock() - t0)
    return min(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--cpu", action="store_true", help="CPU time on one thread instead of wall time")
    args = ap.parse_args()
    clock = time.process_time if args.cpu else time.perf_counter
    if args.cpu:
        numba.set_num_threads(1)
    model, record = parse_model(SPEC), sine()
    print(f"1. {SPEC}, {record.n} samples, best of {args.repeat}, {'CPU' if args.cpu else 'wall'} time")
    for pop in (1, 64):
        P = members(pop)
        s = best_of(args.repeat, lambda P=P: model.force(record, P), clock)
        print(f"  population {pop:>3}: {s * 1e3:9.1f} ms  {pop / s:9.1f} evaluations/s")
    device = VirtualDamper(C=40.0, alpha=0.3, Ks=120.0, friction=12.0, heating=0.05, name="sn101")
    protocol = paper(amplitude=20.0, velocity=200.0, cycles=3, dt=0.002)
    s = best_of(args.repeat, lambda: simulate(device, protocol), clock)
    print(f"2. rig, series spring: {s * 1e3:9.1f} ms  {1 / s:9.2f} records/s")


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
