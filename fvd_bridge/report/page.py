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

import glob
import os
import re
import shlex
from html import escape

import numpy as np

from .._version import __version__
from ..calibration import Calibration, common_tests, same_data
from ..io.staging import atomic_file, safe_name
from ..diagnose.where import analyse, summary_lines
from ..fit import noise_floor
from ..fit.objective import AT_FLOOR, EXPLAINS_LITTLE, NEAR_FLOOR
from ..errors import InputError, PluginNeeded
from ..export.ledger import exports_of
from ..model import EXPORT_TARGETS, export_step
from ..records.readers import read_as_stored
from ..records.cycles import force_noise
from .acceptance import TOLERANCE, checks_of_test
from .html import calibration_table, table, zero_table
from .numbers import rounded, share, small_share
from .frame_page import frame_section
from .parts import figure, read_json
from .series_page import series_section

STYLE = """body{font-family:system-ui,sans-serif;max-width:1200px;margin:2em auto;padding:0 1em;color:#222}
.scroll{overflow-x:auto;max-width:100%;margin:.6em 0 1.2em}table.fvd{border-collapse:collapse}
table.fvd{font-size:.92em}table.fvd td,table.fvd th{border:1px solid #ccc;padding:.2em .5em;text-align:left;
vertical-align:top}table.fvd td{white-space:nowrap}table.fvd td.note{white-space:normal;min-width:14em}
table.fvd caption{text-align:left;font-weight:600;padding:.3em 0;white-space:normal}
.pass{color:#176b2c}.fail{color:#b00020;font-weight:600}.na{color:#666}
img{max-width:100%;border:1px solid #eee}figure{margin:.5em 0 1.5em}figcaption{color:#444;font-size:.9em}
section.device,section.diagnosis,section#series{border-top:2px solid #336;margin-top:2em}
p.answer{font-size:1.1em;background:#f3f6fb;border-left:4px solid #336;padding:.5em .8em}
pre.next{background:#f6f6f6;padding:.5em .8em;white-space:pre-wrap;word-break:break-all}"""


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
    common = [records[t.name] for t in common_tests(cals) if records.get(t.name) is not None]
    if common:
        names = ", ".join(r.name for r in common)
        return min(cals, key=lambda c: np.mean([c.of_on(r) for r in common])), f"the lowest OF on {names}"
    return cals[0], "fitted to different tests: not ranked, the first file's"


def _floor(records: dict, cal=None) -> float | None:
    """The OF the measurement noise alone gives: the records' floor the
    calibration's search was judged by (``fit.floor``, the number its report
    gives beside the OF), else its bootstrap's (force and displacement noise
    through the measurement chain), else the records' force noise alone
    (``fit.noise_floor``, the mean over the tests as the OF is); None
    without any."""
    if cal is not None and cal.solver is not None and cal.solver.floor:
        return float(cal.solver.floor)
    noise_of = cal.intervals.noise_of if cal is not None and cal.intervals else None
    if noise_of is not None and np.isfinite(noise_of) and noise_of > 0:
        return float(noise_of)
    floors = [noise_floor(force_noise(rec.F), rec.F) for rec in records.values() if rec is not None]
    return float(np.mean(floors)) if floors else None


def _how_good(of: float, floor: float | None) -> str:
    """The OF against the noise floor, in words."""
    if floor is None or floor <= 0:
        return f"OF {rounded(of)} (the records are not found: no noise floor to hold it against)"
    ratio = of / floor
    if of > EXPLAINS_LITTLE:
        return (f"OF {rounded(of)}: the model explains little of the measured force (beyond {EXPLAINS_LITTLE}; "
                f"a force of zero scores 0.9 on a sine test): check the record's columns, units and sign, and the law")
    said = (f"OF {rounded(of)}, {rounded(ratio, digits=2)}x the noise floor of its record(s) ({rounded(floor)}, "
            f"the OF the measurement noise alone gives)")
    if ratio <= AT_FLOOR:
        return said + ": it explains the record down to the measurement noise"
    if ratio <= NEAR_FLOOR:
        return said + ": close to the noise, little is left to explain"
    return said + ": it misses part of the record (where it fails, below; diagnose shows what is missing)"


