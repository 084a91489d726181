"""The magnitudes a damper test has, written once, and the doubt of a file
read without units whose magnitudes no damper test has.

A file that gives no units (no ``--units``, no sidecar ``units``, no header
unit such as ``F [kN]``) is read as kN, mm, s. Its peak force |F| [kN], its
stroke (peak |d| about the median [mm]) and their ratio [kN/mm] are held
against the ranges below; outside them the file is in other units (N read
as kN: 1000x the force; m read as mm: 1/1000 the stroke) and a fit of it
would be silently wrong. Units a file or the caller states are never
second-guessed here (only ABSURD holds for them).

Sources of the ranges:

- force: the largest fluid viscous dampers built are about 8,000-9,000 kN
  (Taylor Devices' 2,000-kip class, for long-span bridges); the paper's
  FVDs reach about 290 kN, the shared friction damper 16 kN, the shared MR
  damper 1-2 kN. No damper test reaches FORCE_MAX_KN = 10,000 kN.
- stroke: prototype and production tests (EN 15129:2018 clause 7, velocity
  dependent devices; ASCE 7-16 section 18.6.2, damping devices) run at
  fractions of the design displacement, from a few mm (wind and service
  levels) to about 1 m (bridge and isolation dampers): a peak stroke under
  0.5 mm is within a displacement transducer's noise, above 1,000 mm no
  test stand's.
- force per stroke: the largest force over the smallest stroke of a real
  test, 9,000 kN at +-5 mm, is 1,800 kN/mm; the smallest, a 10 N laboratory
  damper over +-100 mm, 1e-4 kN/mm (the shared MR damper 0.05, the friction
  damper 0.6, the paper's FVDs 7 kN/mm).
"""

from __future__ import annotations

import os

import numpy as np

from ..errors import option
from ..units import FACTORS
from .options import Given, sidecar_path

#: peak |F| [kN] of any damper test (the largest dampers built: about 9,000 kN)
FORCE_MAX_KN = 1.0e4
#: peak stroke about the median [mm] of any damper test: (least, most)
STROKE_MM = (0.5, 1.0e3)
#: peak force / peak stroke [kN/mm] of any real device: (least, most)
FORCE_PER_STROKE = (1.0e-4, 2.0e3)
#: peaks [kN, mm, mm/s] absurd in any unit a file states (validate.check_signal)
ABSURD = {"F": 5.0e4, "d": 5.0e3, "v": 5.0e4}
#: the units a file without units is likely in, tried in this order
LIKELY = {"F": ("N", "lbf"), "d": ("m", "in", "cm", "um")}
#: time step [s] above which a file's time is likely in ms (a note, not a doubt:
#: creep and thermal tests do sample slowly)
LONG_STEP_S = 1.0

_WORDS = {"F": ("peak force", "kN"), "d": ("stroke", "mm")}


def peaks(d: np.ndarray, F: np.ndarray) -> dict:
    """{"F": peak |F| [kN], "d": stroke [mm], peak |d| about the median}."""
    return {"F": float(np.max(np.abs(F))), "d": float(np.max(np.abs(d - np.median(d))))}


def implausible(values: dict) -> list:
    """The keys of ``values`` ({F [kN], d [mm]}) beyond any damper test:
    "F", "d", or "F/d" when each alone is plausible but their ratio is not."""
    out = []
    if values["F"] > FORCE_MAX_KN:
        out.append("F")
    if values["d"] and not STROKE_MM[0] <= values["d"] <= STROKE_MM[1]:
        out.append("d")
    if not out and values["d"] and values["F"]:
        if not FORCE_PER_STROKE[0] <= values["F"] / values["d"] <= FORCE_PER_STROKE[1]:
            out.append("F/d")
    return out


def unit_doubt(where: str, d: np.ndarray, F: np.ndarray, names: dict, stated) -> str | None:
    """The one-line doubt when a file read without the units of d or F
    (``stated``: the keys whose unit the caller, sidecar or header gives)
    has magnitudes no damper test has, naming the likely unit and how to
    give it; None when they are plausible or the units are stated.

    d [mm] and F [kN] as read; ``names``: the file's column names."""
    free = [k for k in ("d", "F") if k not in stated]
    values = peaks(d, F)
    bad = [k for k in implausible(values) if k in free or k == "F/d"] if free else []
    if not bad:
        return None
    guesses = _likely(values, free, bad)
    cols = " and ".join(f"'{names[k]}'" for k in ("d", "F") if k in bad or "F/d" in bad)
    what = {"F": f"a peak force above {FORCE_MAX_KN:,.0f} kN",
            "d": f"a stroke outside {STROKE_MM[0]:g}-{STROKE_MM[1]:,.0f} mm",
            "F/d": f"{_number(values['F'] / values['d'] if values['d'] else 0.0)} kN/mm of peak force per stroke "
                   f"(real devices: {FORCE_PER_STROKE[0]:g}-{FORCE_PER_STROKE[1]:,.0f})"}
    head = (f"{where}: column{'s' if ' and ' in cols else ''} {cols}: peak force {_number(values['F'])} kN over a "
            f"{_number(values['d'])} mm stroke, read as kN and mm (the file gives no units): no damper test has "
            f"{' and '.join(what[k] for k in bad)}")
    if not guesses:
        return head + f"; give the units with {_how(Given({k: 'UNIT' for k in free}), where)}"
    likely = " or ".join(" and ".join(f"{k} in {u}" for k, u in g.items()) for g in guesses)
    return head + f"; is {likely}? give the units with {_how(Given(guesses[0]), where)}"


def _number(x: float) -> str:
    """22,700 or 0.0256: thousands grouped, else 4 significant digits."""
    return f"{x:,.0f}" if abs(x) >= 1e4 else f"{x:.4g}"


def _likely(values: dict, free: list, bad: list) -> list:
    """The unit changes (one quantity's, or each bad one's at once) that
    make the record plausible, most likely first: [{key: unit}, ...]."""
    singles = [{k: u} for k in free for u in LIKELY[k]]
    tries = singles if bad == ["F/d"] else [dict(g) for g in _combos([k for k in ("d", "F") if k in bad])]
    out = []
    for change in tries:
        moved = {k: values[k] * FACTORS[k][change[k]] if k in change else values[k] for k in values}
        if not implausible(moved):
            out.append(change)
    return out[:2] if bad == ["F/d"] else out[:1]


def _combos(keys: list) -> list:
    """Each key's LIKELY units together: [[(k1, u1), (k2, u2)], ...] in preference order."""
    combos = [[]]
    for k in keys:
        combos = [c + [(k, u)] for c in combos for u in LIKELY[k]]
    return combos


def _how(units: Given, where: str) -> str:
    """How to give ``units``: the option in the caller's words, the sidecar, a header."""
    side = os.path.basename(sidecar_path(where))
    header = ", ".join(f"'{k} [{u}]'" for k, u in units.items())
    yaml = ", ".join(f"{k}: {u}" for k, u in units.items())
    return f"{option('--units', units)}, a sidecar {side} with 'units: {{{yaml}}}' or a header such as {header}"
