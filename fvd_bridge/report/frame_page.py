"""The frame analysis' section of OUT/report.html, from OUT/frame_summary.json.

It leads with the verdict (one line per point), then, where the dampers
were sized, the design per story and the damping achieved against the
target, the response table (one line per case, numbers through
``numbers.rounded``, units in the headers, the notes numbered under it),
the series' spread where a model has several devices, and the figures,
each with a caption saying what to look at.  A section with nothing to
show is left out; a wide table scrolls inside its own box.
"""

from __future__ import annotations

import os
from html import escape

from .html import table
from .parts import image, read_json
from .numbers import rounded, share, with_unit

#: the response columns: (key in a case's 'quantities', header, unit)
COLUMNS = (("drift", "drift", "%"), ("residual", "residual drift", "%"), ("pfa", "floor acc.", "g"),
           ("force", "damper force", "kN"), ("stroke", "stroke", "mm"), ("energy", "energy", "kJ"))

#: each figure's caption: what it shows and what to look at
CAPTIONS = {
    "drift_profiles.png": "Peak interstory drift per story (left) and peak floor acceleration per level (right); "
                          "the bare frame dashed, a series' spread as a band, the upper- and lower-bound dampers "
                          "(--bounds) dotted and dash-dotted. Look at the gap between the bare frame and the damped "
                          "profiles (what the dampers do) against the gap between the models (what the choice of "
                          "model changes) and between the bounds (what the series' scatter changes).",
    "damper_hysteresis.png": "Force against deformation of the story-1 dampers (all of the story), first device of "
                             "each model; the loop area is the energy dissipated. Look at whether the models' "
                             "loops coincide and whether the stroke stays within the tested one.",
    "histories.png": "Roof displacement (top) and story-1 damper force (bottom) over the record and the free "
                     "vibration after it. Look at how fast the motion dies out after the strong shaking and at "
                     "the offset it settles at (the residual drift).",
}

SCROLL = "<div style='overflow-x:auto;max-width:100%'>{}</div>"


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


def _response_table(summary: dict) -> str:
    """One line per case; its notes numbered under the table."""
    per_story = (summary.get("settings") or {}).get("dampers_per_story", 1)
    rows, notes = [], []
    for case in summary.get("cases", []):
        q = _quantities(case, per_story)
        marks = []
        for note in _notes_of(case):
            if note not in notes:
                notes.append(note)
            marks.append(f"[{notes.index(note) + 1}]")
        rows.append([case["label"], rounded(case.get("calibration_of"))]
                    + [rounded(q.get(k)) for k, _, _ in COLUMNS] + [" ".join(marks)])
    header = ["case", "OF"] + [with_unit(name, unit) for _, name, unit in COLUMNS] + ["notes"]
    caption = (f"{summary.get('building', '')} under {summary.get('motion', '')} (PGA {rounded(summary.get('pga_g'))}"
               f" g): peak interstory drift ratio, residual drift ratio, peak absolute floor acceleration, damper "
               f"force and stroke (per damper), the largest over the stories; energy all dampers dissipated; OF: "
               f"the model's calibration OF")
    out = SCROLL.format(table(header, rows, caption))
    if notes:
        out += "<ol class='notes'>" + "".join(f"<li>{escape(n)}</li>" for n in notes) + "</ol>"
    return out


def _sizing_tables(summary: dict) -> str:
    """Where the dampers were sized: each model's dampers per story, and the damping achieved against the target."""
    sized = [c for c in summary.get("cases", []) if (c.get("supplemental_damping") or {}).get("target") is not None]
    if not sized:
        return ""
    first = sized[0]["supplemental_damping"]
    rows = [[c["label"], share(c["supplemental_damping"]["target"]),
             share(c["supplemental_damping"]["estimated"], digits=3), share(c["supplemental_damping"]["achieved"], digits=3),
             rounded(c["supplemental_damping"]["factor_per_damper"], digits=3)] for c in sized]
    parts = [f"<h3>dampers sized for the first mode</h3><p>Each damper is the calibrated device with its force times "
             f"one factor in every story, sized by the energy method (FEMA 274 / FEMA 356) at roof drift "
             f"{share(first['roof_drift'])}; the damping achieved is measured by the free-vibration decay of the "
             f"frame with these dampers (elastic members), less the bare frame's.</p>",
             SCROLL.format(table(["case", "target", "energy method", "achieved (decay)", "force factor per damper"],
                                 rows, "supplemental damping ratio of the first mode"))]
    story_rows = []
    for c in sized:
        for k, s in enumerate(c.get("design") or [], start=1):
            story_rows.append([c["label"], k, rounded(s["stroke_mm"]), rounded(s["velocity_mm_s"]),
                               rounded(s["force_kN"]), rounded(c["supplemental_damping"]["factor_per_damper"],
                                                                digits=3)])
    if story_rows:
        parts.append(SCROLL.format(table(
            ["case", "story", with_unit("stroke amplitude", "mm"), with_unit("design velocity", "mm/s"),
             with_unit("force at the design velocity", "kN"), "force factor"], story_rows,
            "each story's damper in the design cycle of the first mode (per damper)")))
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


def frame_section(out: str) -> str:
    """The frame analysis' section of the page ('' without frame_summary.json)."""
    summary = read_json(os.path.join(out, "frame_summary.json"))
    if summary is None:
        return ""
    lines = summary.get("verdict_lines") or [summary.get("verdict", "")]
    figures = [(os.path.join(out, "figures", name), caption) for name, caption in CAPTIONS.items()
               if os.path.isfile(os.path.join(out, "figures", name))]
    parts = ["<section id='frame'><style>#frame td,#frame th{white-space:nowrap}</style><h2>frame analysis</h2>",
             _dampers_line(out, summary), "<ul class='verdict'>" + "".join(f"<li>{escape(line)}</li>" for line in lines if line) + "</ul>",
             _sizing_tables(summary), "<h3>peak response</h3>", _response_table(summary), _series_table(summary),
             *[image(path, caption) for path, caption in figures], "</section>"]
    return "\n".join(p for p in parts if p)
