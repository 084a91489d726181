"""The frame analysis' section of OUT/report.html, from OUT/frame_summary.json.

It opens with the answer (``frames.answer``, a few lines: the damper per
story, the peak drift and damper force with the bound that governs each,
the damping achieved, whether the dampers stayed inside what was tested),
then, where the dampers were sized, the dampers per story and the damping
achieved against the target, the response table (one line per case,
numbers through ``numbers.rounded``, units in the headers, the notes
numbered under it, one per kind with the cases it concerns), the series'
spread where a model has several devices, the verdict point by point,
and the figures, each with a caption saying what to look at.  A section
with nothing to show is left out.  No table is wider than the page: the
cases are named by columns (model, the part of a long device name that
differs, the bound) whose text wraps, and the numbers stay on one line.
An older summary (no 'answer') opens with its verdict as before.
"""

from __future__ import annotations

import os
from html import escape

from .html import table
from .names import common_form, distinct
from .parts import image, read_json
from .numbers import rounded, share, with_unit

#: the response columns: (key in a case's 'quantities', header, unit)
COLUMNS = (("drift", "drift", "%"), ("residual", "residual drift", "%"), ("pfa", "floor acc.", "g"),
           ("force", "damper force", "kN"), ("stroke", "stroke", "mm"), ("energy", "energy", "kJ"))

#: each figure's caption: what it shows and what to look at
CAPTIONS = {
    "drift_profiles.png": "Peak interstory drift per story (left) and peak floor acceleration per level (right); "
                          "the bare frame dashed, a series' spread as a band, the upper- and lower-bound dampers "
                          "(--property-bounds) dotted and dash-dotted. Look at the gap between the bare frame and "
                          "the damped profiles (what the dampers do) against the gap between the models (what the "
                          "choice of model changes) and between the bounds (what the series' scatter changes).",
    "damper_hysteresis.png": "Force against deformation of the story-1 dampers (all of the story), first device of "
                             "each model; the loop area is the energy dissipated. Look at whether the models' "
                             "loops coincide and whether the stroke stays within the tested one.",
    "histories.png": "Roof displacement (top) and story-1 damper force (bottom) over the record and the free "
                     "vibration after it. Look at how fast the motion dies out after the strong shaking and at "
                     "the offset it settles at (the residual drift).",
}

SCROLL = "<div style='overflow-x:auto;max-width:100%'>{}</div>"

#: the bounds as the tables name them
BOUND_NAMES = {"nominal": "nominal", "upper": "upper bound", "lower": "lower bound"}

#: numbers and names stay on one line and headers wrap; a case's name longer than NAME_CHARS (the model's
#: or device's column, class w1 or w2; a header, class wh) wraps, anywhere if it must, so that no table is
#: wider than the page
STYLE = ("#frame td{white-space:nowrap}#frame th{white-space:normal}"
         "#frame table.w1 td:nth-child(1),#frame table.w2 td:nth-child(2)"
         "{white-space:normal;overflow-wrap:anywhere;min-width:16ch}#frame table.wh th{overflow-wrap:anywhere}"
         "#frame td.note{white-space:normal}"
         "#frame p.answer{line-height:1.5}")
#: a case's name up to this many characters keeps one line
NAME_CHARS = 32


def frame_devices(out: str) -> str:
    """'device_01 (laws 2, 9)': the devices of the folder's frame analysis, for the page's head ('' without one)."""
    summary = read_json(os.path.join(out, "frame_summary.json"))
    if summary is None:
        return ""
    laws: dict = {}
    for case in summary.get("cases", []):
        if case.get("device"):
            models = laws.setdefault(case["device"], [])
            if case["model"] not in models:  # a model's bound cases are the same device and law
                models.append(case["model"])
    return ", ".join(f"{escape(d)} (law{'s' if len(m) > 1 else ''} {escape(', '.join(m))})" for d, m in laws.items())


def _quantities(case: dict, per_story: int) -> dict:
    """A case's design quantities; from its response where an older summary has none."""
    if case.get("quantities"):
        return case["quantities"]
    r = case.get("response") or {}

    def peak(key, factor=1.0):
        values = [x for x in (r.get(key) or []) if x is not None]
        return factor * max(abs(x) for x in values) if values else None
    energy = r.get("total_damper_energy_kNmm")
    return {"drift": None if r.get("max_drift_ratio") is None else 100 * r["max_drift_ratio"],
            "residual": peak("residual_drift_ratio", 100.0), "pfa": peak("peak_floor_acceleration_g"),
            "force": peak("peak_damper_force_kN", 1.0 / per_story), "stroke": peak("peak_damper_stroke_mm"),
            "energy": None if energy is None else 1e-3 * energy}


def _notes_of(case: dict) -> list[str]:
    notes = list(case.get("exceeded") or [])
    if case.get("model") and case.get("note") and not case.get("exact"):  # how OpenSees approximates the model
        notes.append(case["note"])
    if case.get("model") and case.get("response") is None:
        notes.insert(0, "skipped")
    return notes


