"""Compare calibrated damper models in a frame under a ground motion.

Each calibration (a law or law + effects fitted on one device) becomes the
damper of every story through the OpenSees export; the bare frame is the
reference.  Per case: peak interstory drift ratio, residual drift ratio,
peak absolute floor acceleration, peak damper force and stroke, energy the
dampers dissipated, and whether the damper left the range it was tested in
(stroke, velocity or frequency beyond the calibration's tested range, force
beyond its tests' peak force, or the given limits).
What the cases say, over a series and between models, is ``verdict``'s.
"""

from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass, field, replace

import numpy as np

from .. import timing
from ..calibration import common_tests, data_key, same_data
from ..calibration import tested as tested_mod
from ..report.numbers import rounded, share
from ..errors import InputError
from ..records.cycles import reversals
from ..records.readers import read_as_stored
from ..export.opensees import opensees_export
from . import decay, sizing
from .property_bounds import expand
from .analysis import FrameResult, run_frame
from .model import DAMPER_TAGS_FROM

#: design quantities of a case: key, label, unit
QUANTITIES = (
    ("drift", "peak interstory drift ratio", "%"),
    ("residual", "residual drift ratio", "%"),
    ("pfa", "peak floor acceleration", "g"),
    ("force", "peak damper force", "kN"),
    ("stroke", "peak damper stroke", "mm"),
    ("energy", "damper energy", "kJ"),
)


@dataclass
class Case:
    """One frame analysis: the bare frame (spec None) or one calibration's damper."""

    label: str
    spec: str | None
    device: str | None
    of: float | None
    result: FrameResult | None = None
    exact: bool | None = None
    note: str = ""
    limits: dict = field(default_factory=dict)  # {'stroke': mm, 'force': kN}
    exceeded: list = field(default_factory=list)
    n_params: int = 0
    per_story: int = 1  # dampers side by side in each story (the link carries all of them)
    fmu: bool = False  # OpenSees has no material for it: the damper FMU runs it (co-simulation)
    fitted_on: frozenset = frozenset()  # the tests its calibration OF is computed on (Calibration.fitted_on)
    ranked_on: tuple | None = None  # (what, OF there): its OF on the common record the models rank on
    scale: float = 1.0  # each damper is the calibrated device with its force times this
    design: object = None  # sizing.Design: its dampers in the first mode's design cycle (energy method)
    achieved: float | None = None  # supplemental damping ratio [-] the frame achieved (free-vibration decay)
    bound: str | None = None  # 'nominal', 'upper', 'lower' with frame --property-bounds; None without
    bound_lambda: float = 1.0  # the bound's factor on the nominal damper's force [-]
    # what the dampers went beyond (``_exceeded``), as data: {'quantity', 'value', 'limit', 'unit',
    # 'against': 'tested' (the calibration's tested range) or 'given' (--stroke-limit, --force-limit), 'where'}
    beyond: list = field(default_factory=list)

    def supplemental_damping(self) -> dict | None:
        """{'target', 'estimated' (energy method), 'achieved' (decay; None:
        not measured), 'roof_drift'} of the first mode [-]; None for the bare frame."""
        d = self.design
        if d is None:
            return None
        return {"target": d.target, "estimated": d.damping, "achieved": self.achieved, "roof_drift": d.roof_drift,
                "factor_per_damper": self.scale}

    def values(self) -> dict:
        """The design quantities (QUANTITIES) of this case; NaN where they do not apply."""
        r = self.result
        nan = float("nan")
        if r is None:
            return {k: nan for k, _, _ in QUANTITIES}
        has = r.damper_force is not None
        return {"drift": 100.0 * r.max_drift_ratio,
                "residual": 100.0 * float(np.nanmax(np.abs(r.residual_drift_ratio))),
                "pfa": float(np.max(r.peak_floor_acceleration_g)),
                "force": float(np.max(r.peak_damper_force)) / self.per_story if has else nan,
                "stroke": float(np.max(r.peak_damper_stroke)) if has else nan,
                "energy": 1e-3 * r.total_damper_energy if has else nan}


