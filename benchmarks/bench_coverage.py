"""Coverage of the 95% intervals: bias, width and coverage over noise seeds,
per law and protocol, against lmfit's covariance on the same records.

Each record is made here, not by the rig: the law's force on an exact
motion, force noise 0.8 kN and displacement noise 0.01 mm, written as a
t,d,F file and read back, so the velocity is derived by the tool as for a
lab's file.  Protocols:

- ``ramped``: 40 mm at 500 mm/s, 3 cycles between one-cycle cosine ramps,
  0.5 s at rest before and after, 500 Hz;
- ``levels``: 20 mm at 25, 50, 125, 250 and 500 mm/s (the 5% level at
  a 2 s period), 3 cycles each, 0.2 s pauses, 500 Hz.

Laws 2 (C 40, alpha 0.3) and 9 (its reference parameters,
``fvd_bridge.golden.REFERENCE``).  fvd_bridge: ``fb.calibrate`` (the
default fit, 20 bootstrap replicates of the measurement chain).  The
peer: what a user of lmfit writes, ``lmfit.minimize`` (least squares) on
the residuals of the same model and the same derived velocity, its
covariance's 95% interval (estimate -/+ 1.96 stderr).

    python benchmarks/bench_coverage.py [--seeds 20] [--laws 2,9]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
import warnings

import numpy as np

import fvd_bridge as fb
from fvd_bridge.catalog import catalog
from fvd_bridge.golden import REFERENCE
from fvd_bridge.records import ReadOptions, Record, read_record

TRUTH = {2: np.array([40.0, 0.3]), 9: np.asarray(REFERENCE[9], dtype=float)}
FORCE_NOISE, DISP_NOISE, FS = 0.8, 0.01, 500.0
UNITS = ReadOptions(units={"t": "s", "d": "mm", "F": "kN"})


def ramped():
    """(t, d, v): the ramped single-level motion [s, mm, mm/s]."""
    w = 500.0 / 40.0
    T = 2 * np.pi / w
    t = np.arange(0.0, 5 * T, 1 / FS)
    env = np.clip(np.minimum(t, 5 * T - t) / T, 0.0, 1.0)
    d = 40.0 * 0.5 * (1 - np.cos(np.pi * env)) * np.sin(w * t)
    return _with_rests(t, d, 0.5)


def levels():
    """(t, d, v): five levels, 3 cycles each, tapered, 0.2 s pauses."""
    parts = []
    for vel in (25.0, 50.0, 125.0, 250.0, 500.0):
        amp = min(20.0, vel * 2.0 / (2 * np.pi))
        w = vel / amp
        T = 2 * np.pi / w
        t = np.arange(0.0, 3 * T, 1 / FS)
        env = np.clip(np.minimum(t, 3 * T - t) / (0.5 * T), 0.0, 1.0)
        parts += [amp * 0.5 * (1 - np.cos(np.pi * env)) * np.sin(w * t), np.zeros(int(0.2 * FS))]
    d = np.concatenate(parts)
    return _with_rests(np.arange(d.size) / FS, d, 0.3)


def _with_rests(t, d, rest):
    still = int(rest * FS)
    d = np.concatenate([np.zeros(still), d, np.zeros(still)])
    t = np.arange(d.size) / FS
    v = np.gradient(d, t, edge_order=2)
    return t, d, v


def lab_file(path, law, motion, seed):
    """Write the law's noisy t,d,F record to ``path`` and read it back."""
    t, d, v = motion
    a = np.gradient(v, t, edge_order=2)
    model = catalog().model(str(law))
    F = model.force(Record(t, d, np.zeros_like(t), v, a), TRUTH[law][None, :])[0]
    rng = np.random.default_rng(1000 + seed)
    np.savetxt(path, np.column_stack([t, d + DISP_NOISE * rng.standard_normal(t.size),
                                      F + FORCE_NOISE * rng.standard_normal(t.size)]),
               delimiter=",", header="t,d,F", comments="", fmt=("%.4f", "%.5f", "%.4f"))
    return read_record(path, UNITS)


