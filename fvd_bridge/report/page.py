"""OUT/report.html: one self-contained page of what an output folder holds.

Built from the files a verb wrote (``fvd-bridge report OUT`` builds it again):
the calibration files (params/DEVICE/*.yaml) give per device its tests, the
fit tables with intervals and warnings, and, with the records read again as
they were calibrated, the acceptance table (``acceptance.py``);
summary.json gives the series' statistics and Pareto front; a diagnosis'
JSON its verdict and candidates; frame_summary.json the frame's verdict.
Every figure in the folder is embedded (base64 PNG): the page fetches
nothing from another host, reads offline and survives being mailed.
"""

from __future__ import annotations

import base64
import csv
import glob
import json
import os
import re
from html import escape

import numpy as np

from .. import __version__
from ..calibration import Calibration, common_tests, same_data
from ..io.staging import atomic_file
from ..diagnose.where import analyse, summary_lines
from ..fit import noise_floor
from ..errors import InputError, PluginNeeded
from ..export.ledger import exports_of
from ..records.readers import read_as_stored
from ..records.cycles import force_noise
from .acceptance import TOLERANCE, checks_of_test
from .html import calibration_table, short, table, zero_table

STYLE = """body{font-family:system-ui,sans-serif;max-width:1200px;margin:2em auto;padding:0 1em;color:#222}
table.fvd{border-collapse:collapse;margin:.6em 0 1.2em}table.fvd td,table.fvd th{border:1px solid #ccc;
padding:.2em .6em;text-align:left}table.fvd caption{text-align:left;font-weight:600;padding:.3em 0}
.pass{color:#176b2c}.fail{color:#b00020;font-weight:600}img{max-width:100%;border:1px solid #eee}
figure{margin:.5em 0 1.5em}figcaption{color:#555;font-size:.9em}section.device{border-top:2px solid #336;
margin-top:2em}"""


def _image(path: str, caption: str) -> str:
    with open(path, "rb") as fh:
        data = base64.b64encode(fh.read()).decode("ascii")
    return (f"<figure><img alt='{escape(caption)}' src='data:image/png;base64,{data}'>"
            f"<figcaption>{escape(caption)}</figcaption></figure>")


def _record(test: dict):
    """A calibration's test read again as it was calibrated, named as the test; None when its file is gone."""
    rec = read_as_stored(test.get("record") or {})
    if rec is not None:
        rec.name = test["name"]
    return rec


def _json(path: str) -> dict | None:
    """The JSON file at ``path``; None when it is not there."""
    if not os.path.isfile(path):
        return None
    with open(path) as fh:
        return json.load(fh)


def _calibrations(out: str, plugins=()) -> dict:
    """{device: [Calibration]} of the folder's calibration files (read with
    the caller's ``plugins``; one whose plugin is not given is an error, not a gap)."""
    found: dict = {}
    for path in sorted(glob.glob(os.path.join(out, "params", "*", "*.yaml"))):
        try:
            cal = Calibration.load(path, plugins=plugins)
        except PluginNeeded:
            raise
        except InputError:  # a file that is not a calibration: not part of the report
            continue
        found.setdefault(os.path.basename(os.path.dirname(path)), []).append(cal)
    return found


def _series_nominal(cals: dict) -> dict:
    """{spec: [Calibration of each device]}: the series' models, for the nominal force."""
    by_spec: dict = {}
    for device_cals in cals.values():
        for cal in device_cals:
            by_spec.setdefault(cal.spec, []).append(cal)
    return by_spec


def _series_force(series_cals: list, rec) -> float:
    """The series' nominal force [kN] on a record's motion: the mean over the
    series' devices of their calibrated model's peak |F|, the devices'
    parameter vectors run as one population (one batch of the kernels)."""
    P = np.array([c.params_for(c.test_named(rec.name)) for c in series_cals])
    return float(np.abs(series_cals[0].model.force(rec, P)).max(axis=1).mean())


def _best(cals: list, records: dict) -> tuple:
    """The device's best model and how it was chosen: the lowest OF where
    all were fitted to the same tests; else the lowest OF on the tests all
    were fitted on (their records read again); else, not ranked, the first."""
    if same_data(cals):
        return min(cals, key=lambda c: c.of), "the lowest OF"
    common = [records[t["name"]] for t in common_tests(cals) if records.get(t["name"]) is not None]
    if common:
        names = ", ".join(r.name for r in common)
        return min(cals, key=lambda c: np.mean([c.of_on(r) for r in common])), f"the lowest OF on {names}"
    return cals[0], "fitted to different tests: not ranked, the first file's"


