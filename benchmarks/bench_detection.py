"""Detection power of ``diagnose``: how often it finds an effect of known size,
against an oracle that knows the true model, and how often it suggests an
effect on a device that has none (issue 31, "Power measured, then set").

Devices: the rig's law-2 orifice (C 40 kN/(mm/s)^alpha, alpha 0.3; about
258 kN at 500 mm/s) with ONE planted effect, its size swept log-spaced from
invisible to obvious (``SWEEPS``: the rig parameter, its range, its unit),
and effect-free devices (size 0):

=================== ============ ================= ==============================
effect (diagnose)   rig          range             "share" on the figure
=================== ============ ================= ==============================
friction            friction Ff  0.97-31 kN        Ff / peak force (0.375-12%)
series_stiffness    Ks           10,000-50 kN/mm   spring deflection at the peak
                                                   force / stroke amplitude
gap                 gap g        0.01-2.5 mm       g / stroke amplitude
asymmetry           asymmetry r  0.001-0.1         largest force change / peak
parallel_stiffness  Kp           0.005-1 kN/mm     largest force change / peak
                                                   (Kp only, no preload)
inertia             mass m       20-5,000 kg       largest force change / peak
thermal_softening   heating      0.005-1 /MJ       largest force change / peak
=================== ============ ================= ==============================

"Largest force change" is max |F_with - F_without| on the exact (noise-free)
record under the same protocol, as a share of max |F_without|; for a
series spring or a gap that number reflects the steep law-2 force near a
reversal more than what a fit can see, so their share is a length.  For law
2 alone, an oil column and a connection spring are the same model
(diagnose refits only ``series_stiffness``); ``oil_column`` counts as
finding it.

Records: the rig's exact t, d, F (``fvd_bridge.rig.simulate`` without noise,
once per device and protocol), then per seed force noise 0.8 kN and
displacement noise 0.01 mm (numpy default_rng(seed), force first, as the
rig draws them), written as a t,d,F CSV with its unit sidecar and read back
by ``fvd_bridge.records.read_record``: the velocity is derived by the tool
from the noisy displacement, as for a lab's file (the logic of
``tests/lab.py``'s ``lab_record``).  Protocols: ``paper`` (the rig's
``paper()``: 10 cycles of 40 mm at 500 mm/s, one level, about 2,900
samples) and ``acceptance`` (the rig's ``acceptance()``: 3 cycles at 5,
125, 250, 375 and 500 mm/s, about 8,700 samples).

Per (effect, size, protocol, seed): ``diagnose(record, "2", seed=seed)``
with its defaults.  Detected: ``diag.best`` is the planted effect.  False
suggestion: ``diag.best`` is another effect (on an effect-free device: any
effect).  The oracle knows which effect is there and takes diagnose's own
refit of it: the likelihood ratio of that model against the base with
Laplace errors (whose maximum likelihood is set by the mean absolute
residual, so by the OF),

    LR = 2 N_eff ln(OF_base / OF_true),  N_eff = the candidate's (rank.py:
         N (1 - rho) / (1 + rho), rho the lag-1 autocorrelation of its residual),

detects when LR > chi2.ppf(0.95, dk), dk the effect's number of
parameters.  On effect-free devices the same test of each effect gives the
oracle's false-alarm rate.  Every row saved to ``--json`` keeps the base OF,
the floor and its force-only part, the margin, and each candidate's OF,
improvement, N_eff, dBIC, OF with the effect switched off, size verdict,
held-out gains, reason and fitted parameters, so that another acceptance
rule can be evaluated from the file without rerunning.

    python benchmarks/bench_detection.py [--effects friction,gap,...] [--seeds 10]
        [--sizes 6] [--protocols paper,acceptance] [--json benchmarks/detection.json]
        [--figure docs/img/detection.png]
    python benchmarks/bench_detection.py --load a.json,b.json   # table and figure from saved rows

One diagnosis takes 2-3 s (paper) and 4-5 s (acceptance) on a 2-core
machine: the friction sweep with 10 seeds (6 sizes and 0, two protocols,
140 diagnoses) 12-14 minutes on a shared machine; every effect with
``--seeds 3 --sizes 4`` (174 diagnoses) about 15.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tempfile
import time
import warnings
from dataclasses import dataclass

import numpy as np
from scipy.stats import chi2

from fvd_bridge.diagnose import diagnose
from fvd_bridge.records import Record, RecordWarning, read_record
from fvd_bridge.records.writers import write_csv
from fvd_bridge.rig import VirtualDamper, acceptance, paper, simulate

#: the device every effect is planted in: law 2, C [kN/(mm/s)^alpha], alpha [-]
C, ALPHA = 40.0, 0.3
#: its orifice force at 500 mm/s [kN]: the "peak force" sizes are quoted against
PEAK_KN = C * 500.0 ** ALPHA
#: lab-like noise: force [kN], displacement [mm]
FORCE_NOISE, DISP_NOISE = 0.8, 0.01
#: the oracle's test level
LEVEL = 0.95
PROTOCOLS = {"paper": paper, "acceptance": acceptance}
#: the other arrangement of an effect that counts as finding it (the same model for law 2 alone)
SAME = {"series_stiffness": {"oil_column"}}


@dataclass(frozen=True)
class Sweep:
    """One effect's sweep: the rig parameter ``key`` from ``lo`` to ``hi``
    (log-spaced, in ``unit``); ``share``: 'force' (largest force change /
    peak force), 'friction' (Ff / PEAK_KN), 'deflection' (PEAK_KN / Ks /
    stroke amplitude) or 'length' (the value / stroke amplitude)."""

    key: str
    lo: float
    hi: float
    unit: str
    share: str

    def sizes(self, k: int) -> list[float]:
        return [float(x) for x in np.geomspace(self.lo, self.hi, k)] if k > 1 else [float(self.hi)]


#: diagnose's effect name -> its sweep (ranges chosen from invisible to obvious at 0.8 kN / 0.01 mm noise)
SWEEPS = {
    "friction": Sweep("friction", 0.00375 * PEAK_KN, 0.12 * PEAK_KN, "kN", "friction"),  # x2 steps at 6 sizes: 3% in it
    "series_stiffness": Sweep("Ks", 10000.0, 50.0, "kN/mm", "deflection"),
    "gap": Sweep("gap", 0.01, 2.5, "mm", "length"),
    "asymmetry": Sweep("asymmetry", 0.001, 0.1, "-", "force"),
    "parallel_stiffness": Sweep("Kp", 0.005, 1.0, "kN/mm", "force"),
    "inertia": Sweep("mass", 20.0, 5000.0, "kg", "force"),
    "thermal_softening": Sweep("heating", 0.005, 1.0, "1/MJ", "force"),
}
#: names a user may type for --effects
ALIASES = {"heating": "thermal_softening", "accumulator": "parallel_stiffness", "mass": "inertia",
           "series": "series_stiffness", "spring": "series_stiffness", "oil_column": "series_stiffness",
           "Ks": "series_stiffness", "seal": "friction"}
FREE = "none"  # the effect name of the effect-free rows


def exact_record(effect: str, value: float, protocol: str) -> dict:
    """The rig's noise-free t [s], d [mm], F [kN] of the device with ``effect``
    at ``value`` (FREE: no effect) under ``protocol``."""
    kw = {} if effect == FREE else {SWEEPS[effect].key: value}
    rec = simulate(VirtualDamper(C=C, alpha=ALPHA, **kw), PROTOCOLS[protocol](), None, name="exact")
    return {"t": rec.t, "d": rec.d, "F": rec.F}


def share(effect: str, value: float, exact: dict, free: dict) -> float:
    """The size as a share (see ``Sweep``) on this protocol's exact records."""
    kind = SWEEPS[effect].share
    stroke = float(np.max(np.abs(free["d"])))
    if kind == "friction":
        return value / PEAK_KN
    if kind == "deflection":
        return PEAK_KN / value / stroke
    if kind == "length":
        return value / stroke
    return float(np.max(np.abs(exact["F"] - free["F"])) / np.max(np.abs(free["F"])))


