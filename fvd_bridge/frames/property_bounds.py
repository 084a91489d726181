"""``frame --property-bounds``: each damper as nominal, upper-bound and lower-bound
device, and the envelope of the frame's response over the three.

The factors (``read_bounds``) come from the bounds.json a campaign or
calibrate writes (``campaign.property_bounds``: per model lambda_min and lambda_max of the force at
the design velocity, the series' nominal force there and the design
motion) or are given as two numbers LMIN,LMAX for every model.  The
bounds scale the damper's whole force (OpenSees' ``Multiplier``, as
``--scale-force`` does), so the upper-bound damper is the nominal one with
its force times lambda_max at every velocity (ASCE 7-16 sec. 18.2.4.5:
P_max = lambda_max P_nominal):

    nominal      factor r = F_nominal(V) / F_cal(V)
    upper bound  factor r lambda_max
    lower bound  factor r lambda_min

F_cal(V) [kN] the calibration's own force at the design velocity V (the
acceptance's sinusoid, ``acceptance.forces_at_velocity``), F_nominal(V)
the series' nominal (mean) force there: the device a user picks is first
brought to the series' nominal (r = 1 with given factors).  Dampers sized
for a target damping (``--target-damping``) are sized on the nominal and
the bounds scale the sized damper.

The envelope (``envelope``) per model: the largest peak interstory drift
and damper force of each bound over the devices, the largest of the
three and which bound gives it.  The usual order is the upper bound
governing the damper force (what the damper and its connections are
designed for) and the lower bound the drift (what the frame is designed
for); where a run does not follow it the lines say so and why.
"""

from __future__ import annotations

import dataclasses
import json
import os
from dataclasses import dataclass

import numpy as np

from ..campaign.acceptance import Acceptance, design_motion
from ..campaign.property_bounds import FORCE, RULE, SOURCE, design_forces
from ..errors import InputError
from ..report.numbers import rounded, share

#: the frame's option that reads the bounds (``--bounds`` alone is calibrate's search box)
OPTION = "--property-bounds"
#: the three dampers of each calibration, in the order they run
BOUNDS = ("nominal", "upper", "lower")
#: the bound expected to govern each quantity
EXPECTED = {"drift": "lower", "force": "upper"}
#: the bounds changing a quantity by less than this share leave which one governs to the analysis' noise
SMALL_CHANGE = 0.01


@dataclass(frozen=True)
class Factors:
    """One model's factors on the damper force [-]; ``nominal_force`` [kN] at
    the design velocity (None: the calibration's own force is nominal)."""

    lambda_min: float
    lambda_max: float
    nominal_force: float | None = None


@dataclass(frozen=True)
class Bounds:
    """Where the factors come from (``source``), per model spec (or '*' for
    every model) its Factors, and the design motion (velocity [mm/s],
    amplitude [mm], dt [s], cycles) of the nominal forces (None with given factors)."""

    source: str
    models: dict
    motion: dict | None = None
    skipped: dict | None = None  # {spec: why the series has no bounds of it}

    def factors(self, spec: str) -> Factors:
        """The factors of model ``spec``; InputError when the bounds have none."""
        found = self.models.get(spec) or self.models.get("*")
        if found is None and spec in (self.skipped or {}):
            raise InputError(f"{OPTION} {self.source}: {self.skipped[spec]}")
        if found is None:
            raise InputError(f"{OPTION} {self.source}: no bounds for law {spec} (it has law "
                             f"{', '.join(self.models)}): give the campaign or calibrate folder that calibrated it, "
                             f"or LMIN,LMAX")
        return found

    def as_dict(self) -> dict:
        return {"source": self.source, "rule": RULE, "rule_source": SOURCE, "motion": self.motion,
                "models": {s: dataclasses.asdict(f) for s, f in self.models.items()}}


