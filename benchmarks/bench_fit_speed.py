"""One fit's wall time against a least-squares peer on the same record.

Lab-like records (t,d,F written and read back, velocity derived by the
tool), the paper protocol (40 mm at 500 mm/s, dt 0.002 s), 1 kN force and
0.005 mm displacement noise: a law-2 device (fitted with law 2), a law-9
device (law 9), and a law-2 device with a 150 kN/mm oil column that
neither law describes (both laws; a calibration searches wider there).
Best of 3 in one process:

- fvd_bridge's default fit ``local`` (least squares on eq. 18 from the
  law's data-driven starts and a Sobol sample's), ``local+de`` (the same,
  then a DE check) and ``de`` (DE and its Nelder-Mead polish, the default
  up to version 0.2.0), and ``fb.calibrate(rec, law, runs=1,
  intervals=0)``: the default fit with what a calibration adds around it
  (the request's checks, the noise floor it is judged by, the Calibration);
- the peer: scipy ``least_squares`` (the solver lmfit's ``least_squares``
  method calls) on the plain residuals F_model - F, the law written in
  plain numpy as its users write it (``plain_force``; not the project's
  kernel), from a data-driven start
  (law 2: a log-log regression of |F| on |v| over the fastest half of the
  samples; law 9: C from the force's slope against v at speed, beta from
  the force at the velocity reversals, alpha 1/(0.1 x stroke)).

Also, when lmfit is installed (``pip install lmfit``), lmfit's
``minimize(method='least_squares')`` on the same residuals from the same
start: it calls the same scipy solver through its Parameters.  Prints OF
(eq. 18) beside time, and the ratios to the scipy peer.

    python benchmarks/bench_fit_speed.py [--repeats 3] [--pairs 40]

The issue's figure, fb.calibrate against lmfit on the law-2 device, is
also measured head to head (``--pairs``, 40 by default): the two calls
alternate, so that both meet the same state of the machine (a best-of
taken in two blocks a second apart moved the ratio between 1.4x and 4x on
one machine), and the median of the per-pair ratios is printed with its
quartiles and the parameter sets each evaluates.

``--record FILE`` times the same fits on a lab file instead (read as
``fvd-bridge`` reads it), e.g. the shared friction damper's 0.5 Hz test
(18k samples), where a solver's work per sample shows.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import tempfile
import time
import warnings

import numpy as np
from scipy.optimize import least_squares

import fvd_bridge as fb
from fvd_bridge.catalog import parse_model
from fvd_bridge.fit import DEFAULT_OPTIMIZER, fit_model, objective
from fvd_bridge.records import read_record
from fvd_bridge.records.writers import write_csv
from fvd_bridge.rig import VirtualDamper, Noise, paper, simulate
from fvd_bridge.rig.model_device import simulate_model


def lab_file(rec):
    """``rec`` written as a lab's t,d,F file and read back (velocity derived by the tool)."""
    folder = tempfile.mkdtemp(prefix="fvd_bench_")
    path = os.path.join(folder, f"{rec.name}.csv")
    write_csv(rec, path)
    return read_record(path)


def lab_records() -> list:
    """(what, record, laws): a device each law describes (its fit ends at the
    noise floor), then the law-2 device with a 150 kN/mm oil column, which
    neither law describes (the calibration's wider search runs)."""
    law9 = simulate_model(parse_model("9"), [0.2, 0.15, 27.0], paper(), Noise(1.0, 0.005), seed=0, name="law9")
    return [("law-2 device", lab_file(simulate(VirtualDamper(C=45.0, alpha=0.3, name="sn045"), paper(),
                                              Noise(1.0, 0.005), seed=0)), ("2",)),
            ("law-9 device", lab_file(law9), ("9",)),
            ("law 2 + 150 kN/mm oil column",
             lab_file(simulate(VirtualDamper(C=45.0, alpha=0.3, Ks=150.0, name="sn150"), paper(),
                               Noise(1.0, 0.005), seed=0)), ("2", "9"))]