def lab_record(exact: dict, seed: int, folder: str, name: str) -> tuple[Record, list[str]]:
    """Noise added to ``exact`` (force first, then displacement, from
    default_rng(seed)), written as FOLDER/NAME.csv with its unit sidecar and
    read back (the velocity derived by the tool); also the reader's warnings."""
    rng = np.random.default_rng(seed)
    F = exact["F"] + FORCE_NOISE * rng.standard_normal(exact["F"].size)
    d = exact["d"] + DISP_NOISE * rng.standard_normal(exact["d"].size)
    path = os.path.join(folder, f"{name}.csv")
    zero = np.zeros_like(exact["t"])
    write_csv(Record(exact["t"], d, F, zero, zero, name=name), path,
              comment=f"lab-like record {name}: noise {FORCE_NOISE:g} kN / {DISP_NOISE:g} mm, seed {seed}")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RecordWarning)
        rec = read_record(path, name=name)
    return rec, [str(w.message) for w in caught if issubclass(w.category, RecordWarning)]


def _plain(x):
    """JSON-ready copy of held-out dicts and the like (numpy to float/list)."""
    if isinstance(x, dict):
        return {str(k): _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, np.ndarray):
        return _plain(x.tolist())
    if isinstance(x, (np.bool_, bool)):
        return bool(x)
    if isinstance(x, (np.integer, int)):
        return int(x)
    if isinstance(x, (np.floating, float)):
        return float(x)
    return x if x is None or isinstance(x, str) else str(x)


