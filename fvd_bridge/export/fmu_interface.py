"""The damper FMU's interface, generated from the registry: its variables
(``modelDescription.xml``) and their value references (``config.h``).

The registry is ``fvd_bridge.laws.LAWS`` (each law's parameters, units,
descriptions, golden reference values) and
``fvd_bridge.effects.catalog.BUILTIN`` (each effect's parameters and the
values that switch it off).  Nothing here names a law or a parameter: a law
or an effect added to the registry appears in the FMU's interface as it is.

Variables, in value-reference order (``variables()``): ``time``; the inputs
``d``, ``v``, ``a``; the outputs ``F``, ``z``, ``E``; the structural
parameters ``law``, ``<effect>.enabled`` (BUILTIN order),
``use_velocity_input``, ``use_acceleration_input``, ``inputs_at_step_end``; the parameters
``h_max``, ``law<N>.<name>`` (law numbers ascending, parameters in the
law's order), ``<effect>.<name>`` (``effects.catalog.EFFECT_PARAMETERS`` order).

``config_header()`` is ``sources/config.h``: the ``ValueReference`` enum
and the tables the hand-written C reads instead of naming variables
(``LAW_FIRST_VR[law]``, ``LAW_N_PAR[law]``, ``LAW_IN_FMU[law]``, ``LAW_CONNECTION[law]``,
``EFFECT_ENABLED_VR``, ``EFFECT_PAR_VR``, ``N_LAWS``, ...).
``model_description(tunable, start)`` is ``modelDescription.xml`` without
the calibration's metadata (``fmu.build_fmu`` adds those): the variables
named in ``tunable`` are tunable parameters, every other law and effect
parameter is fixed.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass

from ..effects.catalog import BUILTIN
from ..laws import LAWS

MODEL_IDENTIFIER = "fvd_damper"

#: FMI units of the registry's unit strings (SI base units, factor to SI); a
#: unit not listed here is declared without base units
UNITS = {
    "s": {"s": "1"},
    "mm": {"m": "1", "factor": "0.001"},
    "mm/s": {"m": "1", "s": "-1", "factor": "0.001"},
    "mm/s^2": {"m": "1", "s": "-2", "factor": "0.001"},
    "kN": {"kg": "1", "m": "1", "s": "-2", "factor": "1000"},
    "kN.mm": {"kg": "1", "m": "2", "s": "-2"},
    "kN/mm": {"kg": "1", "s": "-2", "factor": "1000000"},
    "kN/mm^2": {"kg": "1", "m": "-1", "s": "-2", "factor": "1e9"},
    "kN/(mm/s)": {"kg": "1", "s": "-1", "factor": "1000000"},
    "1/mm": {"m": "-1", "factor": "1000"},
    "1/MJ": {"kg": "-1", "m": "-2", "s": "2", "factor": "1e-6"},
    "kg": {"kg": "1"},
}


@dataclass(frozen=True)
class Variable:
    """One FMU variable; ``vr`` its value reference (= its place in the list)."""

    name: str
    vr: int
    type: str          # Float64, Int32, Boolean
    causality: str
    variability: str
    description: str
    start: object = None
    unit: str | None = None
    initial: str | None = None
    min: object = None
    max: object = None

    @property
    def c_name(self) -> str:
        """Its enumerator in config.h: vr_<name>, '.' as '_'."""
        return "vr_" + self.name.replace(".", "_")


# ------------------------------------------------------------------ registry
def laws() -> dict:
    """{number: Law} of the registry, numbers ascending."""
    return dict(sorted(LAWS.items()))


def effects() -> tuple:
    """The built-in effects, in the registry's order."""
    return tuple(BUILTIN)


def law_parameter_name(number: int, name: str) -> str:
    """The FMU variable of a law's parameter: 'law<N>.<name>' (law2.C)."""
    return f"law{number}.{name}"


def _law_reference(number: int, law) -> tuple:
    """Default start values of a law's parameters: its reference values (the
    golden files'), else the middle of its paper bounds."""
    ref = tuple(law.reference)
    if len(ref) != len(law.parameters):
        ref = tuple(0.5 * (p.paper[0] + p.paper[1]) for p in law.parameters)
    return tuple(float(x) for x in ref)