#: a record block's reading options as the command line spells them
OPTIONS = (("mat_var", "--mat-var"), ("columns", "--columns"), ("units", "--units"), ("dt", "--dt"),
           ("force_sign", "--force-sign"), ("sg_window", "--sg-window"), ("sg_order", "--sg-order"))


def _reading(source) -> list:
    """The command-line words that read a calibration's record (its RecordSource) as it was read."""
    reading, words = source.reading or {}, []
    for key, option in OPTIONS:
        value = reading.get(key)
        if value in (None, {}, ""):
            continue
        text = ",".join(f"{k}={v}" for k, v in value.items()) if isinstance(value, dict) else str(value)
        words += [option, shlex.quote(text)]
    if source.window:
        words += ["--window", ",".join(rounded(x, digits=6) for x in source.window)]
    return words


def _next_commands(cal, device: str, shown: str, out: str, floor: float | None) -> list:
    """What to run next with the calibration: export it (to OpenSees where a
    material holds it, else to an FMU); where its OF is beyond the noise,
    diagnose what it misses, on the same records read the same way."""
    path = shlex.quote(os.path.join(shown, os.path.relpath(cal.path, out))) if cal.path else "PARAMS.yaml"
    lines = [export_step(cal.model.exports(cal.named()), path)]
    sources = [t.record for t in cal.tests]
    if (floor is None or cal.of > NEAR_FLOOR * floor) and all(s.file for s in sources) and sources:
        files = [shlex.quote(s.file) for s in sources]
        one = ["--device", shlex.quote(device)] if len(files) > 1 else []
        where = shlex.quote(os.path.join(os.path.dirname(os.path.normpath(shown)) or ".", f"diagnose_{device}"))
        lines.append(" ".join(["fvd-bridge diagnose", *files, *one, *_reading(sources[0]),
                               f"--law {cal.spec}", f"--out {where}"]))
    return lines


def _next(lines: list) -> str:
    return ("<h3>next</h3><pre class='next'>" + "\n".join(escape(line) for line in lines) + "</pre>") if lines else ""


def _acceptance(device: str, cals: list, series: dict, records: dict, tolerance: float) -> str:
    """The device's acceptance table: its tests checked against the series'
    best model (``_best``: the lowest OF on the same data) as the nominal;
    every row names its rule and source; a rule that does not apply says why."""
    best, chosen = _best(cals, records)
    rows, notes = [], []
    size = len(series[best.spec])
    for test in best.tests:
        rec = records.get(test.name)
        if rec is None:
            notes.append(f"{test.name}: its record file is not found; no acceptance checks")
            continue
        rows += checks_of_test(rec, _series_force(series[best.spec], rec), tolerance, size)
    caption = (f"acceptance of {device}: tolerance +-{share(tolerance)}; nominal force: law {best.spec} ({chosen}) "
               f"of the series ({size} device(s)) at each test's velocity")
    if not rows:
        return f"<h3>acceptance</h3><p>{escape(caption)}: no check made.</p>" + "".join(f"<p>{escape(n)}</p>" for n in notes)
    verdict_css = {"pass": "pass", "FAIL": "fail", "not applicable": "na"}
    body = "".join(
        f"<tr><td>{escape(c.test)}</td><td class='note'>{escape(c.what)}</td><td>{rounded(c.measured)}</td>"
        f"<td>{rounded(c.reference)}</td><td>{'-' if c.deviation is None else share(c.deviation)}</td>"
        f"<td class='{verdict_css[c.verdict]}'>{c.verdict}</td><td class='note'>{escape(c.rule)} "
        f"({escape(c.source)}){escape('. Not applicable: ' + c.why_not if c.why_not else '')}</td></tr>"
        for c in rows)
    out = (f"<div class='scroll'><table class='fvd acceptance'><caption>{escape(caption)}</caption><thead><tr>"
           f"<th>test</th><th>check</th><th>measured</th><th>reference</th><th>deviation</th><th>verdict</th>"
           f"<th>rule (source)</th></tr></thead><tbody>{body}</tbody></table></div>")
    return "<h3>acceptance</h3>" + out + "".join(f"<p>{escape(n)}</p>" for n in notes)