def oracle(c, of_base: float, dk: int) -> dict:
    """The oracle's likelihood-ratio test of candidate ``c`` against the base."""
    lr = 2.0 * c.n_eff * math.log(max(of_base, 1e-300) / max(c.of, 1e-300))
    crit = float(chi2.ppf(LEVEL, dk))
    return {"lr": lr, "crit": crit, "detects": bool(lr > crit)}


def run_one(rec: Record, effect: str, seed: int) -> dict:
    """diagnose ``rec`` with law 2; what the study keeps of it (module doc)."""
    t0 = time.perf_counter()
    diag = diagnose(rec, "2", seed=seed)
    wall = time.perf_counter() - t0
    k_base = len(diag.model.parameters)
    cands = []
    for c in diag.candidates:
        dk = len(c.model.parameters) - k_base
        held = c.held_out or {}
        cands.append({
            "effect": c.effect, "replaces": c.replaces, "of": float(c.of), "improvement": float(c.improvement),
            "n_eff": float(c.n_eff), "delta_bic": float(c.delta_bic), "dk": dk, "of_effect_off": float(c.off_of),
            "significant": bool(c.significant), "reason": c.reason,
            "size": c.size.text if c.size else "", "detectable": bool(c.size.detectable) if c.size else True,
            "plausible": bool(c.size.plausible) if c.size else True,
            "held_out": _plain({k: held[k] for k in ("gain", "passes", "worse") if k in held}) if held else None,
            "on_cap": list(c.on_cap),
            "params": {n: float(v) for n, v in zip(c.fit.names, c.fit.values)},
            "oracle": oracle(c, diag.of, dk)})
    best = diag.best.effect if diag.best is not None else None
    names = {effect} | SAME.get(effect, set())
    planted = next((c for c in cands if c["effect"] in names and not c["replaces"]), None)
    return {
        "of_base": diag.of, "floor": diag.floor, "force_floor": float(diag.noise.force_floor),
        "margin": float(diag.judge.margin), "band": float(getattr(diag.judge, "band", math.nan)),
        "n": int(diag.judge.n), "at_floor": bool(diag.at_floor),
        "base_params": diag.named(), "noise": _plain(diag.noise.as_dict()),
        "best": best, "ranked_first": cands[0]["effect"] if cands else None,
        "detected": effect != FREE and best in names,
        "false": best is not None and best not in names,
        "planted": planted, "oracle": None if planted is None else planted["oracle"]["detects"],
        "candidates": cands, "verdict": diag.verdict(), "wall_s": wall}