def _effect_off(x: float, parameter) -> float:
    """Default start value of an effect parameter: its 'off' value within the
    parameter's bounds (an infinite one, a rigid series spring, as its
    largest stiffness, which the composition counts as rigid)."""
    lo, hi = parameter.paper
    return float(min(max(x, lo), hi))


def _unit(unit: str) -> str | None:
    return None if unit in ("-", "", None) else unit


def _described(text: str, unit: str) -> str:
    return text + (" [-]" if _unit(unit) is None else "")


# ----------------------------------------------------------------- variables
def variables() -> list:
    """Every FMU variable, in value-reference order."""
    out = []

    def add(name, type_, causality, variability, description, **kw):
        out.append(Variable(name, len(out), type_, causality, variability, description, **kw))

    the_laws, the_effects = laws(), effects()
    numbers = list(the_laws)
    stateful = [n for n, law in the_laws.items()
                if (law.state if hasattr(law, "state") else law.kind == "differential")]
    add("time", "Float64", "independent", "continuous", "Simulation time")
    when = "at the communication point t (at t + h with inputs_at_step_end)"
    add("d", "Float64", "input", "continuous", f"pin displacement {when} (positive: tension)", start=0.0, unit="mm")
    add("v", "Float64", "input", "continuous",
        f"pin velocity {when}, used once set (or with use_velocity_input; else derived from d)",
        start=0.0, unit="mm/s")
    add("a", "Float64", "input", "continuous",
        f"pin acceleration {when}, used once set (or with use_acceleration_input; else derived from v)",
        start=0.0, unit="mm/s^2")
    add("F", "Float64", "output", "continuous", "damper force (positive: tension)", unit="kN", initial="calculated")
    add("z", "Float64", "output", "continuous",
        "internal variable of the law (laws " + ", ".join(map(str, stateful)) + "; the series connection's "
        "with a spring or a gap); 0 for a law without state and no connection", initial="calculated")
    add("E", "Float64", "output", "continuous",
        "work done on the damper, integral of F v dt (trapezoidal rule per step; over closed cycles the "
        "dissipated energy)", unit="kN.mm", initial="calculated")
    add("law", "Int32", "structuralParameter", "fixed",
        f"law number {numbers[0]}-{numbers[-1]} (fvd_bridge laws: "
        + ", ".join(f"{n} {law.name}" for n, law in the_laws.items()) + ")",
        start=numbers[0], min=numbers[0], max=numbers[-1])
    for e in the_effects:
        add(f"{e.name}.enabled", "Boolean", "structuralParameter", "fixed", e.summary, start=False)
    add("use_velocity_input", "Boolean", "structuralParameter", "fixed",
        "take v from the input (else v is the second-order backward derivative of the samples of d, from rest)",
        start=False)
    add("use_acceleration_input", "Boolean", "structuralParameter", "fixed",
        "take a from the input (else a is the second-order backward derivative of the samples of v)", start=False)
    add("inputs_at_step_end", "Boolean", "structuralParameter", "fixed",
        "the master sets d, v, a at the END of the coming step, d(t + h), before fmi3DoStep(t, h) (exact; for "
        "structure-first co-simulation); default: FMI's convention, inputs at t, the FMU extrapolating them to "
        "t + h (second order) and redoing the step when the inputs at t + h come", start=False)
    add("h_max", "Float64", "parameter", "fixed",
        "largest sub-step: each step h is integrated in ceil(h / h_max) equal sub-steps", start=1e-3, unit="s")
    for number, law in the_laws.items():
        for i, (p, x) in enumerate(zip(law.parameters, _law_reference(number, law))):
            head = f"law {number}, {law.equation}" if i == 0 else f"law {number}"
            add(law_parameter_name(number, p.name), "Float64", "parameter", "fixed",
                _described(f"{head}: {p.description}", p.unit), start=x, unit=_unit(p.unit))
    for e in the_effects:
        for p, name, off in zip(e.parameters, e.names, e.none):
            add(name, "Float64", "parameter", "fixed", _described(f"{e.name}: {p.description}", p.unit),
                start=_effect_off(off, p), unit=_unit(p.unit))
    return out