def read_bounds(text: str) -> Bounds:
    """``--property-bounds``: a campaign's or calibrate's output folder, its bounds.json, or 'LMIN,LMAX'
    (0 < LMIN <= 1 <= LMAX) for every model; InputError naming the option otherwise."""
    path = os.path.join(text, "bounds.json") if os.path.isdir(text) else text
    if os.path.isfile(path):
        return _from_file(text, path)
    if os.path.isdir(text):
        raise InputError(f"{OPTION} {text}: no bounds.json in it (a campaign's or calibrate's output folder holds one)")
    parts = text.split(",")
    try:
        low, high = (float(p) for p in parts) if len(parts) == 2 else (None, None)
    except ValueError:
        low = high = None
    if low is None:
        raise InputError(f"{OPTION} {text}: expected a campaign's or calibrate's output folder, its "
                         f"bounds.json, or LMIN,LMAX "
                         f"(e.g. 0.85,1.2)")
    if not (np.isfinite(low) and np.isfinite(high) and 0 < low <= 1 <= high):
        raise InputError(f"{OPTION} {text}: factors LMIN,LMAX need 0 < LMIN <= 1 <= LMAX")
    return Bounds(f"given factors {rounded(low, digits=3)}, {rounded(high, digits=3)}", {"*": Factors(low, high)})


def _from_file(text: str, path: str) -> Bounds:
    try:
        with open(path) as fh:
            data = json.load(fh)
        models = {}
        for spec, m in data["models"].items():
            row = next(r for r in m["rows"] if r["quantity"] == FORCE)
            if row["lambda_min"] is None or row["lambda_max"] is None:
                continue
            models[str(spec)] = Factors(float(row["lambda_min"]), float(row["lambda_max"]), float(row["nominal"]))
        motion = {k: float(data[k]) for k in ("velocity", "amplitude", "dt", "cycles")}
        skipped = {str(spec): str(why) for spec, why in (data.get("skipped") or {}).items()}
    except (OSError, ValueError, KeyError, TypeError, StopIteration, AttributeError) as exc:
        raise InputError(f"{OPTION} {text}: {path} is not the bounds.json of a campaign or calibrate "
                         f"({type(exc).__name__}: {exc})") from None
    if not models:
        why = "; ".join(skipped.values())
        raise InputError(f"{OPTION} {text}: {path} holds no model with force factors{f' ({why})' if why else ''}")
    return Bounds(path, models, motion, skipped)


def nominal_ratio(bounds: Bounds, cal) -> float:
    """r = F_nominal(V) / F_cal(V) [-] (module doc); 1 without a nominal force."""
    f = bounds.factors(cal.spec)
    if f.nominal_force is None or bounds.motion is None:
        return 1.0
    m = bounds.motion
    motion = design_motion(Acceptance(velocity=m["velocity"], cycles=m["cycles"]), m["amplitude"], m["dt"])
    own = float(design_forces(cal.model, cal.values, motion)[0])
    if not own > 0:
        raise InputError(f"{OPTION} {bounds.source}: law {cal.spec}'s force at {rounded(m['velocity'])} mm/s is "
                         f"{rounded(own)} kN: it cannot be brought to the nominal force")
    return f.nominal_force / own


def expand(case, cal, bounds: Bounds) -> list:
    """``case`` (a damper Case of frames.compare) as its nominal, upper- and
    lower-bound copies: force factor r, r lambda_max, r lambda_min times its
    scale (module doc), labelled '<label> | upper bound'."""
    f = bounds.factors(cal.spec)
    r = nominal_ratio(bounds, cal)
    out = []
    for name, lam in zip(BOUNDS, (1.0, f.lambda_max, f.lambda_min)):
        scale = case.scale * r * lam
        out.append(dataclasses.replace(case, label=f"{case.label} | {name}{' bound' if name != 'nominal' else ''}",
                                       bound=name, bound_lambda=lam, scale=scale,
                                       limits={**case.limits, "force": (case.limits.get("force") or 0) * r * lam
                                               or None}))
    return out