def size_label(effect: str, value: float, shr: float) -> str:
    if effect == FREE:
        return "0 (effect-free)"
    sw = SWEEPS[effect]
    what = {"friction": "of peak force", "force": "of peak force", "deflection": "deflection/stroke",
            "length": "of stroke"}[sw.share]
    return f"{value:.4g} {sw.unit} ({100 * shr:.3g}% {what})"


def provenance() -> dict:
    """Which fvd_bridge ran: its path and, in a git work tree, the commit and
    the files under fvd_bridge/ that differ from it."""
    import subprocess

    import fvd_bridge

    where = os.path.dirname(os.path.dirname(os.path.abspath(fvd_bridge.__file__)))
    out = {"path": where, "commit": None, "modified": None}
    try:
        git = ["git", "-C", where]
        out["commit"] = subprocess.run(git + ["rev-parse", "HEAD"], capture_output=True, text=True,
                                       check=True).stdout.strip()
        status = subprocess.run(git + ["status", "--porcelain", "--", "fvd_bridge"], capture_output=True,
                                text=True, check=True).stdout
        out["modified"] = [line[3:] for line in status.splitlines()]
    except (OSError, subprocess.CalledProcessError):
        pass
    return out


def parse_list(text: str, known, aliases=None) -> list[str]:
    out = []
    for name in (s.strip() for s in text.split(",") if s.strip()):
        name = (aliases or {}).get(name, name)
        if name not in known:
            sys.exit(f"bench_detection: unknown name '{name}' (known: {', '.join(known)})")
        if name not in out:
            out.append(name)
    return out


def save(path: str, meta: dict, rows: list) -> None:
    if not path:
        return
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    tmp = path + ".tmp"
    with open(tmp, "w") as fh:
        json.dump({"schema_version": 1, **meta, "rows": rows}, fh, indent=1, allow_nan=True)
    os.replace(tmp, path)


def groups(rows: list) -> dict:
    """{(effect, protocol, size index): [rows]} in the order met."""
    out: dict = {}
    for r in rows:
        out.setdefault((r["effect"], r["protocol"], r["size_index"]), []).append(r)
    return out


def table(rows: list) -> str:
    """The printed summary: per effect, protocol and size, diagnose's and the
    oracle's detection counts and false suggestions; then the effect-free rows."""
    lines = [f"{'effect':<19s}{'protocol':<11s}{'size':<42s}{'diagnose':>9s}{'oracle':>8s}{'false':>7s}"]
    free = []
    for (effect, protocol, _), rs in groups(rows).items():
        n = len(rs)
        if effect == FREE:
            free.append((protocol, rs))
            continue
        det = sum(r["detected"] for r in rs)
        orc = sum(bool(r["oracle"]) for r in rs)
        fal = sum(r["false"] for r in rs)
        lines.append(f"{effect:<19s}{protocol:<11s}{rs[0]['size_label']:<42s}{f'{det}/{n}':>9s}"
                     f"{f'{orc}/{n}':>8s}{f'{fal}/{n}':>7s}")
    if free:
        lines.append("")
        lines.append("effect-free devices (size 0): false suggestions of diagnose, and the oracle's false "
                     f"alarms (LR > chi2 {LEVEL:.0%}) per effect tested")
        total = sum(len(rs) for _, rs in free)
        for protocol, rs in free:
            fal = [r["best"] for r in rs if r["best"]]
            alarms = {}
            for r in rs:
                for c in r["candidates"]:
                    if not c["replaces"]:
                        alarms.setdefault(c["effect"], 0)
                        alarms[c["effect"]] += c["oracle"]["detects"]
            lines.append(f"  {protocol:<11s} false suggestions {len(fal)}/{len(rs)}"
                         + (f" ({', '.join(fal)})" if fal else "")
                         + "; oracle: " + ", ".join(f"{k} {v}/{len(rs)}" for k, v in alarms.items()))
        lines.append(f"  all protocols: {sum(bool(r['best']) for _, rs in free for r in rs)}/{total} false suggestions")
    return "\n".join(lines)