def lmfit_interval(model, rec, start):
    """lmfit's least-squares estimate and covariance interval (n, 2), or None."""
    import lmfit

    params = lmfit.Parameters()
    for name, x in zip(model.names, start):
        params.add(name, value=float(x), min=0.0)

    def residual(p):
        P = np.array([[p[n].value for n in model.names]])
        return model.force(rec, P)[0] - rec.F

    out = lmfit.minimize(residual, params, method="least_squares")
    est = np.array([out.params[n].value for n in model.names])
    err = np.array([out.params[n].stderr or np.nan for n in model.names])
    return est, np.column_stack([est - 1.96 * err, est + 1.96 * err])


def study(law, protocol, seeds, folder):
    model = catalog().model(str(law))
    truth = TRUTH[law]
    motion = {"ramped": ramped, "levels": levels}[protocol]()
    rows, peer, times = [], [], []
    for s in seeds:
        rec = lab_file(os.path.join(folder, f"law{law}_{protocol}_{s}.csv"), law, motion, s)
        t0 = time.perf_counter()
        cal = fb.calibrate(rec, str(law), seed=s)
        t1 = time.perf_counter()
        fb.calibrate(rec, str(law), seed=s, intervals=0)  # the fit alone, the same record
        times.append((t1 - t0, time.perf_counter() - t1))
        ci = np.array([cal.intervals.parameters[n].ci95 for n in model.names])
        se = np.array([cal.intervals.parameters[n].stderr for n in model.names])
        rows.append((cal.values, ci, se))
        try:
            peer.append(lmfit_interval(model, rec, truth * 1.1))
        except ImportError:
            pass
    return model, truth, rows, peer, times


def summary(model, truth, rows, peer):
    est = np.array([r[0] for r in rows])
    ci = np.array([r[1] for r in rows])
    se = np.array([r[2] for r in rows])
    cover = ((ci[:, :, 0] <= truth) & (truth <= ci[:, :, 1])).sum(axis=0)
    inside = ((ci[:, :, 0] < est) & (est < ci[:, :, 1])).all(axis=0)
    out = []
    for j, name in enumerate(model.names):
        line = (f"  {name:8s} bias {np.mean(est[:, j] / truth[j] - 1):+.3%} "
                f"({np.mean((est[:, j] - truth[j]) / se[:, j]):+.2f} stderr)  "
                f"width {np.median((ci[:, j, 1] - ci[:, j, 0]) / truth[j]):.2%}  "
                f"cover {cover[j]}/{len(rows)}  inside {'yes' if inside[j] else 'NO'}")
        if peer:
            pe = np.array([p[0] for p in peer])
            pc = np.array([p[1] for p in peer])
            pcov = int(((pc[:, j, 0] <= truth[j]) & (truth[j] <= pc[:, j, 1])).sum())
            line += (f"   | lmfit bias {np.mean(pe[:, j] / truth[j] - 1):+.3%} "
                     f"width {np.nanmedian((pc[:, j, 1] - pc[:, j, 0]) / truth[j]):.2%} cover {pcov}/{len(peer)}")
        out.append(line)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--laws", default="2,9")
    ap.add_argument("--protocols", default="ramped,levels")
    args = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    with tempfile.TemporaryDirectory() as folder:
        for law in (int(x) for x in args.laws.split(",")):
            for protocol in args.protocols.split(","):
                model, truth, rows, peer, times = study(law, protocol, range(args.seeds), folder)
                with_iv, alone = np.median(np.array(times), axis=0)
                print(f"law {law}, {protocol}: {args.seeds} seeds, calibrate with intervals "
                      f"{with_iv * 1e3:.0f} ms a record, the fit alone {alone * 1e3:.0f} ms "
                      f"({with_iv / alone:.1f}x, medians)", flush=True)
                print("\n".join(summary(model, truth, rows, peer)), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