def _acceptance(device: str, cals: list, series: dict, records: dict, tolerance: float) -> str:
    """The device's acceptance table: its tests checked against the series'
    best model (``_best``: the lowest OF on the same data) as the nominal."""
    best, chosen = _best(cals, records)
    rows, notes = [], []
    for test in best.tests:
        rec = records.get(test["name"])
        if rec is None:
            notes.append(f"{test['name']}: its record file is not found; no acceptance checks")
            continue
        nominal = _series_force(series[best.spec], rec)
        for chk in checks_of_test(rec, nominal, tolerance):
            rows.append((chk, f"{chk.deviation:.1%}"))
    body = "".join(
        f"<tr><td>{escape(c.test)}</td><td>{escape(c.what)}</td><td>{short(c.measured)}</td>"
        f"<td>{short(c.reference)}</td><td>{dev}</td><td class='{'pass' if c.passed else 'fail'}'>"
        f"{'pass' if c.passed else 'FAIL'}</td><td>{escape(c.rule)}</td></tr>" for c, dev in rows)
    caption = (f"acceptance of {device}: tolerance +-{tolerance:.0%}; nominal force: law {best.spec} ({chosen}) "
               f"of the series ({len(series[best.spec])} device(s)) at each test's velocity")
    out = (f"<table class='fvd acceptance'><caption>{escape(caption)}</caption><thead><tr><th>test</th>"
           f"<th>check</th><th>measured</th><th>reference</th><th>deviation</th><th>verdict</th><th>rule</th>"
           f"</tr></thead><tbody>{body}</tbody></table>")
    return out + "".join(f"<p>{escape(n)}</p>" for n in notes)


def _tests_table(cal, records: dict) -> str:
    """Each test's range, its noise-floor OF (the record's force noise alone) and the model's OF."""
    rows = []
    for t in cal.tests:
        block, rng, rec = t.get("record") or {}, t.get("range") or {}, records.get(t["name"])
        floor = None if rec is None else noise_floor(force_noise(rec.F), rec.F)
        rows.append([t["name"], block.get("samples", "-"), short(block.get("dt")), short(rng.get("d")), short(rng.get("v")),
                     short(rng.get("f")), short((block.get("peaks") or {}).get("F")), short(floor, 3), short(t.get("of"))])
    return table(["test", "samples", "dt [s]", "stroke [mm]", "velocity [mm/s]", "frequency [Hz]",
                  "peak force [kN]", "noise-floor OF", f"OF of {cal.spec}"], rows, "the tests")


def _where_lists(cals: list, records: dict) -> str:
    """Where each model fails on each test: diagnose's findings (``diagnose.where``)."""
    parts = []
    for cal in cals:
        for name, rec in records.items():
            if rec is None:
                continue
            F = cal.force(rec, test=cal.test_named(name))
            lines = summary_lines(analyse(rec, F), force_noise(rec.F))
            parts.append(f"<p><b>{escape(cal.spec)} on {escape(name)}</b></p><ul>"
                         + "".join(f"<li>{escape(line)}</li>" for line in lines) + "</ul>")
    return "\n".join(parts)


def _exports(out: str, device: str, cals: list, records: dict) -> str:
    """The exports' fidelity: each model's OpenSees material (kN, mm, s)
    driven with each test's motion against the model
    (``opensees_check.check_on_record``), or why OpenSees cannot hold it;
    then the exports made of the device's calibrations (``export.ledger``)."""
    from ..export.opensees_check import check_on_record, quiet_opensees

    quiet_opensees()
    rows = []
    for cal in cals:
        for name, rec in records.items():
            if rec is None:
                continue
            try:
                res = check_on_record(cal, rec, test=cal.test_named(name))
            except InputError as exc:  # OpenSees has no material for it: the FMU is the way
                rows.append([cal.spec, name, "none", "-", "-", str(exc).split(": ", 1)[-1]])
                continue
            rows.append([cal.spec, name, "exact" if res.exact else "approximate", short(res.of, 3),
                         short(res.bound, 3), "within its bound" if res.ok else "OUTSIDE its bound"])
    parts = [table(["model", "test", "OpenSees mapping", "OF(OpenSees vs model)", "bound", "verdict"], rows,
                   "each model's OpenSees material driven with the test's motion (kN, mm, s; eq. 18 with the "
                   "model's force as reference)") if rows else
             "<p>the tests' record files are not found: no OpenSees fidelity check</p>"]
    made = []
    for e in exports_of(out):
        if e.get("device") == device:
            check = e.get("check") or {}
            made.append([e["kind"], e["model"], os.path.basename(e["file"]), e["units"],
                         check.get("record", "not checked"), short(check.get("of"), 3), short(check.get("bound"), 3),
                         e["written"]])
    if made:
        parts.append(table(["export", "model", "file", "units", "checked on", "OF(export vs model)", "bound",
                            "written"], made, "the exports made (fvd-bridge export)"))
    return "\n".join(parts)