def _label_columns(cases: list) -> tuple[list, object, int]:
    """The columns naming a case, a function giving a case's cells, and how
    many of them wrap (the model's and the device's, not the bound's): the
    model; the device where the cases hold several (the part of its name
    that differs, ``names.distinct``); the damper (nominal, upper or lower
    bound) where the run has bounds."""
    devices = distinct(c["device"] for c in cases if c.get("model") and c.get("device"))
    several = len(devices) > 1
    bounds = any(c.get("bound") for c in cases)
    head = ["model"] + (["device"] if several else []) + (["damper"] if bounds else [])

    def cells(case: dict) -> list:
        if not case.get("model"):
            return [case["label"]] + [""] * (len(head) - 1)
        return ([f"law {case['model']}"] + ([devices.get(case.get("device"), case.get("device") or "")] if several
                                            else []) + ([BOUND_NAMES.get(case.get("bound"), "")] if bounds else []))
    return head, cells, 1 + several


def _devices_said(cases: list) -> str:
    """'device ARTS-...-lab-B' or 'devices ARTS-...-…-lab-B (the table names the part that differs)'."""
    devices = list(dict.fromkeys(c["device"] for c in cases if c.get("model") and c.get("device")))
    if len(devices) == 1:
        return f"device {devices[0]}"
    if devices and distinct(devices)[devices[0]] != devices[0]:
        return f"devices {common_form(devices)} (the table names the part that differs)"
    return ""


def _case_notes(summary: dict) -> tuple[list, dict]:
    """The notes under the response table and {label: their numbers}: the
    summary's notes, one per kind (``frames.answer.grouped_notes``); an older
    summary's, one per distinct text."""
    cases = summary.get("cases", [])
    if summary.get("notes") is not None:
        notes = [n["text"] for n in summary["notes"]]
        marks = {c["label"]: [k for k, n in enumerate(summary["notes"], start=1) if c["label"] in n["cases"]]
                 for c in cases}
        return notes, marks
    notes, marks = [], {}
    for case in cases:
        for note in _notes_of(case):
            if note not in notes:
                notes.append(note)
            marks.setdefault(case["label"], []).append(notes.index(note) + 1)
    return notes, marks


def _table(head: list, rows: list, caption: str, labels: int) -> str:
    """``html.table`` whose first ``labels`` columns (the cases' names) wrap
    where a name is longer than NAME_CHARS (class w1, w2), and its headers
    anywhere where one holds a word that long (class wh); a shorter name
    keeps its line, and a squeezed table wraps its headers instead."""
    wrap = [f"w{k + 1}" for k in range(labels) if rows and max(len(str(r[k])) for r in rows) > NAME_CHARS]
    wrap += ["wh"] * any(len(h) > NAME_CHARS and max(map(len, h.split())) > NAME_CHARS for h in head)
    return SCROLL.format(table(head, rows, caption, css=" ".join(wrap)))


def _response_table(summary: dict) -> str:
    """One line per case; its notes numbered under the table, one per kind."""
    per_story = (summary.get("settings") or {}).get("dampers_per_story", 1)
    cases = summary.get("cases", [])
    head, cells, wrap = _label_columns(cases)
    notes, marks = _case_notes(summary)
    rows = []
    for case in cases:
        q = _quantities(case, per_story)
        rows.append(cells(case) + [rounded(case.get("calibration_of"))] + [rounded(q.get(k)) for k, _, _ in COLUMNS]
                    + [" ".join(f"[{k}]" for k in marks.get(case["label"], []))])
    header = head + ["OF"] + [with_unit(name, unit) for _, name, unit in COLUMNS] + ["notes"]
    devices = _devices_said(cases)
    caption = (f"{summary.get('building', '')} under {summary.get('motion', '')} (PGA {rounded(summary.get('pga_g'))}"
               f" g){', ' + devices if devices else ''}: peak interstory drift ratio, residual drift ratio, peak "
               f"absolute floor acceleration, damper force and stroke (per damper), the largest over the stories; "
               f"energy all dampers dissipated; OF: the model's calibration OF")
    out = _table(header, rows, caption, wrap)
    if notes:
        out += "<ol class='notes'>" + "".join(f"<li>{escape(n)}</li>" for n in notes) + "</ol>"
    return out


def _span(values, digits: int | None = None) -> str:
    """'2561' or '2550-2570': the values, rounded, as one number or a range."""
    values = [v for v in values if v is not None]
    if not values:
        return "-"
    low, high = rounded(min(values), digits=digits), rounded(max(values), digits=digits)
    return low if low == high else f"{low}-{high}"