def figure(rows: list, path: str) -> None:
    """Detection rate against size (as a share, log axis), diagnose solid and
    oracle dashed, one panel per protocol."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    protocols = [p for p in PROTOCOLS if any(r["protocol"] == p for r in rows)]
    effects = [e for e in SWEEPS if any(r["effect"] == e for r in rows)]
    if not protocols or not effects:
        return
    colors = dict(zip(SWEEPS, plt.rcParams["axes.prop_cycle"].by_key()["color"]))
    fig, axes = plt.subplots(1, len(protocols), figsize=(5.2 * len(protocols), 4.2), sharey=True, squeeze=False)
    g = groups(rows)
    lengths = any(SWEEPS[e].share in ("deflection", "length") for e in effects)
    xlabel = ("effect size, % (forces: of the peak force;\nspring deflection and gap: of the stroke)" if lengths
              else "effect size, % of the peak force")
    for ax, protocol in zip(axes[0], protocols):
        for effect in effects:
            keys = sorted(k for k in g if k[0] == effect and k[1] == protocol)
            if not keys:
                continue
            x = [100 * g[k][0]["share"] for k in keys]
            det = [np.mean([r["detected"] for r in g[k]]) for k in keys]
            orc = [np.mean([bool(r["oracle"]) for r in g[k]]) for k in keys]
            n = len(g[keys[0]])
            ax.plot(x, det, "-o", color=colors[effect], ms=4, label=f"{effect} ({n} seeds)")
            ax.plot(x, orc, "--", color=colors[effect], lw=1.2)
        free = [r for k, rs in g.items() if k[0] == FREE and k[1] == protocol for r in rs]
        note = (f"effect-free: {sum(bool(r['best']) for r in free)}/{len(free)} false suggestions"
                if free else "")
        ax.set_xscale("log")
        ax.set_ylim(-0.03, 1.03)
        ax.axhline(0.9, color="0.8", lw=0.8, zorder=0)
        ax.set_title(f"{protocol} protocol\n{note}", fontsize=10)
        ax.set_xlabel(xlabel)
        ax.grid(True, which="major", alpha=0.3)
    axes[0][0].set_ylabel("detection rate")
    axes[0][0].plot([], [], "k-", label="diagnose (recommended)")
    axes[0][0].plot([], [], "k--", label=f"oracle (LR test, {LEVEL:.0%})")
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, fontsize=8, loc="lower center", ncol=min(len(labels), 5), frameon=False)
    fig.suptitle(f"diagnose's detection power: law 2 (C {C:g}, alpha {ALPHA:g}) + one effect,\n"
                 f"lab-like records (noise {FORCE_NOISE:g} kN / {DISP_NOISE:g} mm, velocity derived)", fontsize=10)
    fig.tight_layout(rect=(0, 0.05 + 0.045 * math.ceil(len(labels) / 5), 1, 1))
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--effects", default=",".join(SWEEPS), help=f"comma list of {', '.join(SWEEPS)}")
    ap.add_argument("--seeds", type=int, default=10, help="noise seeds per device and protocol (default 10)")
    ap.add_argument("--sizes", type=int, default=6, help="sizes per effect, log-spaced (default 6), plus size 0")
    ap.add_argument("--protocols", default="paper,acceptance", help="comma list of paper, acceptance")
    ap.add_argument("--json", default="benchmarks/detection.json", help="raw rows (default benchmarks/detection.json)")
    ap.add_argument("--figure", default="docs/img/detection.png", help="'' for none (default docs/img/detection.png)")
    ap.add_argument("--load", default="", help="comma list of saved JSON files: table and figure from their rows")
    args = ap.parse_args()

    if args.load:
        rows = []
        for p in args.load.split(","):
            with open(p) as fh:
                rows += json.load(fh)["rows"]
        print(table(rows))
        if args.figure:
            figure(rows, args.figure)
            print(f"figure: {args.figure}")
        return

    effects = parse_list(args.effects, SWEEPS, ALIASES)
    protocols = parse_list(args.protocols, PROTOCOLS)
    if args.seeds < 1 or args.sizes < 1:
        sys.exit("bench_detection: --seeds and --sizes must be at least 1")
    meta = {"fvd_bridge": provenance(), "device": {"law": 2, "C": C, "alpha": ALPHA, "peak_kN": PEAK_KN},
            "noise": {"force_kN": FORCE_NOISE, "displacement_mm": DISP_NOISE}, "level": LEVEL,
            "seeds": args.seeds, "sizes": args.sizes, "protocols": protocols,
            "sweeps": {e: vars(SWEEPS[e]) | {"values": SWEEPS[e].sizes(args.sizes)} for e in effects}}
    plan = [(FREE, 0, 0.0)] + [(e, i + 1, v) for e in effects for i, v in enumerate(SWEEPS[e].sizes(args.sizes))]
    where = meta["fvd_bridge"]
    print(f"fvd_bridge from {where['path']}" + (f" at {where['commit'][:7]}" if where["commit"] else "")
          + (f", modified: {', '.join(where['modified'])}" if where["modified"] else ""), flush=True)
    print(f"bench_detection: {len(plan)} devices x {len(protocols)} protocols x {args.seeds} seeds "
          f"= {len(plan) * len(protocols) * args.seeds} diagnoses", flush=True)
    rows: list = []
    t_all = time.perf_counter()
    free_exact = {p: exact_record(FREE, 0.0, p) for p in protocols}
    with tempfile.TemporaryDirectory(prefix="bench_detection_") as folder:
        for effect, k, value in plan:
            for protocol in protocols:
                t0 = time.perf_counter()
                exact = free_exact[protocol] if effect == FREE else exact_record(effect, value, protocol)
                shr = 0.0 if effect == FREE else share(effect, value, exact, free_exact[protocol])
                label = size_label(effect, value, shr)
                for seed in range(args.seeds):
                    name = f"{effect}_{k}_{protocol}_{seed}"
                    rec, read_warnings = lab_record(exact, seed, folder, name)
                    out = run_one(rec, effect, seed)
                    rows.append({"effect": effect, "size_index": k, "value": value,
                                 "unit": SWEEPS[effect].unit if effect != FREE else "", "share": shr,
                                 "size_label": label, "protocol": protocol, "seed": seed,
                                 "read_warnings": read_warnings, **out})
                rs = rows[-args.seeds:]
                det, orc = sum(r["detected"] for r in rs), sum(bool(r["oracle"]) for r in rs)
                fal = [r["best"] for r in rs if r["false"]]
                print(f"{effect:<19s}{protocol:<11s}{label:<42s} diagnose {det}/{len(rs)}  oracle {orc}/{len(rs)}  "
                      f"false {len(fal)}/{len(rs)}{' (' + ', '.join(fal) + ')' if fal else ''}  "
                      f"[{time.perf_counter() - t0:.0f} s]", flush=True)
                save(args.json, meta, rows)
    print(f"\n{table(rows)}\n\n{len(rows)} diagnoses in {time.perf_counter() - t_all:.0f} s; rows: {args.json}")
    if args.figure:
        figure(rows, args.figure)
        print(f"figure: {args.figure}")


if __name__ == "__main__":
    main()