def _limits(cal, stroke_limit, force_limit, scale: float = 1.0) -> dict:
    """Given limits, else the calibration's tested range (its tests' peak
    stroke and force, the force times the device's ``scale``)."""
    tested = cal.tested
    return {"stroke": stroke_limit if stroke_limit is not None else tested.get("d"),
            "force": force_limit if force_limit is not None else
            (tested.get("F") * scale if tested.get("F") else None)}


def scaled(commands: list, tag: int, factor: float) -> tuple[list, int]:
    """The damper's commands and the tag of material ``tag`` times ``factor``
    (``Multiplier``: stress, tangent and damping tangent scaled, the strain
    rate passed on; MultiplierMaterial.cpp): N dampers side by side, or a
    device scaled in force.  Factor 1: the commands as they are."""
    if factor == 1.0:
        return commands, tag
    top = max(c[2] for c in commands if c[0] == "uniaxialMaterial") + 1
    return list(commands) + [("uniaxialMaterial", "Multiplier", top, tag, float(factor))], top


def damper_motion(result) -> dict:
    """What the dampers went through: peak stroke d [mm] and velocity v
    [mm/s] over the stories, and the frequency f [Hz] of the damper with the
    largest stroke (1 / (2 x its median time between reversals); None with
    fewer than three reversals)."""
    D = result.damper_deformation
    V = np.gradient(D, result.t, axis=0)
    k = int(np.argmax(np.max(np.abs(D), axis=0)))
    r = reversals(D[:, k])
    f = 1.0 / (2.0 * float(np.median(np.diff(result.t[r])))) if r.size >= 3 else None
    return {"d": float(np.max(np.abs(D))), "v": float(np.max(np.abs(V))), "f": f}


def _exceeded(case: Case, cal=None) -> list:
    """The lines of what ``case``'s dampers went beyond (the tested range,
    the stroke and force limits) and of its solver's stops; the same as
    data into ``case.beyond`` (the page groups them by kind)."""
    v = case.values()
    out, beyond = [], []
    tested = _limits(cal, None, None, case.scale) if cal is not None else {}
    where = (cal.device or cal.record.name or "its record") if cal is not None else ""
    if (cal is not None and case.result is not None and case.result.damper_deformation is not None
            and case.result.t.size >= 3):
        motion = damper_motion(case.result)
        for item in tested_mod.beyond(cal, motion):
            if item["quantity"] != "stroke" or case.limits.get("stroke") is None:
                out.append(tested_mod.beyond_text(item, "the dampers' motion"))
                beyond.append({"quantity": item["quantity"], "value": item["value"], "limit": item["tested"],
                               "unit": item["unit"], "against": "tested", "where": item["where"]})
    for key, what in (("stroke", "stroke"), ("force", "force")):
        limit = case.limits.get(key)
        if limit and np.isfinite(v[key]) and v[key] > limit:
            unit = "mm" if key == "stroke" else "kN"
            out.append(f"peak damper {what} {v[key]:.4g} {unit} exceeds {limit:.4g} {unit}")
            beyond.append({"quantity": what, "value": float(v[key]), "limit": float(limit), "unit": unit,
                           "against": "tested" if tested.get(key) and np.isclose(limit, tested[key], rtol=1e-9)
                           else "given", "where": where})
    if case.result is not None and case.result.solver.message:  # a stop, relaxed steps, negative energy
        out.append(case.result.solver.message)
    case.beyond = beyond
    return out


