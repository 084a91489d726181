"""Production statistics of a series: each identified quantity's distribution
over devices, robust outliers, and the acceptance summary.

The quantities per model are each device's calibrated parameters (its best
run: what its calibration file holds), the model's derived quantities (law
8's mu*N) and the best OF.  A device is an outlier in a quantity when
|x - median| > k 1.4826 MAD over the series (stats.robust_outliers: k = 3.5
unless the campaign file says ``outliers: {k: ...}``; at least 5 devices).

Files (inside the campaign's output, written with the other tables):

    production.csv    model, quantity, unit, devices, mean, std, median, robust_sigma
                      (1.4826 MAD), p05, p95, lower/upper fence (median -+ k robust_sigma),
                      outliers (count)
    outliers.csv      model, device, quantity, unit, value, median, robust_z: one row per flag
    acceptance.csv    model, device, F_tension, F_compression, F_nominal [kN],
                      deviation (max relative), pass (acceptance.py)
    production.json   settings (k, acceptance), per model: outliers per device, pass rate
    figures/histogram_law<SPEC>.png, figures/acceptance.png

The terminal's lines of it are ``text.production``'s.
"""

from __future__ import annotations

import os

import numpy as np

from ..io.staging import write_csv_rows, write_json
from . import stats


def quantities(summary: dict, cs) -> dict:
    """{spec: {"names", "units", "values" (n_dev, n_q)}}: parameters, derived, OF."""
    devices = summary["devices"]
    out = {}
    for spec, m in summary["models"].items():
        model = cs.model(spec)
        best = [m["best"][dev] for dev in devices]
        derived = [model.derived(b.values) for b in best]
        d_names = list(derived[0]) if derived else []
        names = list(m["names"]) + d_names + ["OF"]
        units = list(m["units"]) + [derived[0][n][1] for n in d_names] + ["-"]
        values = np.array([list(b.values) + [dv[n][0] for n in d_names] + [b.of] for b, dv in zip(best, derived)],
                          dtype=float).reshape(len(devices), len(names))
        out[spec] = {"names": names, "units": units, "values": values}
    return out


def analyse(summary: dict, cs, k: float = stats.OUTLIER_K) -> dict:
    """Distributions and outliers per model and quantity (module doc)."""
    out = {"k": k, "devices": summary["devices"], "models": {}}
    for spec, q in quantities(summary, cs).items():
        cols = []
        for j in range(len(q["names"])):
            x = q["values"][:, j]
            flags, z = stats.robust_outliers(x, k)
            ok = x[np.isfinite(x)]
            med, sigma = stats.robust_scale(ok) if ok.size else (np.nan, np.nan)
            cols.append({"median": med, "robust_sigma": sigma, "flags": flags, "z": z,
                         "mean": float(ok.mean()) if ok.size else np.nan,
                         "std": float(ok.std()) if ok.size else np.nan,
                         "p05": float(np.percentile(ok, 5)) if ok.size else np.nan,
                         "p95": float(np.percentile(ok, 95)) if ok.size else np.nan,
                         "judged": ok.size >= stats.MIN_FOR_OUTLIERS})
        out["models"][spec] = {**q, "columns": cols,
                               "outlier_devices": np.any([c["flags"] for c in cols], axis=0)}
    return out


def write(stage: str, prod: dict, accept: dict | None, figures: bool = True) -> None:
    """Write the files of the module doc into ``stage``."""
    devices, k = prod["devices"], prod["k"]
    rows, flagged = [], []
    for spec, m in prod["models"].items():
        for j, (name, unit, c) in enumerate(zip(m["names"], m["units"], m["columns"])):
            fence = k * c["robust_sigma"] if c["judged"] else np.nan
            rows.append([spec, name, unit, len(devices), c["mean"], c["std"], c["median"], c["robust_sigma"],
                         c["p05"], c["p95"], c["median"] - fence, c["median"] + fence,
                         int(c["flags"].sum()) if c["judged"] else ""])
            for i in np.flatnonzero(c["flags"]):
                flagged.append([spec, devices[i], name, unit, m["values"][i, j],
                                c["median"], c["z"][i]])
    write_csv_rows(os.path.join(stage, "production.csv"),
                   ["model", "quantity", "unit", "devices", "mean", "std", "median", "robust_sigma", "p05", "p95",
                    "lower_fence", "upper_fence", "outliers"], rows)
    write_csv_rows(os.path.join(stage, "outliers.csv"),
                   ["model", "device", "quantity", "unit", "value", "median", "robust_z"], flagged)
    if accept and accept["models"]:
        arows = [[spec, dev, a["F"][i, 0], a["F"][i, 1], accept["nominal_force"], a["deviation"][i],
                  int(a["passed"][i])]
                 for spec, a in accept["models"].items() for i, dev in enumerate(devices)]
        write_csv_rows(os.path.join(stage, "acceptance.csv"),
                       ["model", "device", "F_tension_kN", "F_compression_kN", "F_nominal_kN", "deviation",
                        "pass"], arows)
    write_json(os.path.join(stage, "production.json"), as_json(prod, accept))
    if figures:
        _figures(stage, prod, accept)


def as_json(prod: dict, accept: dict | None) -> dict:
    devices = prod["devices"]
    models = {}
    for spec, m in prod["models"].items():
        entry = {"outliers": {devices[i]: [n for n, c in zip(m["names"], m["columns"]) if c["flags"][i]]
                              for i in np.flatnonzero(m["outlier_devices"])}}
        if accept and spec in accept["models"]:
            passed = accept["models"][spec]["passed"]
            entry["acceptance"] = {"passed": int(passed.sum()), "devices": len(devices),
                                   "failed": [devices[i] for i in np.flatnonzero(~passed)]}
        models[spec] = entry
    acc = None
    if accept:
        acc = {k: accept[k] for k in ("settings", "nominal_force", "nominal_source", "amplitude", "dt")}
        acc["skipped"] = accept.get("skipped", {})
    return {"outlier_rule": f"|x - median| > {prod['k']:g} x 1.4826 MAD over the series "
                            f"(at least {stats.MIN_FOR_OUTLIERS} devices)",
            "k": prod["k"], "acceptance": acc, "models": models}


def _figures(stage, prod, accept):
    from ..plots import campaign as plots  # lazily: matplotlib (about 1 s), not needed with --no-figures

    fig_dir = os.path.join(stage, "figures")
    os.makedirs(fig_dir, exist_ok=True)
    for spec, m in prod["models"].items():
        plots.histograms(spec, m["names"], m["units"], m["values"], m["columns"], prod["k"],
                         os.path.join(fig_dir, f"histogram_law{spec}.png"))
    if accept and accept["models"]:
        plots.acceptance(accept, os.path.join(fig_dir, "acceptance.png"))
