"""What a frame analysis answers, in a few lines, and its notes, each kind once.

The report page opens with ``answer_lines`` and the terminal ends with them
(issue 41): the damper (model, device, how many per story, its factor on
the device's force and, where the dampers were sized, each story's force at
its design velocity), the peak drift and damper force (with ``--property-bounds``
the envelope and the bound that governs each), the supplemental damping of
the first mode (achieved against the target where sized) and whether the
dampers stayed inside what their calibration tested.  The numbers are the
verdict's (``verdict.choice``: the model it reports; ``bounds.envelope``),
to three significant digits.

``grouped_notes`` gathers the cases' notes by kind (one quantity beyond the
tested range, one limit given and exceeded, a solver's stop, how the
models run, a model skipped): one note per kind, naming the cases it
concerns and the range of their values, where the table gave one note per
case and value.  ``case_names``: each case's short name (the model, the part
of a long device name that differs, the bound), as the tables show it.
"""

from __future__ import annotations

import re

import numpy as np

from ..report.names import common_form, distinct
from ..report.numbers import rounded, share
from . import property_bounds as damper_bounds
from .verdict import SMALL_DAMPING, VERDICT_TOLERANCE, choice, nominal

#: significant digits of the answer's numbers
DIGITS = 3
#: the bounds as the answer names them
BOUND_NAMES = {"nominal": "nominal", "upper": "upper bound", "lower": "lower bound"}
#: the notes' kinds in the order the notes list them
ORDER = ("beyond", "given", "solver", "run", "skipped")


def _damped(cases) -> list:
    return [c for c in cases if c.spec is not None]


def case_names(cases) -> dict:
    """{label: short name}: 'law 2+friction | …0042… | upper bound' (the
    device only where the cases hold several, as its distinct part)."""
    devices = distinct(c.device for c in cases if c.spec is not None)
    several = len(devices) > 1
    out = {}
    for c in cases:
        if c.spec is None:
            out[c.label] = c.label
            continue
        out[c.label] = " | ".join([f"law {c.spec}", *([devices[c.device]] if several else []),
                                   *([BOUND_NAMES[c.bound]] if c.bound else [])])
    return out


def _span(values, digits: int | None = None, unit: str = "") -> str:
    """'46.66-46.71 mm', or '46.7 mm' where the values read alike."""
    values = [float(v) for v in values if v is not None and np.isfinite(v)]
    if not values:
        return "n/a"
    low, high = rounded(min(values), digits=digits), rounded(max(values), digits=digits)
    body = low if low == high else f"{low}-{high}"
    return body + ("" if not unit else unit if unit == "%" else f" {unit}")


def _hz(values) -> str:
    """'2 Hz', '0.977-1.02 Hz' (three significant digits, as the tested range's band)."""
    low, high = f"{min(values):.3g}", f"{max(values):.3g}"
    return f"{low} Hz" if low == high else f"{low}-{high} Hz"


def _share_span(values, digits: int = 2) -> str:
    """'19.7%', or '16.2-23.4%'."""
    values = [v for v in values if v is not None and np.isfinite(v)]
    if not values:
        return "n/a"
    low, high = share(min(values), digits), share(max(values), digits)
    return low if low == high else f"{low[:-1]}-{high}"


def cases_text(concerned, cases) -> str:
    """The cases a note or an answer concerns, short: 'every damper case',
    'law 2+friction (all 3)', 'law 2+friction (lower bound); law 9 (lower bound)'."""
    names = case_names(cases)
    damped = [c for c in _damped(cases) if c.result is not None]
    concerned = list({c.label: c for c in concerned}.values())
    labels = {c.label for c in concerned}
    if len(damped) > 1 and {c.label for c in damped} <= labels:
        return "every damper case"
    for bound in ("upper", "lower", "nominal"):
        of_bound = {c.label for c in damped if c.bound == bound}
        if len({c.spec for c in damped}) > 1 and of_bound == labels:
            return f"every model's {BOUND_NAMES[bound]}"
    parts = []
    for spec in dict.fromkeys(c.spec for c in concerned):
        mine = [c for c in concerned if c.spec == spec]
        of_model = [c for c in damped if c.spec == spec]
        if len(mine) >= len(of_model):
            parts.append(f"law {spec}" + (f" (all {len(mine)})" if len(mine) > 1 else ""))
        else:
            rest = [names[c.label][len(f"law {spec} | "):] for c in mine]
            parts.append(f"law {spec} ({', '.join(rest)})")
    return "; ".join(parts)


