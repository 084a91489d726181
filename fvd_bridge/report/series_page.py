"""The series' section of OUT/report.html, after its devices: each model's
mean OF and robustness, the Pareto front, the dispersion, and a production
campaign's tables (statistics, outliers, acceptance, upper and lower bounds)."""

from __future__ import annotations

import csv
import glob
import os
from html import escape

from ..campaign import acceptance as series_acceptance
from ..campaign import property_bounds as series_bounds
from .html import NOTE_CHARS, table
from .numbers import cell, rounded
from .parts import figure, read_json


def series_section(out: str) -> str:
    """The series, after its devices: each model's mean OF and robustness,
    the Pareto front, the dispersion, a production campaign's statistics;
    nothing for fewer than two devices (no scatter over devices to show)."""
    summary = read_json(os.path.join(out, "summary.json"))
    if summary is None:
        return ""
    devices = [d["name"] if isinstance(d, dict) else d for d in summary.get("devices", [])]
    if len(devices) < 2:
        return ""
    rows = []
    for spec, m in summary.get("models", {}).items():
        of = m.get("of_mean")
        of = sum(of) / len(of) if isinstance(of, list) else of
        rows.append([f"law {spec}", rounded(of), rounded(m.get("beta"), digits=3),
                     "yes" if m.get("non_dominated") else "", "; ".join(m.get("notes") or [])])
    figs = [p for name in ("of_bars.png", "pareto.png") for p in [os.path.join(out, "figures", name)]
            if os.path.isfile(p)]
    figs += sorted(glob.glob(os.path.join(out, "figures", "dispersion_law*.png")))
    figs += sorted(glob.glob(os.path.join(out, "figures", "histogram_law*.png")))
    figs += [p for p in [os.path.join(out, "figures", "acceptance.png")] if os.path.isfile(p)]
    production = [csv_table(out, name, caption) for name, caption in PRODUCTION_TABLES]
    return "\n".join(["<section id='series'><h2>the series</h2>",
                      table(["model", "mean OF", "robustness index beta_r", "Pareto front", "notes"], rows,
                            f"{len(devices)} devices: {', '.join(devices)}"),
                      *[p for p in production if p], *[figure(p) for p in figs], "</section>"])


#: a production campaign's tables (``campaign.production``), as the report shows them
PRODUCTION_TABLES = (("production.csv", "production statistics of the calibrated quantities"),
                     ("outliers.csv", "outliers: devices beyond the robust fences"),
                     ("acceptance.csv", f"the series' acceptance: {series_acceptance.RULE} ({series_acceptance.SOURCE})"),
                     ("bounds.csv", f"upper- and lower-bound properties (nominal: the series' mean; units in 'unit'): "
                                    f"{series_bounds.RULE} ({series_bounds.SOURCE})"))


def csv_table(out: str, name: str, caption: str) -> str:
    """A CSV file of the folder as a table, its numbers rounded (``numbers.cell``), its columns of long
    notes listed under it (the rows stay one line high); '' when it is not there or holds no row."""
    path = os.path.join(out, name)
    if not os.path.isfile(path):
        return ""
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    if len(rows) < 2:
        return ""
    header, body = rows[0], rows[1:]
    notes = [j for j in range(1, len(header)) if any(len(r[j]) > NOTE_CHARS and " " in r[j] for r in body if j < len(r))]
    keep = [j for j in range(len(header)) if j not in notes]
    listed = [f"<li><b>{escape(r[0])}</b>, {escape(header[j])}: {escape(r[j])}</li>"
              for r in body for j in notes if j < len(r) and r[j]]
    out = table([header[j] for j in keep], [[cell(r[j]) if j < len(r) else "" for j in keep] for r in body], caption)
    return out + (f"<ul class='notes'>{''.join(listed)}</ul>" if listed else "")