def start_of(law: str, rec) -> np.ndarray:
    """The peer's data-driven start (module docstring)."""
    v, F = np.abs(rec.v), np.abs(rec.F)
    fast = v > np.median(v)
    if law == "2":
        slope, icept = np.polyfit(np.log(v[fast]), np.log(np.maximum(F[fast], 1e-6)), 1)
        return np.array([np.exp(icept), slope])
    C = np.polyfit(rec.v[fast], rec.F[fast], 1)[0]
    slow = v < 0.05 * v.max()
    beta = float(np.median(F[slow])) if slow.any() else 0.5 * F.max()
    return np.array([C, 1.0 / (0.1 * np.ptp(rec.d) / 2), beta])


def plain_force(law: str, p: np.ndarray, rec) -> np.ndarray:
    """The law's force [kN] as its users write it in plain numpy, not the
    project's kernel: law 2 C sign(v)|v|^alpha; law 9 F = beta z + C v with
    dz/dt = v - alpha |v| z stepped sample by sample in a Python loop (the
    exact step for v constant over the sample: z relaxes towards
    sign(v)/alpha at the rate alpha |v|)."""
    v = rec.v
    if law == "2":
        C, alpha = p
        return C * np.sign(v) * np.abs(v) ** alpha
    C, alpha, beta = p
    decay = np.exp(-alpha * np.abs(v) * rec.dt)
    target = np.sign(v) / alpha
    z = np.empty(rec.n)
    zk = 0.0
    for k in range(rec.n):
        zk = target[k] + (zk - target[k]) * decay[k]
        z[k] = zk
    return beta * z + C * v


def peer_fit(model, rec, x0, bounds):
    law = model.spec

    def residuals(p):
        return plain_force(law, p, rec) - rec.F
    res = least_squares(residuals, np.clip(x0, bounds[:, 0], bounds[:, 1]), bounds=(bounds[:, 0], bounds[:, 1]),
                        method="trf", x_scale="jac")
    return res.x, float(objective(rec.F, model.force(rec, res.x[None, :])[0], rec.t))


def lmfit_fit(model, rec, x0, bounds):
    """(parameters, OF) of lmfit's ``minimize(method='least_squares')`` (the
    issue's peer) on the same residuals from the same start."""
    out = lmfit_minimize(model, rec, x0, bounds)
    x = np.array([out.params[n].value for n in model.names])
    return x, float(objective(rec.F, model.force(rec, x[None, :])[0], rec.t))


def lmfit_minimize(model, rec, x0, bounds, calls: list | None = None):
    """lmfit's fit itself (its MinimizerResult; ``calls``: a one-item list its
    residual calls are counted in)."""
    import lmfit

    params = lmfit.Parameters()
    for name, x, (lo, hi) in zip(model.names, np.clip(x0, bounds[:, 0], bounds[:, 1]), bounds):
        params.add(name, value=float(x), min=float(lo), max=float(hi))

    def residuals(p):
        if calls is not None:
            calls[0] += 1
        return plain_force(model.spec, np.array([p[n].value for n in model.names]), rec) - rec.F
    return lmfit.minimize(residuals, params, method="least_squares")


def head_to_head(rec, law: str, pairs: int) -> str:
    """fb.calibrate(runs=1, intervals=0) against lmfit, the calls alternating
    ``pairs`` times: the median per-pair time ratio, its quartiles, and the
    parameter sets each evaluates (lmfit's residual calls, counted)."""
    model = parse_model(law)
    bounds = np.array(model.bounds("auto", rec.scales()), dtype=float)
    sets = [0]
    ratios, ours, peer = [], [], []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for k in range(pairs + 3):  # the first three warm both up
            t0 = time.perf_counter()
            lmfit_minimize(model, rec, start_of(law, rec), bounds, sets)
            t1 = time.perf_counter()
            cal = fb.calibrate(rec, law, runs=1, intervals=0)
            t2 = time.perf_counter()
            if k >= 3:
                peer.append(t1 - t0)
                ours.append(t2 - t1)
                ratios.append((t2 - t1) / (t1 - t0))
    q1, med, q3 = np.percentile(ratios, [25, 50, 75])
    lmfit_sets = sets[0] // (pairs + 3)
    return (f"     head to head, {pairs} alternating pairs: fb.calibrate {1e3 * np.median(ours):.1f} ms, lmfit "
            f"{1e3 * np.median(peer):.1f} ms (medians); the ratio {med:.2f}x (quartiles {q1:.2f}-{q3:.2f}x), "
            f"OF {cal.of:.5f}; parameter sets: {cal.solver.evaluations} against lmfit's {lmfit_sets}")


