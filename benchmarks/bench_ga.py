"""The paper's GA against a plain numba population kernel, law 9, same record.

The record is bench_optimizers.py's: demo device 1 under the paper's
protocol (1 kN force noise, 2,865 samples).  Two ways to evaluate law 9
(LuGre + viscous, paper eqs. 14-15 with eps = K = F0 = 0) on it:

- the peer: what a user writes by hand, one ``@njit(parallel=True)`` loop
  over the members that integrates z (dz/dt = v - alpha |v| z, exactly
  over each step's travel with v linear between samples, split where v
  changes sign) and sums eq. 18's objective as it goes
  (``peer_objective``, written here, not the project's kernel); it is
  handed populations of 200 members drawn in the GA's search box, one call
  each, and its figure is members evaluated per second;
- fvd_bridge's ``fit_model(..., optimizer="ga")``, the paper's GA (Table 3:
  population 200, at most 200 generations, stop after 20 without a better
  best, 1% mutation, seed per run): parameter sets evaluated per second
  of the whole fit's wall time, everything around the kernel included
  (selection, crossover, mutation, the repeated children's reuse, the
  unit-cube transform, eq. 18 on the forces, the progress callback).

The two are timed in turn, ``--rounds`` times (peer, GA, peer, GA, ...),
each round about as long for both, and the ratio is taken round by round
(its median is the figure): a machine whose speed drifts slows both.  The peer's
OF is checked against the project's on a few members (an independent
algorithm: they agree to rounding).  Last, what a GA generation costs
around the kernel: its operators alone (with an objective that costs
nothing) and eq. 18 on a generation's new children beyond the kernel's own
time (best of many; ``NUMBA_NUM_THREADS=1`` times the two on one thread).

    python benchmarks/bench_ga.py [--rounds 21] [--runs 2]
"""

from __future__ import annotations

import argparse
import math
import time

import numba
import numpy as np
from numba import njit, prange

from fvd_bridge.catalog import parse_model
from fvd_bridge.fit import evaluate_params, fit_model
from fvd_bridge.fit.api import joint_objective, residual_weights
from fvd_bridge.fit.ga import GASettings, run_ga
from fvd_bridge.fit.layout import Layout
from fvd_bridge.fit.space import Space
from fvd_bridge.records.device import as_device
from fvd_bridge.rig import DEMO_NOISE, Noise, demo_series, paper, simulate

POP = 200  # the paper's population (Table 3)


@njit(cache=True)
def lugre_travel(z, u, alpha):
    """z after a travel u [mm] of one sign: dz/du = sign(u) - alpha z, so z
    relaxes exponentially towards sign(u)/alpha."""
    if u == 0.0:
        return z
    target = (1.0 if u > 0.0 else -1.0) / alpha
    return target + (z - target) * math.exp(-alpha * abs(u))


@njit(parallel=True, cache=True)
def peer_objective(P, v, dt, F, weights):
    """Eq. 18 of law 9 for each row (C, alpha, beta) of P: F_model = beta z
    + C v, z from 0; OF = sum_k |F_model,k - F_k| weights_k."""
    out = np.empty(P.shape[0])
    for i in prange(P.shape[0]):
        C, alpha, beta = P[i, 0], P[i, 1], P[i, 2]
        z = 0.0
        total = abs(C * v[0] - F[0]) * weights[0]
        for k in range(1, v.size):
            v0, v1 = v[k - 1], v[k]
            if v0 * v1 >= 0.0:
                z = lugre_travel(z, 0.5 * (v0 + v1) * dt, alpha)
            else:  # v changes sign inside the step: two travels of one sign each
                tau = dt * v0 / (v0 - v1)
                z = lugre_travel(z, 0.5 * v0 * tau, alpha)
                z = lugre_travel(z, 0.5 * v1 * (dt - tau), alpha)
            total += abs(beta * z + C * v1 - F[k]) * weights[k]
        out[i] = total
    return out