def _kind(item: dict) -> tuple:
    return ("beyond" if item["against"] == "tested" else "given", item["quantity"])


def _beyond_text(kind: tuple, entries: list, cases) -> str:
    """One note of a quantity beyond the tested range or a given limit (``Case.beyond`` items)."""
    concerned = cases_text([c for c, _ in entries], cases)
    items = [item for _, item in entries]
    quantity, unit = kind[1], items[0]["unit"]
    where = common_form(item["where"] for item in items if item["where"])
    if quantity == "frequency":
        tested = _hz([x for item in items for x in item["limit"]])
        return (f"the dampers' dominant frequency {_hz([i['value'] for i in items])} is outside the {tested} "
                f"tested on {where}: an extrapolation ({concerned})")
    values = _span([i["value"] for i in items], unit=unit)
    limits = _span([i["limit"] for i in items], unit=unit)
    if kind[0] == "given":
        return f"peak damper {quantity} {values} exceeds the {limits} limit given ({concerned})"
    times = " times the damper's force factor" if quantity == "force" else ""
    return (f"peak damper {quantity} {values} is beyond the {limits} tested on {where}{times}: an "
            f"extrapolation ({concerned})")


def grouped_notes(cases) -> list[dict]:
    """The cases' notes, one per kind: [{'text', 'kind' ('beyond': the
    tested range, 'given': a limit given, 'solver', 'run', 'skipped'),
    'cases': [labels]}] (module doc)."""
    groups: dict = {}

    def add(key, case, what):
        groups.setdefault(key, []).append((case, what))

    for c in _damped(cases):
        if c.result is None:
            add(("skipped",), c, c.note)
            continue
        for item in c.beyond:
            add(_kind(item), c, item)
        if c.result.solver.message:  # alike messages (their numbers apart) are one kind
            add(("solver", re.sub(r"\d+(\.\d+)?", "#", c.result.solver.message)), c, c.result.solver.message)
        if c.note and not c.exact:
            add(("run",), c, c.note)
    notes = []
    for key in sorted(groups, key=lambda k: ORDER.index(k[0])):
        entries = groups[key]
        concerned = [c for c, _ in entries]
        if key[0] in ("beyond", "given"):
            text = _beyond_text(key, entries, cases)
        elif key[0] == "solver":
            first = [c for c, message in entries if message == entries[0][1]]
            rest = [c for c, message in entries if message != entries[0][1]]
            text = f"{entries[0][1]} ({cases_text(first, cases)})" + (
                f"; alike, with their own times and values, in {cases_text(rest, cases)}" if rest else "")
        else:
            per_model = {}
            for c, note in entries:
                per_model.setdefault(c.spec, [])
                if note not in per_model[c.spec]:
                    per_model[c.spec].append(note)
            said = "; ".join(f"law {spec}: {texts[0]}" + (f" (each of its {len(texts)} devices with its own "
                                                           f"values)" if len(texts) > 1 else "")
                             for spec, texts in per_model.items())
            text = (f"how the models run in the frame: {said}" if key[0] == "run" else
                    f"skipped, neither OpenSees nor the FMU carries it: {said}")
        notes.append({"text": text, "kind": key[0], "cases": list(dict.fromkeys(c.label for c in concerned))})
    return notes


def _few(concerned, cases) -> str:
    """The cases an answer's line concerns: ``cases_text`` where it is short, else 'N of M damper cases'."""
    said = cases_text(concerned, cases)
    if len(said) <= 40:
        return said
    n = len({c.label for c in concerned})
    return f"{n} of {len([c for c in _damped(cases) if c.result is not None])} damper cases"