def _loop_figures(out: str, device: str, cals: list) -> list:
    """The device's loop figures, by the names ``campaign.outputs`` gives them."""
    names = [f"loops_{t['name'] if len(c.tests) == 1 else device + '_' + t['name']}_law{c.spec}.png"
             for c in cals for t in c.tests]
    return [p for p in (os.path.join(out, "figures", n) for n in names) if os.path.isfile(p)]


def _device_section(out: str, device: str, cals: list, series: dict, tolerance: float) -> str:
    figures = _loop_figures(out, device, cals)
    records = {t["name"]: _record(t) for t in cals[0].tests}
    parts = [f"<section class='device' id='device-{escape(device)}'><h2>device {escape(device)}</h2>",
             _tests_table(cals[0], records), "<h3>fits</h3>", *[calibration_table(c) for c in cals],
             "<h3>acceptance</h3>", _acceptance(device, cals, series, records, tolerance),
             "<h3>where each model fails</h3>", _where_lists(cals, records),
             "<h3>exports</h3>", _exports(out, device, cals, records), "<h3>loops</h3>",
             *[_image(p, os.path.basename(p)) for p in figures], "</section>"]
    return "\n".join(parts)


def _series_section(out: str) -> str:
    summary = _json(os.path.join(out, "summary.json"))
    if summary is None:
        return ""
    devices = [d["name"] if isinstance(d, dict) else d for d in summary.get("devices", [])]
    rows = []
    for spec, m in summary.get("models", {}).items():
        rows.append([spec, short(m.get("of_mean") if not isinstance(m.get("of_mean"), list) else
                              sum(m["of_mean"]) / len(m["of_mean"])), short(m.get("beta")),
                     "yes" if m.get("non_dominated") else "", "; ".join(m.get("notes") or [])])
    figs = [p for name in ("of_bars.png", "pareto.png") for p in [os.path.join(out, "figures", name)]
            if os.path.isfile(p)]
    figs += sorted(glob.glob(os.path.join(out, "figures", "dispersion_law*.png")))
    figs += sorted(glob.glob(os.path.join(out, "figures", "histogram_law*.png")))
    figs += [p for p in [os.path.join(out, "figures", "acceptance.png")] if os.path.isfile(p)]
    production = [_csv_table(out, name, caption) for name, caption in PRODUCTION_TABLES]
    return "\n".join(["<section id='series'><h2>the series</h2>",
                      table(["model", "mean OF", "robustness beta_r", "Pareto front", "notes"], rows,
                            f"{len(devices)} device(s): {', '.join(devices)}"),
                      *[p for p in production if p],
                      *[_image(p, os.path.basename(p)) for p in figs], "</section>"])


#: a production campaign's tables (``campaign.production``), as the report shows them
PRODUCTION_TABLES = (("production.csv", "production statistics of the calibrated quantities"),
                     ("outliers.csv", "outliers: devices beyond the robust fences"),
                     ("acceptance.csv", "the series' acceptance: force at the design velocity against the band"))


def _csv_table(out: str, name: str, caption: str) -> str:
    """A CSV file of the folder as a table ('' when it is not there)."""
    path = os.path.join(out, name)
    if not os.path.isfile(path):
        return ""
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    if len(rows) < 2:
        return f"<p>{escape(caption)}: none</p>"
    return table(rows[0], rows[1:], caption)