def run_cases(building, motion, calibrations, *, stroke_limit=None, force_limit=None, dt_analysis=None,
              progress=None, per_story: int = 1, scale: float = 1.0, rank_on=None,
              target_damping: float | None = None, design_drift: float | None = None, bounds=None) -> list[Case]:
    """The bare frame, then one analysis per calibration (fvd_bridge.calibration.Calibration).

    The models rank on the same data (``rank_common``): ``rank_on``, a test
    Record (kN, mm, s), is the record every model's OF is computed on; None:
    their own OFs where all were fitted to the same tests, else a test all
    were fitted on.

    ``per_story`` dampers side by side in each story, each the calibrated
    device with its force times ``scale`` (a larger device of the same
    series); forces are reported per damper.  ``target_damping`` [-]: each
    model's dampers sized instead (``sizing.design``: the factor giving the
    first mode this supplemental damping ratio at roof drift ratio
    ``design_drift``, default the bare frame's peak under the record), and
    the ratio the frame achieves measured by its free-vibration decay
    (``decay.measure``, elastic members, less the bare frame's).  Every
    damper case carries its design (``Case.design``: the energy method's
    ratio of the dampers as they run).  A model OpenSees cannot
    express runs as the damper FMU in co-simulation with the frame
    (``cosim.cosimulate_frame``, explicit scheme: the frame takes the forces
    of the step before), its note saying so; one the FMU cannot carry
    either is kept as a case without result, its note saying why.
    ``bounds`` (frames.property_bounds.Bounds): each calibration runs as its nominal,
    upper- and lower-bound damper (``bounds.expand``).  A calibration with
    parameters fitted per test is refused: take one test's first
    (``Calibration.for_test``)."""
    calibrations = [cal.for_test() for cal in calibrations]
    runs = [(Case("bare frame", None, None, None), None, None)]
    for cal in calibrations:
        device = cal.device or cal.record.name or "device"
        case = Case(f"law {cal.spec} | {device}", cal.spec, device, float(cal.of),
                    limits=_limits(cal, stroke_limit, force_limit, scale), n_params=len(cal.model.names),
                    per_story=per_story, fitted_on=cal.fitted_on, scale=scale)
        commands = None
        try:
            export = cal.solving(opensees_export(cal.model, cal.named(), DAMPER_TAGS_FROM, tested=cal.tested))
            if export.connection:  # the frames place one damper element per brace
                raise InputError(f"model {cal.spec} is two materials in series through an internal node, "
                                 f"which the frames do not place")
            case.exact, case.note, commands = export.exact, export.note, export.commands
        except InputError as exc:
            case.note = str(exc)
            case.fmu = not cal.model.fmu_refusal()
            if case.fmu:
                case.note = (f"co-simulated with its FMU, explicit scheme, step {COSIM_STEP:g} s at most "
                             f"(OpenSees: {exc})")
        runs += [(each, commands, cal) for each in (expand(case, cal, bounds) if bounds is not None else [case])]
    rank_common([case for case, _, _ in runs[1:]], [cal for _, _, cal in runs[1:]], rank_on)
    mode = sizing.first_mode(building)
    drift, bare_decay = design_drift, None
    for case, commands, cal in runs:
        if case.spec is not None and commands is None and not case.fmu:
            if progress:
                progress(f"{case.label}: skipped ({case.note})")
            continue
        if case.spec is not None:
            case.design = sizing.design(mode, cal, drift, target_damping, per_story * case.scale)
            if target_damping is not None:
                case.scale = case.design.factor / per_story * case.bound_lambda
                # a bound's dampers: the nominal's sized ones times its factor (frames.property_bounds)
                case.design = replace(case.design, factor=case.design.factor * case.bound_lambda)
                case.limits = _limits(cal, stroke_limit, force_limit, case.scale)
                if progress:
                    progress(f"{case.label}: sized for {share(target_damping)} of critical damping at roof drift "
                             f"{share(drift)}: each damper the device x{rounded(case.scale, digits=3)} in force")
        with timing.stage(f"  {case.label}"):
            case.result = _analysed(building, motion, case, commands, cal, dt_analysis)
        if case.spec is None and drift is None:
            drift = float(np.max(np.abs(case.result.floor_displacement[:, -1]))) / mode.roof_height
        if case.spec is not None and target_damping is not None:
            with timing.stage(f"  {case.label}: free-vibration decay"):
                if bare_decay is None:
                    bare_decay = _decay(building, mode, case.design.roof_amplitude)
                case.achieved = _decay(building, mode, case.design.roof_amplitude, case, commands, cal) - bare_decay
        case.exceeded = _exceeded(case, cal)
        if progress:
            v = case.values()
            force = f", damper force {rounded(v['force'])} kN" if np.isfinite(v["force"]) else ""
            how = ", ".join(case.result.solver.algorithms_used) + ("" if case.exact in (True, None) and
                                                                   not case.fmu else f"; {case.note}")
            got = f", supplemental damping achieved {share(case.achieved)}" if case.achieved is not None else ""
            progress(f"{case.label}: peak drift {rounded(v['drift'])}%{force}{got} ({how})")
    return [case for case, _, _ in runs]