def _see(notes: list, kinds: tuple) -> str:
    """' (notes 1, 2)': the notes of these kinds, for the answer to point at."""
    found = [str(k) for k, n in enumerate(notes, start=1) if n["kind"] in kinds]
    return f" (note{'s' if len(found) > 1 else ''} {', '.join(found)})" if found else ""


def _damper_line(spec: str, pick: dict, spread: dict, mine: list, settings: dict) -> str:
    """'Damper: law 2 (best fit), 1 per story: DEVICE x9.76 in force, 2560/2830/2730 kN at ... mm/s (stories 1/2/3).'"""
    who = f"law {spec}"
    if len(spread) > 1:
        if pick["best"] is None:
            who += " (not ranked: fitted to different tests; the simplest)"
        elif pick["simplest"] != spec:
            who += f" (best fit; law {pick['simplest']}, simpler, within {VERDICT_TOLERANCE:.0%})"
        else:
            who += " (best fit)"
    devices = list(dict.fromkeys(c.device for c in mine))
    device = devices[0] if len(devices) == 1 else f"any of {len(devices)} devices {common_form(devices)}"
    n = settings.get("dampers_per_story", 1)
    factors = [c.scale for c in mine]
    factor = "" if np.allclose(factors, 1.0) else f" x{_span(factors, digits=DIGITS)} in force"
    line = f"Damper: {who}, {n} per story: {device}{factor}"
    sized = [c for c in mine if c.design is not None and c.design.target is not None]
    if sized:
        # per story, over the model's devices: the force at the design velocity of the damper as it runs
        force = [[s.force * c.scale for s, c in zip(story, sized)] for story in zip(*(c.design.stories for c in sized))]
        velocity = [s.velocity for s in sized[0].design.stories]
        if len(force) <= 4:
            line += (f", {'/'.join(_span(f, digits=DIGITS) for f in force)} kN at "
                     f"{'/'.join(rounded(v, digits=DIGITS) for v in velocity)} mm/s "
                     f"(stories {'/'.join(str(k) for k in range(1, len(force) + 1))})")
        else:
            line += (f", {_span(sum(force, []), digits=DIGITS)} kN at {_span(velocity, digits=DIGITS)} mm/s "
                     f"over the {len(force)} stories")
    return line + "."


def _response_line(spec: str, spread: dict, env: dict | None, bare: dict | None) -> str:
    """'Peak drift and force: 1.30% (lower bound governs; bare frame 2.38%) and 2500 kN per damper (...).'"""
    bare_drift = (f"bare frame {rounded(bare['drift'], digits=DIGITS)}%"
                  if bare is not None and np.isfinite(bare["drift"]) else "")
    if env is None:
        s = spread[spec]
        return (f"Peak drift and force: {_span(s['drift'][::2], digits=DIGITS, unit='%')}"
                f"{f' ({bare_drift})' if bare_drift else ''} and {_span(s['force'][::2], digits=DIGITS, unit='kN')} "
                f"per damper.")
    d, f = env["drift"], env["force"]
    drift = "; ".join(x for x in (f"{BOUND_NAMES[d['governing']]} governs", bare_drift) if x)
    return (f"Peak drift and force: {rounded(d['envelope'], digits=DIGITS)}% ({drift}) and "
            f"{rounded(f['envelope'], digits=DIGITS)} kN per damper ({BOUND_NAMES[f['governing']]} governs).")


