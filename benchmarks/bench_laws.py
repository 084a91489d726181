"""Speed of the law kernels: population evaluations per second.

A 2,500-sample paper-like record (40 mm, 0.5 m/s, dt 0.002 s) and a
population of 200: the realistic parameter set of each law jittered by +-10 %
("nominal"), and 200 members drawn inside the 'auto' bounds (what a GA sees,
stiff law-7 members included).  Each figure is the best of several runs.  The
naive peer, timed in the same run on a few nominal members, is a per-member
scipy solve_ivp (RK45, default tolerances) for the differential laws and a
per-member Python loop over the samples for the algebraic ones.

    python benchmarks/bench_laws.py [--pop 200] [--repeats 7]
"""

from __future__ import annotations

import argparse
import math
import os
import time

import numba
import numpy as np
from scipy.integrate import solve_ivp

from fvd_bridge.laws import LAWS
from fvd_bridge.golden import REFERENCE as NOMINAL  # a realistic parameter set per law

DT, N = 0.002, 2500  # [s], samples
AMPLITUDE, V_PEAK = 40.0, 500.0  # [mm], [mm/s]
SCALES = {"F": 300.0, "v": V_PEAK, "d": AMPLITUDE}


def record():
    w = V_PEAK / AMPLITUDE
    t = np.arange(N) * DT
    s = np.clip(t * w / (2 * np.pi), 0.0, 1.0)  # fade in over the first cycle
    e, de = s * s * (3 - 2 * s), 6 * s * (1 - s) * w / (2 * np.pi)
    return t, AMPLITUDE * e * np.sin(w * t), AMPLITUDE * (de * np.sin(w * t) + e * w * np.cos(w * t))


def _sv(x, c, a):
    return c * math.copysign(abs(x) ** a, x)


NAIVE_SAMPLE = {  # force at one sample, for the per-member Python loop (laws 1-5)
    1: lambda d, v, C: C * v,
    2: lambda d, v, C, a: _sv(v, C, a),
    3: lambda d, v, C, a, K1: K1 * d + _sv(v, C, a),
    4: lambda d, v, C, a, K1, K2: K1 * d + K2 * d * d + _sv(v, C, a),
    5: lambda d, v, C, a, K, b: _sv(d, K, b) + _sv(v, C, a),
}
def _relief(F, C, Fr, p):  # law 10's dashpot velocity at the force F
    return F / C if abs(F) <= Fr else math.copysign(Fr / C + (abs(F) - Fr) / (p * C), F)


NAIVE_ODE = {  # (dz/dt, F) for solve_ivp (laws 6-10)
    6: (lambda z, v, C, K, a, b: v - b * abs(v) * z - b * v * abs(z),
        lambda z, d, v, C, K, a, b: a * K * d + (1 - a) * K * z + C * v),
    7: (lambda z, v, C, a, K, b: v - math.copysign((K * abs(z) ** b / C) ** (1 / a), z),
        lambda z, d, v, C, a, K, b: K * np.sign(z) * np.abs(z) ** b),
    8: (lambda z, v, C, K, mu, N: 0.0 if (z >= 1 and v > 0) or (z <= -1 and v < 0) else K / (mu * N) * v,
        lambda z, d, v, C, K, mu, N: np.clip(z, -1, 1) * mu * N + C * v),
    9: (lambda z, v, C, a, b: v - a * abs(v) * z, lambda z, d, v, C, a, b: b * z + C * v),
    10: (lambda z, v, K, C, Fr, p: K * (v - _relief(z, C, Fr, p)), lambda z, d, v, K, C, Fr, p: z),
}


def naive(number, t, d, v, P):
    """The naive peer's force for one member."""
    if number in NAIVE_SAMPLE:
        f = NAIVE_SAMPLE[number]
        return np.array([f(d[k], v[k], *P) for k in range(t.size)])
    rate, force = NAIVE_ODE[number]
    sol = solve_ivp(lambda s, z: [rate(z[0], np.interp(s, t, v), *P)], (t[0], t[-1]), [0.0], t_eval=t)
    return force(sol.y[0], d, v, *P)


def best_rate(fn, n_members, repeats):
    """Members per second: n_members / best wall time of fn()."""
    best = math.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return n_members / best


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--pop", type=int, default=200)
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--naive-members", type=int, default=3)
    args = parser.parse_args(argv)
    t, d, v = record()
    rng = np.random.default_rng(0)
    print(f"record: {N} samples, dt {DT} s; population {args.pop}; numba {numba.get_num_threads()} threads "
          f"({numba.config.THREADING_LAYER} layer); load average {os.getloadavg()[0]:.1f} "
          f"on {os.cpu_count()} CPUs")
    print(f"{'law':<4} {'kind':<13} {'first call s':>12} {'nominal /s':>12} {'auto /s':>12} "
          f"{'naive /s':>10} {'speed-up':>9}")
    for number, law in LAWS.items():
        nominal = np.array(NOMINAL[number]) * rng.uniform(0.9, 1.1, (args.pop, len(law.parameters)))
        b = law.bounds("auto", SCALES)
        auto = b[:, 0] + rng.random((args.pop, len(b))) * (b[:, 1] - b[:, 0])
        t0 = time.perf_counter()
        law.force(d, v, DT, auto[:1])  # compile, or load from numba's cache
        first = time.perf_counter() - t0
        r_nominal = best_rate(lambda: law.force(d, v, DT, nominal), args.pop, args.repeats)
        r_auto = best_rate(lambda: law.force(d, v, DT, auto), args.pop, args.repeats)
        members = nominal[:args.naive_members]
        r_naive = best_rate(lambda: [naive(number, t, d, v, p) for p in members], len(members), 1)
        print(f"{number:<4} {law.kind:<13} {first:12.2f} {r_nominal:12,.0f} {r_auto:12,.0f} "
              f"{r_naive:10,.1f} {r_nominal / r_naive:8,.0f}x")


if __name__ == "__main__":
    main()