def _diagnosis_sections(out: str) -> str:
    parts = []
    for path in sorted(glob.glob(os.path.join(out, "*_diagnose.json"))):
        rep = _json(path)
        rows = [[c["effect"], short(c["of"]), f"{c['improvement']:.1%}", "yes" if c.get("significant") else "no",
                 c.get("reason", "")] for c in rep.get("all_candidates", [])]
        base = path[:-len("_diagnose.json")]
        figs = [p for p in (f"{base}_where.png", f"{base}_where_final.png", f"{base}_ladder.png") if os.path.isfile(p)]
        parts += [f"<section class='diagnosis'><h2>diagnosis of {escape(rep['model'])} on {escape(rep['record'])}</h2>",
                  f"<p>{escape(rep.get('verdict', ''))}</p>",
                  table(["effect", "OF", "lower by", "credited", "why not"], rows,
                        f"OF {rep['of']:.5g}, noise floor {rep['noise_floor_of']:.4g}"),
                  *([zero_table(rep["force_zero"])] if rep.get("force_zero") else []),
                  *[_image(p, os.path.basename(p)) for p in figs], "</section>"]
    return "\n".join(parts)


def _compare_sections(out: str) -> str:
    parts = []
    for path in sorted(glob.glob(os.path.join(out, "*_compare.json"))):
        rep = _json(path)
        rows = [[os.path.basename(m["file"]), m["model"], m.get("device") or "", short(m.get("of")),
                 short(m.get("of_calibration")), short(m.get("peak_force_kN"))] for m in rep.get("models", [])]
        figure = path[:-len(".json")] + ".png"
        parts += [f"<section class='compare'><h2>calibrated models on {escape(os.path.basename(rep['record']))}</h2>",
                  table(["file", "model", "device", "OF here", "OF on its calibration", "peak force [kN]"], rows,
                        "prediction only (no measured force)" if rep.get("prediction_only") else
                        "best first (OF, eq. 18)"),
                  *([_image(figure, os.path.basename(figure))] if os.path.isfile(figure) else []), "</section>"]
    return "\n".join(parts)


def _frame_section(out: str) -> str:
    summary = _json(os.path.join(out, "frame_summary.json"))
    if summary is None:
        return ""
    figs = sorted(glob.glob(os.path.join(out, "figures", "*.png")))
    caption = f"{summary.get('building', '')} under {summary.get('motion', '')} (PGA {summary.get('pga_g', 0):.3g} g)"
    return "\n".join(["<section id='frame'><h2>frame analysis</h2>",
                      f"<p>{escape(str(summary.get('verdict', '')))}</p>",
                      _csv_table(out, "frame_table.csv", caption),
                      *[_image(p, os.path.basename(p)) for p in figs], "</section>"])


def _tolerance_of_page(path: str) -> float | None:
    """The acceptance tolerance the page at ``path`` was built with; None when there is none."""
    if not os.path.isfile(path):
        return None
    with open(path) as fh:
        found = re.search(r"<meta name='fvd-tolerance' content='([0-9.eE+-]+)'>", fh.read(4096))
    return float(found.group(1)) if found else None


def build_report(out: str, tolerance: float | None = None, shown_as: str | None = None, plugins=()) -> str:
    """Write ``out``/report.html from the folder's files (calibration files,
    summary.json, a diagnosis', a comparison's or a frame's JSON, exports.json,
    figures) with the acceptance checks at ``tolerance`` (a share; None: the
    one the page there was built with, else ``TOLERANCE``); ``shown_as``: the
    folder the page names (a verb builds it in its staging folder);
    ``plugins``: the plugin files its calibrations' models need; returns its path."""
    path = os.path.join(out, "report.html")
    if tolerance is None:
        tolerance = _tolerance_of_page(path) or TOLERANCE
    cals = _calibrations(out, plugins)
    series = _series_nominal(cals)
    body = [_series_section(out), *[_device_section(out, dev, c, series, tolerance) for dev, c in cals.items()],
            _diagnosis_sections(out), _compare_sections(out)]
    if not cals and not any(body):
        body.append(_frame_section(out))
    title = f"fvd_bridge report: {os.path.basename(os.path.abspath(shown_as or out))}"
    page = (f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>{escape(title)}</title>"
            f"<meta name='fvd-tolerance' content='{tolerance!r}'>"
            f"<style>{STYLE}</style></head><body><h1>{escape(title)}</h1>"
            f"<p>fvd_bridge {__version__}; units kN, mm, s. Devices: "
            + ", ".join(f"<a href='#device-{escape(d)}'>{escape(d)}</a>" for d in cals) + "</p>"
            + "\n".join(b for b in body if b) + "</body></html>")
    with atomic_file(path) as fh:
        fh.write(page)
    return path