def _damping_line(spec: str, cases, target, resize: str | None) -> str:
    """'Damping: 19.7% of critical achieved for the 20% target (bounds 16.2-23.4%).'"""
    mine = [c for c in _damped(cases) if c.spec == spec and c.result is not None and c.design is not None]
    if not mine:
        return ""
    own = nominal(mine)
    if target is not None:
        got = [c.achieved for c in own]
        if not any(x is not None and np.isfinite(x) for x in got):
            return (f"Damping: not measured for the {share(target)} target (the decay did not reach the design "
                    f"amplitude).")
        line = f"Damping: {_share_span(got, 3)} of critical achieved for the {share(target)} target"
        others = [c.achieved for c in mine if c.bound in ("upper", "lower")]
        if others:
            line += f" (bounds {_share_span(others, 3)})"
        return line + "."
    xi = [c.design.damping for c in own]
    line = (f"Damping: the dampers add {_share_span(xi)} of critical to the first mode (energy method at roof "
            f"drift {share(own[0].design.roof_drift)})")
    if max(xi) < SMALL_DAMPING:
        line += ": too small to matter; size them" + (f": {resize}" if resize else " (frame --target-damping 0.20)")
    return line + "."


def _tested_line(cases, notes: list) -> str:
    """'Inside what was tested ...', or what went beyond it, in which cases (``Case.beyond``)."""
    ran = [c for c in _damped(cases) if c.result is not None]
    if not ran:
        return ""
    kinds: dict = {}
    for c in ran:
        for item in c.beyond:
            kinds.setdefault(_kind(item), []).append((c, item))
    parts = {"beyond": [], "given": []}
    for (against, quantity), entries in kinds.items():
        items = [i for _, i in entries]
        if quantity == "frequency":
            values, limit = _hz([i["value"] for i in items]), _hz([x for i in items for x in i["limit"]])
        else:
            values = f"up to {rounded(max(i['value'] for i in items), digits=DIGITS)} {items[0]['unit']}"
            limit = _span([i["limit"] for i in items], digits=DIGITS, unit=items[0]["unit"])
        parts[against].append(f"{quantity} {values}, {'tested' if against == 'beyond' else 'limit'} {limit}, "
                              f"in {_few([c for c, _ in entries], cases)}")
    if parts["beyond"]:
        said = [f"Beyond what was tested: {'; '.join(parts['beyond'])}: an extrapolation{_see(notes, ('beyond',))}."]
    else:
        said = ["Inside what was tested: stroke, velocity, frequency and force within the calibration's tests."]
    if parts["given"]:
        said.append(f"Beyond the limits given: {'; '.join(parts['given'])}{_see(notes, ('given',))}.")
    return " ".join(said)


def _left_out_line(cases, notes: list) -> str:
    """'Left out: law 1 | upper bound, stopped at 1.3 s; law 7 skipped (notes 2, 3).'"""
    names = case_names(cases)
    stopped = [c for c in _damped(cases) if c.result is not None and not c.result.solver.completed]
    skipped = [c for c in _damped(cases) if c.result is None]
    said = [f"{names[c.label]}, stopped at {c.result.solver.failed_at or c.result.t[-1]:.1f} s" for c in stopped]
    said += [f"{names[c.label]}, skipped" for c in skipped]
    return f"Left out: {'; '.join(said)}{_see(notes, ('solver', 'skipped'))}." if said else ""


def answer_lines(cases, spread: dict, settings: dict | None = None, resize: str | None = None,
                 notes: list | None = None) -> list[str]:
    """The answer (module doc), one line each; ``settings`` the run's
    (dampers per story, target damping), ``resize`` the command that sizes
    dampers too small to matter, ``notes`` the ``grouped_notes`` it points
    at (default: the cases')."""
    settings = settings or {}
    notes = grouped_notes(cases) if notes is None else notes
    pick = choice(spread, cases)
    if not pick:
        return [line for line in ("No damper model ran to the end.", _left_out_line(cases, notes)) if line]
    spec = pick["shown"]
    mine = [c for c in nominal(cases) if c.spec == spec and c.result is not None and c.result.solver.completed]
    env = damper_bounds.envelope(cases).get(spec)
    bare = next((c.values() for c in cases if c.spec is None and c.result is not None), None)
    lines = [_damper_line(spec, pick, spread, mine, settings), _response_line(spec, spread, env, bare),
             _damping_line(spec, cases, settings.get("target_damping"), resize), _tested_line(cases, notes),
             _left_out_line(cases, notes)]
    return [line for line in lines if line]