def envelope(cases) -> dict:
    """{spec: {'drift' and 'force': {'nominal', 'upper', 'lower' (the largest
    over the model's devices of peak drift [%] and damper force [kN] per
    damper), 'envelope', 'governing', 'expected', 'change'}, 'devices',
    'factors': {bound: force factor of each device's damper}, 'lambda':
    {bound: its factor on the nominal}}} of the
    models run with bounds whose three analyses all reached their end."""
    out = {}
    ran = [c for c in cases if getattr(c, "bound", None) and c.result is not None and c.result.solver.completed]
    for spec in dict.fromkeys(c.spec for c in ran):
        group = [c for c in ran if c.spec == spec]
        if {c.bound for c in group} != set(BOUNDS):
            continue
        entry = {"devices": list(dict.fromkeys(c.device for c in group)),
                 "factors": {b: [c.scale for c in group if c.bound == b] for b in BOUNDS},
                 "lambda": {b: next(c.bound_lambda for c in group if c.bound == b) for b in BOUNDS}}
        for key in ("drift", "force"):
            peak = {b: max(c.values()[key] for c in group if c.bound == b) for b in BOUNDS}
            top = max(BOUNDS, key=lambda b: peak[b])
            low = min(peak.values())
            entry[key] = {**peak, "envelope": peak[top], "governing": top, "expected": EXPECTED[key],
                          "change": (peak[top] - low) / abs(low) if low else float("nan")}
        out[spec] = entry
    return out


def envelope_lines(cases) -> list[str]:
    """The verdict's lines on the bounds: per model the envelope of drift and
    damper force with the governing bound, and, against the usual order,
    why (module doc); [] without bounds."""
    lines = []
    for spec, e in envelope(cases).items():
        d, f = e["drift"], e["force"]
        lam = e["lambda"]
        lines.append(f"bounds, law {spec}: the upper-bound damper is the nominal one with its force "
                     f"x{rounded(lam['upper'], digits=3)}, the lower-bound x{rounded(lam['lower'], digits=3)} "
                     f"(ASCE 7-16 18.2.4.5: P = lambda P_nominal)")
        lines.append(f"bounds, law {spec}: envelope of peak interstory drift {rounded(d['envelope'])}% "
                     f"({_named(d['governing'])} governs; {_others(d, '%')}), of damper force "
                     f"{rounded(f['envelope'])} kN per damper ({_named(f['governing'])} governs; {_others(f, ' kN')})")
        for key, what in (("force", "damper force"), ("drift", "peak drift")):
            q = e[key]
            if q["governing"] != q["expected"]:
                lines.append(f"law {spec}: {_named(q['expected'])} does not give the largest {what} here "
                             f"({_named(q['governing'])} does): " + _why_not(key, q))
    return lines


def _named(bound: str) -> str:
    """'the upper bound', 'the nominal damper'."""
    return "the nominal damper" if bound == "nominal" else f"the {bound} bound"


def _others(q: dict, unit: str) -> str:
    """'nominal 1.21%, upper bound 1.19%': the bounds that do not govern."""
    return ", ".join(f"{b}{' bound' if b != 'nominal' else ''} {rounded(q[b])}{unit}"
                     for b in BOUNDS if b != q["governing"])


def _why_not(key: str, q: dict) -> str:
    """Why a quantity is not governed by the bound expected to govern it."""
    if np.isfinite(q["change"]) and q["change"] < SMALL_CHANGE:
        return (f"the three dampers change it by {share(q['change'])} only, which leaves the order to the "
                f"analysis' details; the dampers hardly change it (see the supplemental damping)")
    if key == "drift":
        return (f"the bounds change it by {share(q['change'])}; a weaker damper lets the frame move more in "
                "general, but under one record a change of damping can shift when the peak comes and meet a "
                "stronger pulse: check the envelope over more records")
    return (f"the bounds change it by {share(q['change'])}; a stronger damper slows the motion it resists, and "
            "here that lowers its force more than its larger coefficient raises it")


def summary(cases, bounds: Bounds | None) -> dict | None:
    """frame_summary.json's 'bounds': where the factors came from and the envelope; None without bounds."""
    if bounds is None:
        return None
    return {**bounds.as_dict(), "envelope": envelope(cases)}