def _sizing_tables(summary: dict) -> str:
    """Where the dampers were sized: each story's damper (per model, its
    force at the design velocity: nominal, and the bounds' range), and each
    case's force factor and damping achieved against the target."""
    cases = summary.get("cases", [])
    sized = [c for c in cases if (c.get("supplemental_damping") or {}).get("target") is not None]
    if not sized:
        return ""
    first = sized[0]["supplemental_damping"]
    head, cells, wrap = _label_columns(sized)
    rows = [cells(c) + [rounded(c["supplemental_damping"]["factor_per_damper"], digits=3),
                        share(c["supplemental_damping"]["estimated"], digits=3),
                        share(c["supplemental_damping"]["achieved"], digits=3)] for c in sized]
    damping = _table(head + ["force factor per damper", "energy method", "achieved (decay)"], rows,
                     f"supplemental damping ratio of the first mode for the {share(first['target'])} target", wrap)
    parts = ["<h3>dampers per story</h3>"]
    designed = [c for c in sized if c.get("design")]
    if designed:
        models = list(dict.fromkeys(c["model"] for c in designed))
        bounds = any(c.get("bound") in ("upper", "lower") for c in designed)
        story_rows = []
        for k in range(len(designed[0]["design"])):
            row = [k + 1, _span([c["design"][k]["stroke_mm"] for c in designed]),
                   _span([c["design"][k]["velocity_mm_s"] for c in designed])]
            for m in models:
                mine = [c for c in designed if c["model"] == m]
                own = [c["design"][k]["force_kN"] for c in mine if c.get("bound") in (None, "nominal")]
                other = [c["design"][k]["force_kN"] for c in mine if c.get("bound") in ("upper", "lower")]
                row.append(_span(own) + (f" ({_span(other)})" if other else ""))
            story_rows.append(row)
        force = "nominal (lower-upper bound)" if bounds else "per damper"
        parts.append(_table(["story", with_unit("stroke amplitude", "mm"), with_unit("design velocity", "mm/s")]
                            + [f"law {m}: {with_unit('force at it', 'kN')}" for m in models], story_rows,
                            f"each story's damper in the design cycle of the first mode: force at the design "
                            f"velocity per damper, {force}", 0))
    parts += [damping,
              f"<p>Each damper is the calibrated device with its force times one factor in every story, sized by "
              f"the energy method (FEMA 274 / FEMA 356) at roof drift {share(first['roof_drift'])}; the damping "
              f"achieved is measured by the free-vibration decay of the frame with these dampers (elastic "
              f"members), less the bare frame's.</p>"]
    return "\n".join(parts)


def _series_table(summary: dict) -> str:
    """Min / mean / max (CoV) over a series' devices, per model with more than one device."""
    rows = []
    for spec, s in (summary.get("series") or {}).items():
        if len(s.get("devices", [])) < 2:
            continue
        for key, name, unit in COLUMNS:
            low, mean, high, cov = s[key]
            rows.append([f"law {spec}", len(s["devices"]), with_unit(name, unit), rounded(low), rounded(mean),
                         rounded(high), share(cov)])
    if not rows:
        return ""
    return SCROLL.format(table(["model", "devices", "quantity", "min", "mean", "max", "CoV"], rows,
                               "the series: spread over the devices of each model"))


def _dampers_line(out: str, summary: dict) -> str:
    """'Devices: device_01 (laws 2, 9); 1 damper per story, ...': what sits in the stories."""
    devices = frame_devices(out)
    if not devices:
        return ""
    settings = summary.get("settings") or {}
    n = settings.get("dampers_per_story", 1)
    how = f"{n} damper{'s' if n > 1 else ''} per story"
    if settings.get("target_damping") is not None:
        how += f", sized for {share(settings['target_damping'])} of critical damping in the first mode"
    elif settings.get("scale_force", 1.0) != 1.0:
        how += f", each the device with its force x{rounded(settings['scale_force'], digits=3)}"
    return f"<p>Devices: {devices}; {escape(how)}</p>"


def _answer(summary: dict) -> str:
    """The answer the section opens with (the summary's 'answer', one line
    each, the words before a line's first colon set in bold)."""
    lines = []
    for line in summary.get("answer") or []:
        head, sep, rest = line.partition(": ")
        lines.append(f"<b>{escape(head)}:</b> {escape(rest)}" if sep and len(head) <= 40 else escape(line))
    return f"<p class='answer'>{'<br>'.join(lines)}</p>" if lines else ""


def frame_section(out: str) -> str:
    """The frame analysis' section of the page ('' without frame_summary.json)."""
    summary = read_json(os.path.join(out, "frame_summary.json"))
    if summary is None:
        return ""
    lines = summary.get("verdict_lines") or [summary.get("verdict", "")]
    verdict = "<ul class='verdict'>" + "".join(f"<li>{escape(line)}</li>" for line in lines if line) + "</ul>"
    figures = [(os.path.join(out, "figures", name), caption) for name, caption in CAPTIONS.items()
               if os.path.isfile(os.path.join(out, "figures", name))]
    answer = _answer(summary)
    top = [answer] if answer else [_dampers_line(out, summary), verdict]  # an older summary: its verdict first
    bottom = ["<h3>the verdict, point by point</h3>", verdict] if answer else []
    parts = [f"<section id='frame'><style>{STYLE}</style><h2>frame analysis</h2>", *top,
             _sizing_tables(summary), "<h3>peak response</h3>", _response_table(summary), _series_table(summary),
             *bottom, *[image(path, caption) for path, caption in figures], "</section>"]
    return "\n".join(p for p in parts if p)