def _analysed(building, motion, case: Case, commands, cal, dt_analysis=None, free_vibration=None,
              record_dampers: bool = True) -> FrameResult:
    """``case``'s frame under ``motion``: its dampers (``per_story`` x
    ``scale`` times the device; none for the bare frame) through OpenSees,
    or its FMU in co-simulation."""
    factor = case.per_story * case.scale
    if case.fmu:
        return _cosimulated(building, motion, cal, factor, dt_analysis, free_vibration)
    tag = DAMPER_TAGS_FROM
    if commands is not None:
        commands, tag = scaled(commands, tag, factor)
    return run_frame(building, motion, commands, tag, dt_analysis=dt_analysis, free_vibration=free_vibration,
                     record_dampers=record_dampers)


def _decay(building, mode, amplitude: float, case: Case | None = None, commands=None, cal=None) -> float:
    """The first-mode damping ratio [-] of the frame (elastic members) with
    ``case``'s dampers (None: bare) at roof amplitude ``amplitude`` [mm],
    by its free-vibration decay (``decay.measure``)."""
    elastic = building.with_(yielding=False)
    case = case or Case("bare frame", None, None, None)

    def run(motion, free_vibration):
        return _analysed(elastic, motion, case, commands, cal, free_vibration=free_vibration, record_dampers=False)

    return decay.measure(run, mode, amplitude).damping


#: [s] largest communication step of a frame co-simulated with the damper
#: FMU: the explicit scheme's one-step force lag is first order in it (law 9's
#: refit on the shared friction damper, 3-story frame, El Centro x100 force:
#: peak drift 1.088% at 0.02 s, a spurious 6 Hz oscillation; 0.961% at
#: 0.005 s; 0.956% at 0.002 s; law 9 through the FMU against its native
#: OpenSees material: 5% apart at 0.02 s, 0.4% at 0.002 s)
COSIM_STEP = 0.002


def _cosimulated(building, motion, cal, scale: float, dt_analysis=None, free_vibration=None) -> FrameResult:
    """The frame with ``cal``'s damper FMU in each story (built in a temporary
    folder), its force times ``scale``: the explicit co-simulation, which
    runs yielding members, at a step of at most COSIM_STEP; free vibration
    [s] as ``run_frame``'s."""
    from .cosim import cosimulate_frame

    h = min(float(dt_analysis or motion.dt), COSIM_STEP)
    with tempfile.TemporaryDirectory(prefix="fvd_frame_fmu-") as folder:
        fmu = cal.to_fmu(os.path.join(folder, "damper.fmu"))
        result, _ = cosimulate_frame(building, motion, fmu, 'explicit', dt_analysis=h, free_vibration=free_vibration,
                                     force_scale=scale)
    return result


def rank_common(cases, calibrations, record=None) -> None:
    """Each damper case's OF on a common record (``Case.ranked_on``) when the
    models' own OFs are not on the same data: on ``record`` (a test Record a
    caller gives) always; else, where the calibrations were fitted to
    different tests, on the tests every one of them was fitted on whose
    records are at hand (kept in memory, or their files read again as they
    were calibrated; the mean OF over them).  Nothing found: the cases keep
    none and the verdict does not rank them."""
    calibrations = list(calibrations)
    if record is not None:
        what, records = f"the record {record.name}", [record]
    elif same_data(calibrations):
        return
    else:
        records = [r for r in (_at_hand(t, calibrations) for t in common_tests(calibrations)) if r is not None]
        if not records:
            return
        names = ", ".join(r.name for r in records)
        what = f"the test{'s' if len(records) > 1 else ''} {names}, which every model was fitted on"
    for case, cal in zip(cases, calibrations):
        case.ranked_on = (what, float(np.mean([cal.of_on(r) for r in records])))


def _at_hand(test, calibrations):
    """A common test's record: one a calibration keeps in memory, else its file read as calibrated; None: gone."""
    key = data_key(test)
    for cal in calibrations:
        for rec in cal.records:
            if ((rec.provenance or {}).get("file") or rec.name, rec.n) == key:
                return rec
    return read_as_stored(test.record, test.name)