# -------------------------------------------------------------------- config.h
def config_header() -> str:
    """sources/config.h: the model identifier, the ValueReference enum (the
    order of modelDescription.xml) and the registry's tables for the C."""
    vs = variables()
    by_name = {v.name: v for v in vs}
    the_laws, the_effects = laws(), effects()
    n_laws = max(the_laws)
    first = ["0"] * (n_laws + 1)
    n_par = ["0"] * (n_laws + 1)
    carried = ["false"] * (n_laws + 1)
    connection = ["false"] * (n_laws + 1)
    for n, law in the_laws.items():
        if law.parameters:
            first[n] = by_name[law_parameter_name(n, law.parameters[0].name)].c_name
        n_par[n] = str(len(law.parameters))
        carried[n] = "true" if law.fmu else "false"
        connection[n] = "true" if law.connection else "false"
    effect_par = [name for e in the_effects for name in e.names]
    enum, kind = [], None
    for v in vs:
        group = _group(v)
        if group != kind:
            enum.append(f"    /* {group} */")
            kind = group
        enum.append(f"    {v.c_name},")
    lines = [
        "/* The damper FMU's configuration: identifier, value references, the registry's tables.",
        " *",
        " * GENERATED by fvd_bridge.export.fmu_interface.config_header() from the registry",
        " * (fvd_bridge.laws.LAWS, fvd_bridge.effects.catalog.BUILTIN) when build_fmu writes an FMU:",
        " * do not edit, and do not keep a copy in fmu/.  The value references are the order of the",
        " * variables in modelDescription.xml (generated alongside).  calibration.h, written by",
        " * build_fmu, holds the instantiation token and the calibrated start values. */",
        "#ifndef config_h",
        "#define config_h",
        "",
        "#include <stdbool.h>",
        "#include <stdint.h>",
        "",
        f"#define MODEL_IDENTIFIER {MODEL_IDENTIFIER}",
        "",
        "typedef enum {",
        *enum,
        "    N_VR",
        "} ValueReference;",
        "",
        "/* value-reference ranges of each kind of variable */",
        f"#define VR_FIRST_INPUT {by_name['d'].c_name}",
        f"#define VR_LAST_INPUT {by_name['a'].c_name}",
        f"#define VR_FIRST_OUTPUT {by_name['F'].c_name}",
        f"#define VR_LAST_OUTPUT {by_name['E'].c_name}",
        f"#define VR_FIRST_STRUCTURAL {by_name['law'].c_name}",
        f"#define VR_LAST_STRUCTURAL {by_name['inputs_at_step_end'].c_name}",
        f"#define VR_FIRST_BOOLEAN {next(v.c_name for v in vs if v.type == 'Boolean')}",
        f"#define VR_FIRST_PARAMETER {by_name['h_max'].c_name}",
        "",
        "/* the laws, by number (index 0 and numbers absent from the registry: no law) */",
        f"#define N_LAWS {n_laws}",
        f"#define MAX_LAW_PAR {max([len(law.parameters) for law in the_laws.values()] + [1])}",
        "/* first value reference of each law's parameters (law<N>.<first>), their number, whether the C has the",
        " * law (Law.fmu), whether it can sit behind a series spring or a gap (Law.connection) */",
        _c_table("LAW_FIRST_VR_VALUES", first),
        _c_table("LAW_N_PAR_VALUES", n_par),
        _c_table("LAW_IN_FMU_VALUES", carried),
        _c_table("LAW_CONNECTION_VALUES", connection),
        "",
        "/* the built-in effects (fvd_bridge.effects.catalog.BUILTIN order): their switches, and their",
        " * parameters in fvd_bridge.effects.catalog.EFFECT_PARAMETERS order with the effect each belongs to */",
        f"#define N_EFFECTS {len(the_effects)}",
        f"#define N_EFFECT_PAR {len(effect_par)}",
        _c_table("EFFECT_ENABLED_VR_VALUES", [by_name[f"{e.name}.enabled"].c_name for e in the_effects]),
        _c_table("EFFECT_PAR_VR_VALUES", [by_name[name].c_name for name in effect_par]),
        _c_table("EFFECT_OF_PAR_VALUES", [str(i) for i, e in enumerate(the_effects) for _ in e.names]),
        _c_table("EFFECT_IN_FMU_VALUES", ["true" if e.fmu else "false" for e in the_effects]),
        "",
        '#include "calibration.h"',
        "",
        "#endif /* config_h */",
    ]
    return "\n".join(lines) + "\n"


