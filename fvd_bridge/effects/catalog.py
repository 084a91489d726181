"""The eight built-in physical effects, declared as data (``base.Effect``):
parameters, stage, equation, fingerprints (README, "Physical effects"), the
connection slots they fill, their physical size, golden reference values and
export targets.

Each effect's equation lives in the docstring of the function that computes
it.  Bounds scale with the record: F = peak force [kN], v = peak velocity
[mm/s], d = peak displacement [mm]; each range contains the value that
switches the effect off.  Forces in kN, positive in tension.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ..kernel_cache import kernel_array
from ..laws.base import OpenSeesForm, Parameter
from . import connection, sizes, steps
from .base import Effect
from .opensees_forms import asymmetric, friction, parallel_spring

#: smoothing velocity of the friction term [mm/s] (fixed, not fitted)
FRICTION_V_F = steps.FRICTION_V_F
#: series stiffness [kN/mm] at and above which the connection is rigid (the
#: model without the spring; far above any real oil column, rod or frame)
KS_RIGID = 1e6
#: a row's Ks counts as rigid from here (the upper bound, to rounding)
KS_RIGID_FROM = KS_RIGID * (1.0 - 1e-12)


def _col(P, j):
    return P[:, j:j + 1]


def _rows(x):
    return kernel_array(np.atleast_2d(x))


# ------------------------------------------------------------------ series
def connection_force(law_number, PL, x, xv, xa, dt, slots: dict, substeps=1):
    """The damper's connection: a spring Ks [kN/mm] (series_stiffness: fluid
    compressibility and connection flexibility) whose force has the dead
    zone of a pin clearance g [mm] (gap: total, h = g/2 on each side), in
    series with the internal element (the law with asymmetry r, heating
    theta, friction Ff and, behind a gap, the parallel spring Kp [kN/mm],
    F0 [kN]), a Maxwell model for any law whose ``connection`` capability
    is set:

      F = Ks dz(w, h) = F_int(x_o, dx_o/dt),  w = x - x_o,
      dz(w, h) = w - h (w > h),  w + h (w < -h),  0 (|w| <= h),

    x, xv, xa the pin's motion (the record's d, v, a), x_o the law's
    displacement.  ``slots``: {slot: (pop,) values} of the connection's
    arguments (Ks, g, r, theta, Ff, Kp, F0), filled by the model's effects
    (``Effect.slots``), the others at their 'off' values (SLOT_OFF: Ks = inf
    with a gap alone, a rigid contact: in contact w = +-h and the law moves
    with the pin, connection.series_stage; g = 0, a plain spring).  No
    force passes in the clearance: there F_int = 0, so a viscous law holds
    still and a friction or hysteretic element unloads through its own
    dashpot and state.  Contact holds while the force keeps its sign; when
    it would reverse, the connection opens, F = 0 until the pin has crossed
    the clearance (a dead band of pin travel about g after each force
    reversal), then contact closes on the other side.  The pin starts
    centred.  Solved by connection.series_population (TR-BDF2, one scalar
    root-find per stage, a step cut where the contact closes).  Returns the
    force [kN], the law's velocity [mm/s], its force with asymmetry and
    heating [kN] and its displacement [mm], each (pop, n_t).  A closed gap
    (g <= 0) or a rigid spring (Ks >= KS_RIGID) is handled by the
    composition: the model without it."""
    c = kernel_array  # writable, contiguous float64: one compiled signature (kernel_cache)
    table = c(np.column_stack([np.asarray(slots[slot], dtype=float) for slot in connection.SLOTS]))
    return connection.series_population(int(law_number), c(x), c(xv), c(xa), float(dt), c(PL), table,
                                        int(substeps))


def _gap_closed(values):
    return values[:, 0] <= 0.0


def _spring_rigid(values):
    return values[:, 0] >= KS_RIGID_FROM


# ------------------------------------------------------------------ output
def asymmetry_force(P, F, x, xv, dt):
    """Tension/compression asymmetry r [-]: F (1 + r) where F > 0 (tension),
    F (1 - r) where F < 0 (compression)."""
    return F * steps.asymmetry_factors(F, _col(P, 0))  # (steps.asymmetry_factor)


def thermal_force(P, F, x, xv, dt):
    """Heating of the fluid, theta [1/MJ]: F exp(-theta E(t)) with

      E(t) = 1e-6 * integral_0^t F_out xv dt  [MJ],

    the energy the law has dissipated so far (its softened force F_out [kN]
    times its velocity xv [mm/s]; 1 kN mm = 1 J).  Computed in the closed
    form exp(theta E) = 1 + theta W0, W0 = 1e-6 integral F xv dt with the
    unsoftened F (steps.thermal_population, trapezoidal rule)."""
    return steps.thermal_population(kernel_array(F), _rows(xv), float(dt), kernel_array(P[:, 0]))


# ---------------------------------------------------------------- parallel
def friction_force(P, t, x, xv, xa):
    """Seal friction Ff [kN]: + Ff tanh(u / v_f), v_f = FRICTION_V_F = 1 mm/s
    (Coulomb friction smoothed over 1 mm/s), u the rod's velocity: the pin's
    velocity xv, also beside an oil column; behind a series_stiffness or a
    gap the law's own velocity (the term is then solved inside the
    connection, element.element_force)."""
    return steps.friction_terms(_col(P, 0), np.asarray(xv))  # (steps.friction_term)


def parallel_force(P, t, x, xv, xa):
    """Accumulator (gas spring) and preload: + Kp x + F0, Kp [kN/mm], F0 [kN],
    x [mm] the rod's displacement: the pin's d, also beside an oil column;
    behind a series_stiffness or a gap (no force passes a clearance at all)
    the term is solved inside the connection on the law's displacement x_o
    (connection_force)."""
    return steps.parallel_springs(_col(P, 0), _col(P, 1), np.asarray(x))  # (steps.parallel_spring)


def inertia_force(P, t, x, xv, xa):
    """Moving mass m [kg]: + m xa 1e-6 [kN], xa [mm/s^2] the measured
    acceleration (the record's a, also with a gap or series spring: the mass
    is taken to move with the pin; 1 kg mm/s^2 = 1e-6 kN)."""
    return steps.inertia_terms(_col(P, 0), np.asarray(xa))  # (steps.inertia_term)


def _stiff(s):
    return s["F"] / s["d"]


def _accel(s):  # peak acceleration of a sinusoid with these peaks: v^2 / d [mm/s^2]
    return s["v"] ** 2 / s["d"]


def _cycle_energy(s):  # dissipated energy of one full cycle [MJ], about pi F d
    return math.pi * s["F"] * s["d"] * 1e-6


#: connections that carry the element's effects of the fluid (asymmetry, heating) inside them
CONNECTIONS = ("gap", "series_stiffness", "oil_column")
#: connections with the whole damper behind them (the seal and the accumulator too)
OUTSIDE = ("gap", "series_stiffness")


def _spring(what: str) -> Parameter:
    return Parameter("Ks", "kN/mm", (10.0, KS_RIGID), lambda s: (min(0.3 * _stiff(s), 1e-3 * KS_RIGID), KS_RIGID),
                     f"{what}; Ks >= {KS_RIGID:.0e} is rigid", log=True)


#: a flexible connection with the whole damper behind it; ``oil_column`` is the same spring inside it
SERIES_STIFFNESS = Effect(
    name="series_stiffness", stage="series", order=20, function=None, none=(math.inf,), slots=("Ks",),
    off_rule=_spring_rigid,
    parameters=(_spring("spring in series with the whole damper (a flexible connection, rod, clevis or "
                        "frame)"),),
    equation="F = Ks (d - x) = element(x, dx/dt) (with a gap: Ks dz(d - x, g/2)); "
             "seal friction and accumulator behind the spring",
    summary="series flexibility outside the damper: a connection, rod or frame spring with the whole damper "
            "(orifice, seal friction, accumulator) behind it (Maxwell model)",
    symptom="force lags the velocity at reversals (tilted loop, force not zero at zero velocity)",
    cause="the connections flex (or the fluid is compressible)",
    cause_hysteretic="the device's body, connections or supports flex in series with it",
    size=sizes.series_spring, reference=(50.0,), fmu=True,
    opensees=OpenSeesForm("the law's series form (laws 1, 2: ViscousDamper Ks C alpha)", None))

BUILTIN = (
    Effect(
        name="gap", stage="series", order=10, function=None, none=(0.0,), slots=("g",), off_rule=_gap_closed,
        parameters=(Parameter("g", "mm", (0.0, 5.0), lambda s: (0.0, 0.2 * s["d"]),
                              "pin clearance (total, g/2 on each side)"),),
        equation="F = Ks dz(d - x, g/2) = element(x, dx/dt), dz(w, h) = w - h (w > h), w + h (w < -h), "
                 "0 (|w| <= h); Ks rigid, or series_stiffness's",
        summary="connection gap: pins and clevises have clearance; no force passes while the pin crosses it "
                "after each force reversal, then contact closes on the other side",
        symptom="force stays near zero just after each reversal (a plateau in the loop)",
        cause="the connection has clearance (play)",
        cause_hysteretic="the connection has play: no force passes while the pin crosses its clearance",
        size=sizes.gap, reference=(1.0,), fmu=True, global_search=True, stepped=("g",),  # the dead zone: local solves stop short
        opensees=OpenSeesForm("the law's series form with ViscousDamper's LGap g (laws 1, 2; 7 with beta 1)",
                              None, accuracy="gap")),
    SERIES_STIFFNESS,
    replace(
        SERIES_STIFFNESS, name="oil_column", arrangement_of="series_stiffness",
        parameters=(_spring("stiffness of the compressible oil column, in series with the orifice only"),),
        equation="F = Ks (d - x) = orifice(x, dx/dt) + seal friction(d') + accumulator(d): the seal and the "
                 "accumulator act on the rod's full stroke, beside the oil column and orifice",
        summary="fluid compressibility inside the damper: the oil column is a spring in series with the orifice, "
                "while seal friction and the accumulator act on the rod's full stroke beside it",
        symptom="force lags the velocity at reversals, while a friction force turns at once with the stroke",
        cause="the oil is compressible (the seal rubs on the rod's full stroke)",
        cause_hysteretic="the fluid or body of the device is compressible while its rubbing parts follow the rod",
        opensees=OpenSeesForm("the law's series form beside the seal and accumulator "
                              "(laws 1, 2: Parallel(ViscousDamper Ks C alpha, friction, spring))", None)),
    Effect(
        name="asymmetry", stage="output", order=40, function=asymmetry_force, none=(0.0,), slots=("r",),
        inside_with=CONNECTIONS,
        parameters=(Parameter("r", "-", (-0.5, 0.5), lambda s: (-0.5, 0.5),
                              "tension/compression force ratio offset"),),
        equation="F_law (1 + r sign(F_law))",
        summary="tension/compression asymmetry: rod-side and cap-side areas or valves differ",
        symptom="peak forces differ in tension and compression",
        cause="the two piston sides or valves differ",
        cause_hysteretic="the device is stronger in one direction (clamping or contact conditions differ)",
        size=sizes.asymmetry, reference=(0.1,), fmu=True, opensees=asymmetric,
        offset_like=True),  # F_law + r |F_law|: a mean of r mean|F_law| over a cycle, as an offset has
    Effect(
        name="thermal_softening", stage="output", order=50, function=thermal_force, none=(0.0,),
        slots=("theta",), inside_with=CONNECTIONS,
        parameters=(Parameter("theta", "1/MJ", (0.0, 10.0), lambda s: (0.0, 1.0 / _cycle_energy(s)),
                              "force loss per MJ dissipated", log=True),),
        equation="F_law exp(-theta E), E = 1e-6 integral (F_law exp(-theta E)) u dt [MJ]",
        summary="heating: dissipated energy warms the oil and the force falls cycle after cycle",
        symptom="force falls from cycle to cycle (residual grows with time and dissipated energy)",
        cause="the oil heats up and its viscosity drops",
        cause_hysteretic="the dissipated energy heats the sliding surfaces and the friction coefficient falls",
        size=sizes.heating, reference=(5.0,), fmu=True,
        no_opensees="thermal_softening (force falling with dissipated energy)"),
    Effect(
        name="friction", stage="parallel", order=60, function=friction_force, none=(0.0,), slots=("Ff",),
        inside_with=OUTSIDE,
        parameters=(Parameter("Ff", "kN", (0.0, 30.0), lambda s: (0.0, 0.3 * s["F"]),
                              "seal friction force"),),
        equation=f"+ Ff tanh(u / v_f), v_f = {FRICTION_V_F:g} mm/s, u the law's velocity",
        summary="seal friction: a nearly constant force opposing motion, dominant at low velocity",
        symptom="loops are too square at low velocity (a constant force the law misses)",
        cause="the seals rub",
        cause_hysteretic="an extra rubbing contact (seals, guides) adds a nearly constant force",
        size=sizes.friction, reference=(5.0,), fmu=True, opensees=friction),
    Effect(
        name="parallel_stiffness", stage="parallel", order=70, function=parallel_force, none=(0.0, 0.0),
        slots=("Kp", "F0"), inside_with=OUTSIDE,
        parameters=(Parameter("Kp", "kN/mm", (-5.0, 10.0), lambda s: (-0.5 * _stiff(s), _stiff(s)),
                              "parallel stiffness (accumulator, gas spring)"),
                    Parameter("F0", "kN", (-30.0, 30.0), lambda s: (-0.2 * s["F"], 0.2 * s["F"]),
                              "preload")),
        equation="+ Kp x + F0 (x = d; behind series_stiffness or a gap: the law's displacement)",
        summary="accumulator / gas spring and preload: a static stiffness and an offset force",
        symptom="residual grows with displacement and has an offset",
        cause="pressurised fluid acts as a spring with a preload",
        cause_hysteretic="the device or its supports carry a static spring (an elastic element beside "
                         "the friction or hysteretic element) and a preload",
        size=sizes.parallel_spring, reference=(1.0, 3.0), fmu=True, opensees=parallel_spring,
        offset_like=True),  # the preload F0: a force at d = 0, v = 0, as a load cell's zero
    Effect(
        name="inertia", stage="parallel", order=80, function=inertia_force, none=(0.0,), slots=("m",),
        parameters=(Parameter("m", "kg", (0.0, 1e4), lambda s: (0.0, 0.5 * s["F"] / _accel(s) * 1e6),
                              "moving mass (fluid and piston)"),),
        equation="+ m a 1e-6 (a the measured acceleration, also with a gap)",
        summary="inertia: moving fluid and piston mass, a force proportional to acceleration",
        symptom="residual follows the acceleration (grows with frequency, peaks at the reversals)",
        cause="fluid and piston mass are accelerated", cause_hysteretic="accelerated mass of the moving parts",
        size=sizes.inertia, reference=(1000.0,), fmu=True, no_opensees="inertia (a mass, not a material)"),
)

EFFECTS = {e.name: e for e in BUILTIN}
#: the connection's arguments and their 'off' values (a rigid spring, no gap, no effect inside)
SLOT_OFF = {slot: off for e in BUILTIN for slot, off in zip(e.slots, e.none)}
#: the built-in effects' parameters in registry order ('effect.param'): the FMU's layout
EFFECT_PARAMETERS = tuple(n for e in BUILTIN for n in e.names)
