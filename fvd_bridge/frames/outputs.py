"""Outputs of a frame comparison (written all or nothing into one folder).

DIR/frame_table.csv        one row per case: design quantities, calibration OF, export kind, limits exceeded
DIR/frame_series.csv       per model: min, mean, max, CoV over the series' devices of each quantity
DIR/frame_summary.json     building, motion, every case's summary (quantities, supplemental damping of
                           the first mode, the dampers' design per story), the spread and the verdict
DIR/histories/<device>_law<SPEC>_story<k>.csv   each damper's deformation history (t [s], d [mm]):
                           `rig --protocol history:FILE` and `compare` accept it, a lab can play it
DIR/figures/               drift profiles (series band), damper hysteresis, time histories
DIR/opensees.log           OpenSees' own messages (kept out of the console)
"""

from __future__ import annotations

import os
import shutil

import numpy as np

from ..io.staging import num, safe_name, staged_dir, write_csv_rows, write_json
from ..report.names import common_form, distinct
from ..report.numbers import rounded, share, with_unit
from . import property_bounds as damper_bounds
from .answer import answer_lines, case_names, grouped_notes
from .compare import QUANTITIES
from .verdict import choice, nominal, series_spread, verdict_lines


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


def _cell(x: float) -> str:
    """A table value (``numbers.rounded``); '-' where the quantity does not exist (the bare frame's damper force)."""
    return rounded(x) if np.isfinite(x) else "-"


def format_sizing_table(cases) -> str:
    """The dampers sized for a target damping: per model (its nominal
    dampers; the bounds' are these times their factor) and story the
    damper's stroke, velocity and force at the design velocity and its
    factor, then each case's damping achieved against the target ('' when
    none was sized); cases by their short names (``answer.case_names``)."""
    sized = [c for c in cases if c.design is not None and c.design.target is not None]
    if not sized:
        return ""
    names = case_names(cases)
    d = sized[0].design
    head = ["case", "story", with_unit("stroke", "mm"), with_unit("design velocity", "mm/s"),
            with_unit("force at it", "kN"), "force factor"]
    rows = [[names[c.label], str(k), rounded(s.amplitude), rounded(s.velocity), rounded(s.force * c.scale),
             rounded(c.scale, digits=3)] for c in nominal(sized) for k, s in enumerate(c.design.stories, start=1)]
    lines = [f"dampers sized for {share(d.target)} of critical damping in the first mode (T1 {rounded(d.period)} s) "
             f"at roof drift {share(d.roof_drift)} ({rounded(d.roof_amplitude)} mm), energy method (FEMA 274): "
             "each damper the calibrated device with its force times one factor in every story"
             + ("; a bound's damper is the nominal one times its factor" if len(nominal(sized)) < len(sized) else ""),
             *_columns(head, rows), ""]
    for c in sized:
        got = "not measured" if c.achieved is None else share(c.achieved, 3)
        lines.append(f"  {names[c.label]}: force factor {rounded(c.scale, digits=3)}, supplemental damping target "
                     f"{share(c.design.target)}, energy method {share(c.design.damping, 3)}, achieved {got} "
                     f"(free-vibration decay)")
    return "\n".join(lines)


def _columns(head: list, rows: list, right_from: int = 1) -> list[str]:
    """Lines of a text table: columns as wide as their widest cell, numbers right-aligned."""
    width = [max(len(str(r[k])) for r in [head, *rows]) for k in range(len(head))]

    def line(r):
        return "  ".join(f"{r[k]:<{width[k]}}" if k < right_from else f"{r[k]:>{width[k]}}"
                         for k in range(len(r))).rstrip()
    top = line(head)
    return [top, "-" * len(top), *[line(r) for r in rows]]


def format_frame_table(cases, spread: dict, text: str | list, answer: list | None = None) -> str:
    """The printed comparison: one line per case by its short name
    (``answer.case_names``; the device named once above), its notes
    numbered under the table, one per kind (``answer.grouped_notes``), the
    series spread, the dampers' sizing, the verdict (a text or its lines)
    and, last, the answer (``answer.answer_lines``: what the page opens with)."""
    names = case_names(cases)
    notes = grouped_notes(cases)
    rows = []
    for c in cases:
        v = c.values()
        marks = [f"[{k}]" for k, n in enumerate(notes, start=1) if c.label in n["cases"]]
        rows.append([names[c.label], rounded(c.of)] + [_cell(v[k]) for k, _, _ in QUANTITIES] + [" ".join(marks)])
    head = ["case", "calibration OF"] + [with_unit(k, u) for k, _, u in QUANTITIES] + ["notes"]
    devices = list(dict.fromkeys(c.device for c in cases if c.spec is not None))
    lines = []
    if len(devices) == 1:
        lines.append(f"device: {devices[0]}")
    elif devices and distinct(devices)[devices[0]] != devices[0]:
        lines.append(f"devices: {common_form(devices)} (the cases name the part that differs)")
    lines += _columns(head, rows, right_from=1)
    lines += [f"  [{k}] {n['text']}" for k, n in enumerate(notes, start=1)]
    if any(len(s["devices"]) > 1 for s in spread.values()):
        lines += ["", "production series: min / mean / max (CoV) over devices"]
        for spec, s in spread.items():
            cells = ", ".join(f"{k} {rounded(s[k][0])}/{rounded(s[k][1])}/{rounded(s[k][2])} ({share(s[k][3])})"
                              for k in ("drift", "force", "stroke"))
            lines.append(f"  law {spec} ({len(s['devices'])} devices): {cells}")
    sizing = format_sizing_table(cases)
    if sizing:
        lines += ["", sizing]
    verdict = [text] if isinstance(text, str) else list(text)
    lines += ["", "verdict:" + ("" if len(verdict) > 1 else f" {verdict[0]}")]
    if len(verdict) > 1:
        lines += [f"  - {line}" for line in verdict]
    if answer:
        lines += ["", "answer:", *[f"  {line}" for line in answer]]
    return "\n".join(lines)
