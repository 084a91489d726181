"""A frame comparison as text (``frame``): one line per case, its notes, the
series' spread, the dampers' sizing, the verdict and the answer
(``frames.answer``: what the page opens with)."""

from __future__ import annotations

import numpy as np

from ..frames.answer import case_names, grouped_notes
from ..frames.compare import QUANTITIES
from ..frames.verdict import nominal
from ..report.names import common_form, distinct
from ..report.numbers import rounded, share, with_unit
from .table import columns


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
             *columns(head, rows), ""]
    for c in sized:
        got = "not measured" if c.achieved is None else share(c.achieved, 3)
        lines.append(f"  {names[c.label]}: force factor {rounded(c.scale, digits=3)}, supplemental damping target "
                     f"{share(c.design.target)}, energy method {share(c.design.damping, 3)}, achieved {got} "
                     f"(free-vibration decay)")
    return "\n".join(lines)


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
    lines += columns(head, rows, right_from=1)
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