def _group(v: Variable) -> str:
    if v.causality in ("independent", "input", "output"):
        return {"independent": "the time", "input": "inputs: the pin's motion at the END of the coming "
                "communication step", "output": "outputs"}[v.causality]
    return "structural parameters" if v.causality == "structuralParameter" else "parameters"


def _c_table(name: str, items: list) -> str:
    return f"#define {name} {{ " + ", ".join(items) + " }"


# ------------------------------------------------------ modelDescription.xml
def model_description(tunable=(), start: dict | None = None, description: str | None = None) -> ET.Element:
    """modelDescription.xml as an element tree: every variable of
    ``variables()`` with its unit and start value (``start`` {name: value}
    overrides the registry's defaults); the parameters named in ``tunable``
    are variability="tunable", every other parameter fixed.  The token,
    generation date and annotations are the caller's (``fmu.build_fmu``)."""
    vs = variables()
    names = {v.name for v in vs}
    start = dict(start or {})
    unknown = sorted((set(start) | set(tunable)) - names)
    if unknown:
        raise KeyError(", ".join(unknown))
    tunable = set(tunable)
    for name in tunable:
        v = next(v for v in vs if v.name == name)
        if v.causality != "parameter":
            raise KeyError(f"{name} is not a parameter: it cannot be tunable")
    root = ET.Element("fmiModelDescription", {
        "fmiVersion": "3.0", "modelName": MODEL_IDENTIFIER,
        "description": description or "fluid-viscous damper (fvd_bridge)",
        "generationTool": "fvd_bridge", "instantiationToken": "{00000000-0000-0000-0000-000000000000}",
        "variableNamingConvention": "structured"})
    ET.SubElement(root, "CoSimulation", modelIdentifier=MODEL_IDENTIFIER,
                  canHandleVariableCommunicationStepSize="true", canGetAndSetFMUState="true",
                  canSerializeFMUState="true")
    used = {v.unit for v in vs if v.unit}
    units = ET.SubElement(root, "UnitDefinitions")
    for name in [u for u in UNITS if u in used] + sorted(used - set(UNITS)):
        unit = ET.SubElement(units, "Unit", name=name)
        if name in UNITS:
            ET.SubElement(unit, "BaseUnit", UNITS[name])
    cats = ET.SubElement(root, "LogCategories")
    ET.SubElement(cats, "Category", name="logEvents", description="Log events")
    ET.SubElement(cats, "Category", name="logStatusError",
                  description="Log error messages (bad parameters, non-finite inputs or results)")
    ET.SubElement(root, "DefaultExperiment", startTime="0", stepSize=xml_value(start.get("h_max", 1e-3)))
    mv = ET.SubElement(root, "ModelVariables")
    for v in vs:
        attrs = {"name": v.name, "valueReference": str(v.vr), "causality": v.causality,
                 "variability": "tunable" if v.name in tunable else v.variability}
        if v.initial:
            attrs["initial"] = v.initial
        if v.unit:
            attrs["unit"] = v.unit
        x = start.get(v.name, v.start)
        if x is not None:
            attrs["start"] = xml_value(x)
        if v.min is not None:
            attrs["min"] = xml_value(v.min)
        if v.max is not None:
            attrs["max"] = xml_value(v.max)
        attrs["description"] = v.description
        ET.SubElement(mv, v.type, attrs)
    ms = ET.SubElement(root, "ModelStructure")
    outputs = [v for v in vs if v.causality == "output"]
    for tag in ("Output", "InitialUnknown"):
        for v in outputs:
            ET.SubElement(ms, tag, valueReference=str(v.vr))
    ET.indent(root, space="  ")
    return root


def xml_value(x) -> str:
    """A start value as FMI XML writes it."""
    if isinstance(x, bool):
        return "true" if x else "false"
    if isinstance(x, int):
        return str(x)
    return "INF" if x == math.inf else repr(float(x))