def eq18_weights(t: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Trapezoidal weights of eq. 18 over sigma_F (t_end - t_0)."""
    w = np.zeros_like(t)
    w[:-1] += 0.5 * np.diff(t)
    w[1:] += 0.5 * np.diff(t)
    return w / (np.std(F) * (t[-1] - t[0]))


def timed_peer(rec, weights, space, rng, calls: int = 8) -> float:
    """Members per second of the peer on ``calls`` fresh populations."""
    pops = [space.to_params(rng.random((POP, space.n))) for _ in range(calls)]
    t0 = time.perf_counter()
    for P in pops:
        peer_objective(P, rec.v, rec.dt, rec.F, weights)
    return calls * POP / (time.perf_counter() - t0)


def timed_ga(model, rec, seeds) -> tuple[float, float, list]:
    """(evaluations per second, members per second: population x generations,
    the fits) of the paper's GA over ``seeds``."""
    fits, evals, members, wall = [], 0, 0, 0.0
    for seed in seeds:
        t0 = time.perf_counter()
        fit = fit_model(model, rec, optimizer="ga", seed=seed)
        wall += time.perf_counter() - t0
        fits.append(fit)
        evals += fit.evaluations
        members += POP * len(fit.history)
    return evals / wall, members / wall, fits


def best_us(run, repeats: int = 200) -> float:
    """The shortest of ``repeats`` calls of ``run()`` [us]."""
    walls = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        run()
        walls.append(time.perf_counter() - t0)
    return 1e6 * min(walls)


def generation_costs(model, rec, space, children: int) -> str:
    """A generation's costs around the kernel: the GA's operators (selection,
    crossover, mutation, the repeated children's reuse) with an objective
    that costs nothing, and eq. 18 on ``children`` new members through
    fit_model's path (unit cube to parameters, the forces, the weighted
    residuals' sum) less the kernel's own time."""
    def free(X):
        return ((X - 0.3) ** 2).sum(axis=1) + 0.01

    gens = 60
    t0 = time.perf_counter()
    for seed in range(20):
        run_ga(free, space.n, np.random.default_rng(seed), GASettings(gens=gens, stall=gens))
    operators = 1e6 * (time.perf_counter() - t0) / (20 * (gens - 1))
    device = as_device(rec)
    layout, weights = Layout(model, tuple(device.test_names)), residual_weights(device)
    X = np.random.default_rng(2).random((children, space.n))
    P = space.to_params(X)
    kernel = best_us(lambda: model.force(rec, P))
    whole = best_us(lambda: joint_objective(model, device, layout, space.to_params(X), weights=weights))
    return (f"a generation around the kernel: the operators {operators:.0f} us; eq. 18 on {children} new children "
            f"{whole - kernel:.0f} us beyond the kernel's {kernel:.0f} us (best of 200)")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=21, help="peer and GA timed in turn this many times")
    ap.add_argument("--runs", type=int, default=2, help="GA runs (seeds) per round")
    args = ap.parse_args()
    rec = simulate(demo_series()[0], paper(), Noise(**DEMO_NOISE), seed=0)
    model = parse_model("9")
    bounds = model.bounds("auto", rec.scales())
    space = Space.of(bounds, model.log_scale("auto"))
    weights = eq18_weights(rec.t, rec.F)
    rng = np.random.default_rng(1)

    check = space.to_params(rng.random((8, space.n)))  # compiles the peer too
    peer = peer_objective(check, rec.v, rec.dt, rec.F, weights)
    ours = np.array([evaluate_params(model, rec, p) for p in check])
    fit_model(model, rec, optimizer="ga", seed=0)  # compiles the project's kernels
    print(f"record: demo device 1, paper protocol, {rec.n} samples; law 9; population {POP}; "
          f"{numba.get_num_threads()} threads; peer OF against fvd_bridge's on 8 members: "
          f"largest relative difference {np.max(np.abs(peer - ours) / ours):.1e}\n")

    peer_rates, ga_rates, member_rates, fits = [], [], [], []
    print(f"{'round':>5} {'peer members/s':>15} {'GA evaluations/s':>17} {'GA members/s':>13} {'peer / GA':>10}")
    for r in range(args.rounds):
        peer_rates.append(timed_peer(rec, weights, space, rng))
        rate, members, some = timed_ga(model, rec, range(r * args.runs, (r + 1) * args.runs))
        fits += some
        ga_rates.append(rate)
        member_rates.append(members)
        print(f"{r + 1:5d} {peer_rates[-1]:15,.0f} {rate:17,.0f} {members:13,.0f} {peer_rates[-1] / rate:10.2f}")
    ratio = float(np.median(np.array(peer_rates) / np.array(ga_rates)))
    print(f"\nmedian: peer {np.median(peer_rates):,.0f} members/s, GA {np.median(ga_rates):,.0f} evaluations/s "
          f"({np.median(member_rates):,.0f} members/s counting the children it reuses); "
          f"peer / GA {ratio:.2f} round by round (target <= 2)")
    of = np.array([f.of for f in fits])
    children = int(round(np.median([(f.evaluations - POP) / max(len(f.history) - 1, 1) for f in fits])))
    print(f"the GA's {len(fits)} runs (seeds 0-{len(fits) - 1}): OF median {np.median(of):.5f}, best {of.min():.5f}; "
          f"{sum(f.evaluations for f in fits):,} evaluations, {children} new children a generation (median)")
    print(generation_costs(model, rec, space, children))


if __name__ == "__main__":
    main()
