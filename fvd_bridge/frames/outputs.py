"""Outputs of a frame comparison (written all or nothing into one folder).

DIR/frame_table.csv        one row per case: design quantities, calibration OF, export kind, limits exceeded
DIR/frame_series.csv       per model: min, mean, max, CoV over the series' devices of each quantity
DIR/frame_summary.json     building, motion, every case's summary (quantities, supplemental damping of
                           the first mode, the dampers' design per story), the spread and the verdict
DIR/histories/<device>_law<SPEC>_story<k>.csv   each damper's deformation history (t [s], d [mm]):
                           `rig --protocol history:FILE` and `compare` accept it, a lab can play it
DIR/figures/               drift profiles (series band), damper hysteresis, time histories
DIR/opensees.log           OpenSees' own messages (kept out of the console)

What the terminal prints of it is ``text.frames``'.
"""

from __future__ import annotations

import os
import shutil

from ..io.staging import num, safe_name, staged_dir, write_csv_rows, write_json
from . import property_bounds as damper_bounds
from .answer import answer_lines, case_names, grouped_notes
from .compare import QUANTITIES
from .verdict import choice, series_spread, verdict_lines


def write_frame_outputs(out: str, building, motion, cases, figures: bool = True, settings: dict | None = None,
                        log: str | None = None, bounds=None) -> dict:
    """Write the tables, histories and figures; returns the summary dict (its
    'series' the spread over the devices, its 'verdict' the verdict's text).
    ``settings``: the run's (dampers per story, force scale, the record's
    share kept; 'sizing_command': the command line the verdict gives for
    sizing dampers too small to matter) into the summary; ``log``:
    OpenSees' own messages, kept as opensees.log; ``bounds``: the
    frames.property_bounds.Bounds the cases ran with (the envelope: 'bounds').
    The summary's 'answer' (``answer.answer_lines``) is what the page opens
    with and the terminal ends with; 'notes' the cases' notes, one per kind
    (``answer.grouped_notes``: its text and the labels of the cases it
    concerns); 'choice' the model the verdict reports (``verdict.choice``)."""
    spread = series_spread(cases)
    resize = (settings or {}).get("sizing_command")
    lines = verdict_lines(spread, cases, resize) + damper_bounds.envelope_lines(cases)
    text = "; ".join(lines)
    names = case_names(cases)
    with staged_dir(out) as stage:
        header = ["case", "model", "device", "calibration_of"] + [f"{k} [{u}]" for k, _, u in QUANTITIES] + [
            "opensees", "algorithms", "exceeded", "note"]
        rows = []
        for c in cases:
            v = c.values()
            kind = "" if c.spec is None else ("skipped" if c.result is None else
                                              "fmu" if c.fmu else ("exact" if c.exact else "approx"))
            rows.append([c.label, c.spec or "", c.device or "", "" if c.of is None else c.of]
                        + [num(v[k]) for k, _, _ in QUANTITIES]
                        + [kind, " ".join(c.result.solver.algorithms_used) if c.result else "",
                           "; ".join(c.exceeded), c.note if c.spec else ""])
        write_csv_rows(os.path.join(stage, "frame_table.csv"), header, rows)
        srows = [[spec, len(s["devices"]), s["of"], k, *map(num, s[k])] for spec, s in spread.items()
                 for k, _, _ in QUANTITIES]
        write_csv_rows(os.path.join(stage, "frame_series.csv"),
                       ["model", "devices", "mean_calibration_of", "quantity", "min", "mean", "max", "cov"], srows)
        hist = os.path.join(stage, "histories")
        os.makedirs(hist, exist_ok=True)
        for c in cases:
            if c.result is None or c.result.damper_deformation is None:
                continue
            for k in range(c.result.damper_deformation.shape[1]):
                bound = f"_{c.bound}" if c.bound in ("upper", "lower") else ""
                name = f"{safe_name(c.device)}_law{safe_name(c.spec)}{bound}_story{k + 1}.csv"
                write_csv_rows(os.path.join(hist, name), ["t", "d"],
                               [[f"{t:.6g}", f"{d:.9g}"] for t, d in zip(c.result.t, c.result.damper_deformation[:, k])])
        summary = {"building": building.name, "motion": motion.name, "motion_source": motion.source,
                   "pga_g": motion.pga_g, "cases": [{"label": c.label, "model": c.spec, "device": c.device,
                                                     "calibration_of": c.of, "exact": c.exact, "note": c.note,
                                                     "exceeded": c.exceeded, "limits": c.limits,
                                                     "ranked_on": ({"record": c.ranked_on[0], "of": c.ranked_on[1]}
                                                                   if c.ranked_on else None),
                                                     "response": c.result.summary() if c.result else None,
                                                     "quantities": ({k: num(x) for k, x in c.values().items()}
                                                                    if c.result else None),
                                                     "supplemental_damping": c.supplemental_damping(),
                                                     "bound": c.bound, "force_factor": c.scale,
                                                     "design": _design_rows(c), "beyond": c.beyond,
                                                     "short": names[c.label]}
                                                    for c in cases],
                   "series": spread, "verdict": text, "verdict_lines": lines, "settings": settings or {},
                   "bounds": damper_bounds.summary(cases, bounds),
                   "answer": answer_lines(cases, spread, settings, resize), "notes": grouped_notes(cases),
                   "choice": choice(spread, cases)}
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


def _design_rows(case) -> list | None:
    """Each story's damper in the first mode's design cycle (per damper):
    stroke amplitude [mm], peak velocity [mm/s], force at it [kN], loop
    energy [kN mm]; None for the bare frame."""
    d = case.design
    if d is None:
        return None
    return [{"stroke_mm": s.amplitude, "velocity_mm_s": s.velocity, "force_kN": s.force * case.scale,
             "energy_kNmm": s.energy * case.scale} for s in d.stories]