def overhead(model, rec, wall: float, fit) -> str:
    """Where the default fit's time goes: its parameter sets through the
    kernel (timed in batches of n + 1, as its Jacobians run) and the rest
    (the solver's and the package's Python per call)."""
    n = len(model.names)
    P = np.repeat(np.asarray(fit.values, dtype=float)[None, :], n + 1, axis=0)
    per_set, _ = best_of(5, lambda: model.force(rec, P))
    kernel = fit.evaluations * per_set / (n + 1)
    return (f"     default fit: {fit.evaluations} parameter sets, {1e3 * kernel:.1f} ms in the kernel "
            f"({1e6 * per_set / (n + 1):.0f} us a set in batches of {n + 1}); the rest, "
            f"{1e3 * max(wall - kernel, 0.0):.1f} ms, is the solver's and the package's Python")


def best_of(repeats, run):
    walls, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = run()
        walls.append(time.perf_counter() - t0)
    return min(walls), out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--record", help="a lab file to fit instead of the simulated records")
    ap.add_argument("--pairs", type=int, default=40,
                    help="alternating fb.calibrate/lmfit pairs on the law-2 device (0: none; needs lmfit)")
    args = ap.parse_args()
    cases = [("a lab file", read_record(args.record), ("2", "9"))] if args.record else lab_records()
    for what, rec, laws in cases:
        print(f"record: {rec.name}, {rec.n} samples ({what}); best of {args.repeats}\n")
        print(f"{'law':>4} {'fit':>34} {'wall [ms]':>10} {'OF':>9} {'x peer time':>12}")
        for law in laws:
            time_law(law, rec, args.repeats)
            if what == "law-2 device" and args.pairs and importlib.util.find_spec("lmfit") is not None:
                print(head_to_head(rec, law, args.pairs) + "\n")


def time_law(law: str, rec, repeats: int) -> None:
    """One law's fits on ``rec``: the peers, the optimizers, fb.calibrate."""
    model = parse_model(law)
    bounds = np.array(model.bounds("auto", rec.scales()), dtype=float)
    model.force(rec, bounds.mean(axis=1)[None, :])  # compile first
    peer_wall, (_, peer_of) = best_of(repeats, lambda: peer_fit(model, rec, start_of(law, rec), bounds))
    rows = [("scipy least_squares (peer)", peer_wall, peer_of)]
    lmfit_row = None
    if importlib.util.find_spec("lmfit") is not None:
        wall, (_, of) = best_of(repeats, lambda: lmfit_fit(model, rec, start_of(law, rec), bounds))
        lmfit_row = ("lmfit least_squares", wall, of)
        rows.append(lmfit_row)
    for opt in ("de", "local+de", DEFAULT_OPTIMIZER):
        fit_wall, fit = best_of(repeats, lambda: fit_model(model, rec, optimizer=opt, seed=0))
        rows.append((f"fvd_bridge {opt}{' (default)' if opt == DEFAULT_OPTIMIZER else ''}", fit_wall, fit.of))
    with warnings.catch_warnings():  # a calibration's FitWarnings are its own matter here
        warnings.simplefilter("ignore")
        cal_wall, cal = best_of(repeats, lambda: fb.calibrate(rec, law, runs=1, intervals=0))
    rows.append(("fb.calibrate(runs=1, intervals=0)", cal_wall, cal.of))
    for name, wall, of in rows:
        print(f"{law:>4} {name:>34} {1e3 * wall:10.1f} {of:9.5f} {wall / peer_wall:12.1f}")
    print(overhead(model, rec, fit_wall, fit))
    if lmfit_row is not None:
        wider = cal.settings.get("wider_runs", 0)
        print(f"     fb.calibrate / lmfit: {cal_wall / lmfit_row[1]:.2f}x the time, OF {cal.of:.5f} vs "
              f"{lmfit_row[2]:.5f}" + (f" ({wider} wider search rounds: far above the noise floor)" if wider else ""))
    print()


if __name__ == "__main__":
    main()