def _tests_table(cals: list, records: dict) -> str:
    """Each test's range, its noise-floor OF (the record's force noise alone) and each model's OF on it."""
    rows = []
    for t in cals[0].tests:
        source, rng, rec = t.record, t.range, records.get(t.name)
        floor = None if rec is None else noise_floor(force_noise(rec.F), rec.F)
        ofs = [next((u.of for u in c.tests if u.name == t.name), None) for c in cals]
        rows.append([t.name, source.samples or "-", rounded(source.dt), rounded(rng.get("d")),
                     rounded(rng.get("v")), rounded(rng.get("f")), rounded(source.peaks.F),
                     rounded(floor, digits=3), *[rounded(x) for x in ofs]])
    return table(["test", "samples", "dt [s]", "stroke [mm]", "velocity [mm/s]", "frequency [Hz]",
                  "peak force [kN]", "noise-floor OF", *[f"OF of law {c.spec}" for c in cals]], rows,
                 "the tests: their range, the OF their noise alone gives, and each model's OF on them")


def _where_list(cal, records: dict) -> str:
    """Where the model fails on each test: diagnose's findings (``diagnose.where``)."""
    parts = []
    for name, rec in records.items():
        if rec is None:
            continue
        F = cal.force(rec, test=cal.test_named(name))
        lines = summary_lines(analyse(rec, F), force_noise(rec.F))
        parts.append(f"<p><b>law {escape(cal.spec)} on {escape(name)}</b></p><ul>"
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
            rows.append([cal.spec, name, "exact" if res.exact else "approximate", rounded(res.of, digits=3),
                         rounded(res.bound, digits=3), "within its bound" if res.ok else "OUTSIDE its bound"])
    parts = [table(["model", "test", "OpenSees mapping", "OF(OpenSees vs model)", "bound", "verdict"], rows,
                   "each model's OpenSees material driven with the test's motion (kN, mm, s; eq. 18 with the "
                   "model's force as reference)") if rows else ""]
    made = []
    for e in exports_of(out):
        if e.get("device") == device:
            check = e.get("check") or {}
            made.append([e["kind"], e["model"], os.path.basename(e["file"]), e["units"],
                         check.get("record", "not checked"), rounded(check.get("of"), digits=3),
                         rounded(check.get("bound"), digits=3), e["written"]])
    if made:
        parts.append(table(["export", "model", "file", "units", "checked on", "OF(export vs model)", "bound",
                            "written"], made, "the exports made (fvd-bridge export)"))
    return ("<h3>exports</h3>" + "\n".join(p for p in parts if p)) if any(parts) else ""


def _loop_figures(out: str, device: str, cal) -> list:
    """The calibration's loop figures, by the names ``campaign.outputs`` gives them."""
    names = [f"loops_{t.name if len(cal.tests) == 1 else device + '_' + t.name}_law{cal.spec}.png"
             for t in cal.tests]
    return [p for p in (os.path.join(out, "figures", n) for n in names) if os.path.isfile(p)]


def _device_section(out: str, shown: str, device: str, cals: list, series: dict, tolerance: float,
                    diagnosed: bool = False) -> str:
    """One device, the answer first: the model to use and how good it is
    against the noise floor, its parameters, its loops, where it fails, the
    next command; then the other models, the tests, acceptance and exports."""
    records = {t.name: read_as_stored(t.record, t.name) for t in cals[0].tests}  # None: its file is gone
    best, chosen = _best(cals, records)
    told = read_json(os.path.join(out, f"{safe_name(device)}_diagnose.json")) if diagnosed else None
    floor = (told or {}).get("noise_floor_of") or _floor(records, best)  # a diagnosis' floor: the record's
    lead = ("the calibration diagnose wrote" if diagnosed and len(cals) == 1 else
            "the best of the calibrations diagnose wrote" if diagnosed else "use")
    why = f"{chosen} of {len(cals)} models" if len(cals) > 1 else "the one model calibrated"
    parts = [f"<section class='device' id='device-{escape(device)}'><h2>device {escape(device)}</h2>",
             f"<p class='answer'><b>{escape(lead.capitalize())} law {escape(best.spec)}</b> ({escape(why)}): "
             f"{escape(_how_good(best.of, floor))}.</p>",
             calibration_table(best), *[figure(p) for p in _loop_figures(out, device, best)]]
    where = _where_list(best, records)
    if where:
        parts += [f"<h3>where law {escape(best.spec)} fails</h3>", where]
    parts.append(_next(_next_commands(best, device, shown, out, floor)))
    others = [c for c in cals if c is not best]
    if others:
        parts.append("<h3>the other models</h3>")
        for cal in others:
            parts += [calibration_table(cal), *[figure(p) for p in _loop_figures(out, device, cal)]]
    parts += ["<h3>the tests</h3>", _tests_table(cals, records),
              _acceptance(device, cals, series, records, tolerance), _exports(out, device, cals, records), "</section>"]
    return "\n".join(p for p in parts if p)


def _diagnosis_sections(out: str) -> str:
    """Each diagnosis, its verdict first: the verdict, the model's OF against
    the noise floor, the next command; then the candidates, each named as the
    model it is, the force zero and the figures."""
    parts = []
    for path in sorted(glob.glob(os.path.join(out, "*_diagnose.json"))):
        rep = read_json(path)
        model = rep["model"]
        rows = [[c.get("spec") or f"{model}+{c['effect']}", rounded(c["of"]), small_share(c["improvement"]),
                 "yes" if c.get("significant") else "no", c.get("reason", "")] for c in rep.get("all_candidates", [])]
        base = path[:-len("_diagnose.json")]
        figs = [p for p in (f"{base}_where.png", f"{base}_where_final.png", f"{base}_ladder.png") if os.path.isfile(p)]
        files = rep.get("calibrations") or {}
        target = rep.get("target")
        best = next((c for c in rep.get("all_candidates", []) if c.get("significant") and c.get("calibration")
                     and (target is None or target in (c.get("exports") or []))), None)
        step = best and export_step({t: "" if t in best.get("exports", []) else "no" for t in EXPORT_TARGETS},
                                    shlex.quote(best["calibration"]), target)
        lines = [step] if step else []
        parts += [f"<section class='diagnosis'><h2>diagnosis of {escape(model)} on {escape(rep['record'])}</h2>",
                  f"<p class='answer'><b>Verdict:</b> {escape(rep.get('verdict', ''))}</p>",
                  _target_line(target, rep.get("left_out")),
                  f"<p>law {escape(model)} alone: {escape(_how_good(rep['of'], rep.get('noise_floor_of')))}."
                  + (f" Calibration files written: {escape(', '.join(files.values()))}." if files else "") + "</p>",
                  _next(lines),
                  table(["model", "OF", "lower by", "credited", "why (not)"], rows,
                        f"each effect added to law {model} and refitted (law {model} alone: OF {rounded(rep['of'])}, "
                        f"noise floor {rounded(rep['noise_floor_of'])})") if rows else "",
                  zero_table(rep["force_zero"], model) if rep.get("force_zero") else "",
                  *[figure(p) for p in figs], "</section>"]
    return "\n".join(p for p in parts if p)


def _target_line(target: str | None, left: dict | None) -> str:
    """Where the diagnosis was told the model must go (diagnose --target), and what that left out."""
    if not target:
        return ""
    name = EXPORT_TARGETS.get(target, target)
    out = f"<b>Target:</b> {escape(name)}: only what exports there is suggested"
    if left:
        out += (f"; left out: {escape(left['spec'])} (OF {rounded(left['of'])}), which does not reach "
                f"{escape(name)}: {escape(left['why'])}")
    return f"<p>{out}.</p>"


def _compare_sections(out: str) -> str:
    parts = []
    for path in sorted(glob.glob(os.path.join(out, "*_compare.json"))):
        rep = read_json(path)
        measured = rep.get("measured")  # older comparisons: none, and no energy
        per_cycle = rep.get("cycles") is not None
        energy_key = "energy_per_cycle_kNmm" if per_cycle else "energy_kNmm"

        def of_measured(m, key):
            ref = (measured or {}).get(key)
            return share(m.get(key) / ref, digits=3) if ref and m.get(key) is not None else ""

        rows = [[os.path.basename(m["file"]), m["model"], m.get("device") or "", rounded(m.get("of")),
                 rounded(m.get("of_calibration")), rounded(m.get("peak_force_kN")), of_measured(m, "peak_force_kN"),
                 rounded(m.get(energy_key)), of_measured(m, energy_key)] for m in rep.get("models", [])]
        if measured:
            rows.insert(0, ["measured", "", "", "", "", rounded(measured["peak_force_kN"]), "",
                            rounded(measured.get(energy_key)), ""])
        energy = ("energy per cycle [kN mm = J]" if per_cycle else "energy, total [kN mm = J]")
        if per_cycle:
            how = (f"energy per cycle: the integral of F dd over the record / its {rep['cycles']:.3g} "
                   f"displacement cycles")
        elif any("energy_kNmm" in m for m in rep.get("models", [])):
            how = "energy: the integral of F dd over the record (d reverses fewer than twice: no cycles to count)"
        else:
            how = "no energy (a comparison written before it was computed)"
        png = path[:-len(".json")] + ".png"
        parts += [f"<section class='compare'><h2>calibrated models on {escape(os.path.basename(rep['record']))}</h2>",
                  table(["file", "model", "device", "OF here", "OF on its calibration", "peak |F| [kN]",
                         "of measured", energy, "of measured"], rows,
                        f"prediction only (no measured force); {how}" if rep.get("prediction_only") else
                        f"the measured force first, then the models best first (OF, eq. 18); {how}"),
                  *([figure(png)] if os.path.isfile(png) else []), "</section>"]
    return "\n".join(parts)


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
    ``plugins``: the plugin files its calibrations' models need; returns its path.

    The page leads with the answer: a diagnosis' verdict, else each device's
    model to use; the series' material follows its devices, and only for two
    devices or more; a section with nothing to show is left out."""
    path = os.path.join(out, "report.html")
    if tolerance is None:
        tolerance = _tolerance_of_page(path) or TOLERANCE
    shown = shown_as or out
    cals = _calibrations(out, plugins)
    series = _series_nominal(cals)
    diagnoses = _diagnosis_sections(out)
    body = [diagnoses, *[_device_section(out, shown, dev, c, series, tolerance, bool(diagnoses))
                         for dev, c in cals.items()],
            series_section(out), _compare_sections(out)]
    if not cals and not any(body):
        body.append(frame_section(out))
    title = f"fvd_bridge report: {os.path.basename(os.path.abspath(shown))}"
    devices = ("; devices: " + ", ".join(f"<a href='#device-{escape(d)}'>{escape(d)}</a>" for d in cals)) if cals else ""
    page = (f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>{escape(title)}</title>"
            f"<meta name='fvd-tolerance' content='{tolerance!r}'>"
            f"<style>{STYLE}</style></head><body><h1>{escape(title)}</h1>"
            f"<p>fvd_bridge {__version__}; units kN, mm, s{devices}</p>"
            + "\n".join(b for b in body if b) + "</body></html>")
    with atomic_file(path) as fh:
        fh.write(page)
    return path
