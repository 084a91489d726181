"""Outputs of a frame comparison (written all or nothing into one folder).

DIR/frame_table.csv        one row per case: design quantities, calibration OF, export kind, limits exceeded
DIR/frame_series.csv       per model: min, mean, max, CoV over the series' devices of each quantity
DIR/frame_summary.json     building, motion, every case's summary, the spread and the verdict
DIR/histories/<device>_law<SPEC>_story<k>.csv   each damper's deformation history (t [s], d [mm]):
                           `rig --protocol history:FILE` and `compare` accept it, a lab can play it
DIR/figures/               drift profiles (series band), damper hysteresis, time histories
DIR/opensees.log           OpenSees' own messages (kept out of the console)
"""

from __future__ import annotations

import os
import shutil

import numpy as np

from ..io.staging import safe_name, staged_dir, write_csv_rows, write_json
from .compare import QUANTITIES, series_spread, verdict



def _num(x):
    x = float(x)
    return None if not np.isfinite(x) else x


def write_frame_outputs(out: str, building, motion, cases, figures: bool = True, settings: dict | None = None,
                        log: str | None = None) -> dict:
    """Write the tables, histories and figures; returns the summary dict (its
    'series' the spread over the devices, its 'verdict' the verdict's text).
    ``settings``: the run's (dampers per story, force scale, the record's
    share kept) into the summary; ``log``: OpenSees' own messages, kept as
    opensees.log."""
    spread = series_spread(cases)
    text = verdict(spread, cases)
    with staged_dir(out) as stage:
        header = ["case", "model", "device", "calibration_of"] + [f"{k} [{u}]" for k, _, u in QUANTITIES] + [
            "opensees", "algorithms", "exceeded", "note"]
        rows = []
        for c in cases:
            v = c.values()
            kind = "" if c.spec is None else ("skipped" if c.result is None else
                                              "fmu" if c.fmu else ("exact" if c.exact else "approx"))
            rows.append([c.label, c.spec or "", c.device or "", "" if c.of is None else c.of]
                        + [_num(v[k]) for k, _, _ in QUANTITIES]
                        + [kind, " ".join(c.result.solver.algorithms_used) if c.result else "",
                           "; ".join(c.exceeded), c.note if c.spec else ""])
        write_csv_rows(os.path.join(stage, "frame_table.csv"), header, rows)
        srows = [[spec, len(s["devices"]), s["of"], k, *map(_num, s[k])] for spec, s in spread.items()
                 for k, _, _ in QUANTITIES]
        write_csv_rows(os.path.join(stage, "frame_series.csv"),
                       ["model", "devices", "mean_calibration_of", "quantity", "min", "mean", "max", "cov"], srows)
        hist = os.path.join(stage, "histories")
        os.makedirs(hist, exist_ok=True)
        for c in cases:
            if c.result is None or c.result.damper_deformation is None:
                continue
            for k in range(c.result.damper_deformation.shape[1]):
                name = f"{safe_name(c.device)}_law{safe_name(c.spec)}_story{k + 1}.csv"
                write_csv_rows(os.path.join(hist, name), ["t", "d"],
                               [[f"{t:.6g}", f"{d:.9g}"] for t, d in zip(c.result.t, c.result.damper_deformation[:, k])])
        summary = {"building": building.name, "motion": motion.name, "motion_source": motion.source,
                   "pga_g": motion.pga_g, "cases": [{"label": c.label, "model": c.spec, "device": c.device,
                                                     "calibration_of": c.of, "exact": c.exact, "note": c.note,
                                                     "exceeded": c.exceeded, "limits": c.limits,
                                                     "ranked_on": ({"record": c.ranked_on[0], "of": c.ranked_on[1]}
                                                                   if c.ranked_on else None),
                                                     "response": c.result.summary() if c.result else None}
                                                    for c in cases],
                   "series": spread, "verdict": text, "settings": settings or {}}
        write_json(os.path.join(stage, "frame_summary.json"), summary)
        if log and os.path.isfile(log):
            shutil.copyfile(log, os.path.join(stage, "opensees.log"))
        if figures:
            # lazily: matplotlib takes about a second to import, and --no-figures needs none
            from ..plots import frames as figs

            fig_dir = os.path.join(stage, "figures")
            os.makedirs(fig_dir, exist_ok=True)
            title = f"{building.name} under {motion.name} (PGA {motion.pga_g:.3g} g)"
            figs.drift_profiles(cases, title, os.path.join(fig_dir, "drift_profiles.png"))
            if any(c.result is not None and c.spec for c in cases):
                figs.hysteresis(cases, 0, f"story-1 damper in the {building.name}",
                                os.path.join(fig_dir, "damper_hysteresis.png"))
                figs.histories(cases, title, os.path.join(fig_dir, "histories.png"))
        from ..report.page import build_report

        build_report(stage, shown_as=out)
    return summary


def _cell(x: float) -> str:
    """A table value; '-' where the quantity does not exist (the bare frame's damper force)."""
    return f"{x:.4g}" if np.isfinite(x) else "-"


def format_frame_table(cases, spread: dict, text: str) -> str:
    """The printed comparison: one line per case, the series spread, the verdict."""
    w = max(len(c.label) for c in cases) + 2
    head = f"{'case':<{w}}" + "".join(f"{k + ' [' + u + ']':>15}" for k, _, u in QUANTITIES) + "  notes"
    lines = [head, "-" * len(head)]
    for c in cases:
        v = c.values()
        notes = "; ".join(["FMU co-simulation"] * c.fmu + c.exceeded) if c.result is not None else \
            f"skipped: {c.note}"
        lines.append(f"{c.label:<{w}}" + "".join(f"{_cell(v[k]):>15}" for k, _, _ in QUANTITIES) + f"  {notes}")
    if any(len(s["devices"]) > 1 for s in spread.values()):
        lines += ["", "production series: min / mean / max (CoV) over devices"]
        for spec, s in spread.items():
            cells = ", ".join(f"{k} {s[k][0]:.4g}/{s[k][1]:.4g}/{s[k][2]:.4g} ({100 * s[k][3]:.1f}%)"
                              for k in ("drift", "force", "stroke"))
            lines.append(f"  law {spec} ({len(s['devices'])} devices): {cells}")
    lines += ["", f"verdict: {text}"]
    return "\n".join(lines)
