"""The seven built-in physical effects (their fingerprints: README, "Physical effects").

Each effect's equation lives in the docstring of the function that computes
it.  Bounds scale with the record: F = peak force [kN], v = peak velocity
[mm/s], d = peak displacement [mm]; each range contains the value that
switches the effect off.  Forces in kN, positive in tension.
"""

from __future__ import annotations

import math

import numpy as np

from ..laws.base import Parameter
from . import steps
from .base import Effect

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
    return np.ascontiguousarray(np.atleast_2d(x), dtype=float)


# ------------------------------------------------------------------ series
def _connection(law_number, PL, x, xv, xa, dt, Ks, g, r, theta, Ff, Kp, F0, substeps):
    c = np.ascontiguousarray
    return steps.series_population(int(law_number), c(x, dtype=float), c(xv, dtype=float), c(xa, dtype=float),
                                     float(dt), c(Ks, dtype=float), c(g, dtype=float), c(PL, dtype=float),
                                     c(r, dtype=float), c(theta, dtype=float), c(Ff, dtype=float),
                                     c(Kp, dtype=float), c(F0, dtype=float), int(substeps))


def gap_force(P, law_number, PL, x, xv, xa, dt, Ks, r, theta, Ff, Kp, F0, substeps=1):
    """Pin clearance g [mm] (total; h = g/2 on each side): a contact gap in
    series with the internal element (the law with asymmetry r, heating
    theta, friction Ff and the parallel spring Kp [kN/mm], F0 [kN]; zeros
    when those effects are absent), for any law 1-9:

      F = Ks dz(w, h) = F_int(x_o, dx_o/dt),  w = x - x_o,
      dz(w, h) = w - h (w > h),  w + h (w < -h),  0 (|w| <= h),

    x, xv, xa the pin's motion (the record's d, v, a), x_o the law's
    displacement, Ks [kN/mm] per row: series_stiffness's Ks (a spring and
    the gap in series: a dead-zone spring) or inf (a rigid contact: in
    contact w = +-h and the law moves with the pin, steps.series_stage).
    No force passes in the clearance: there F_int = 0, so a viscous law
    holds still and a friction or hysteretic element unloads through its
    own dashpot and state.  Contact holds while the force keeps its sign;
    when it would reverse, the connection opens, F = 0 until the pin has
    crossed the clearance (a dead band of pin travel about g after each
    force reversal), then contact closes on the other side.  The pin starts
    centred.  Solved by steps.series_population (TR-BDF2, one scalar
    root-find per stage, a step cut where the contact closes).  Returns
    the force [kN], the law's velocity [mm/s], its force with asymmetry and
    heating [kN] and its displacement [mm], each (pop, n_t).  g <= 0 is no
    gap (handled by the composition: the model without it)."""
    return _connection(law_number, PL, x, xv, xa, dt, Ks, P[:, 0], r, theta, Ff, Kp, F0, substeps)


def series_force(P, law_number, PL, x, xv, xa, dt, r, theta, Ff, substeps=1):
    """Fluid compressibility and connection flexibility, Ks [kN/mm]: a spring
    in series with the internal element (the law with asymmetry r, heating
    theta and friction Ff; zeros when those effects are absent), a Maxwell
    model for any law 1-9:

      F = Ks (x - x_o) = element(x_o, dx_o/dt),

    x, xv, xa the pin's motion (the record's d, v, a), x_o the law's own
    displacement.  Solved per step by TR-BDF2 with one scalar root-find per
    stage (steps.series_population).  Returns the force through the spring
    [kN], the law's velocity [mm/s], the law's force with asymmetry and
    heating [kN] and the law's displacement [mm], each (pop, n_t).
    Ks >= KS_RIGID is a rigid connection (handled by the composition: the
    model without it).  With a gap the composition calls gap_force, whose
    spring has the gap's dead zone."""
    zeros = np.zeros(P.shape[0])
    return _connection(law_number, PL, x, xv, xa, dt, P[:, 0], zeros, r, theta, Ff, zeros, zeros, substeps)


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
    return steps.thermal_population(np.ascontiguousarray(F, dtype=float), _rows(xv), float(dt),
                                      np.ascontiguousarray(P[:, 0], dtype=float))


# ---------------------------------------------------------------- parallel
def friction_force(P, t, x, xv, xa):
    """Seal friction Ff [kN]: + Ff tanh(u / v_f), v_f = FRICTION_V_F = 1 mm/s
    (Coulomb friction smoothed over 1 mm/s), u the law's velocity (the
    pin's velocity xv without a series spring or gap; with one the term is
    solved inside the connection, steps.element_force)."""
    return steps.friction_terms(_col(P, 0), np.asarray(xv))  # (steps.friction_term)


def parallel_force(P, t, x, xv, xa):
    """Accumulator (gas spring) and preload: + Kp x + F0, Kp [kN/mm], F0 [kN],
    x [mm] the pin's displacement d.  With a gap the accumulator is behind
    the clearance (no force passes there at all): the term is solved inside
    the connection on the law's displacement x_o (gap_force)."""
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


BUILTIN = (
    Effect(
        name="gap", stage="series", order=10, function=gap_force, none=(0.0,),
        parameters=(Parameter("g", "mm", (0.0, 5.0), lambda s: (0.0, 0.2 * s["d"]),
                              "pin clearance (total, g/2 on each side)"),),
        equation="F = Ks dz(d - x, g/2) = element(x, dx/dt), dz(w, h) = w - h (w > h), w + h (w < -h), "
                 "0 (|w| <= h); Ks rigid, or series_stiffness's",
        summary="connection gap: pins and clevises have clearance; no force passes while the pin crosses it "
                "after each force reversal, then contact closes on the other side",
        symptom="force stays near zero just after each reversal (a plateau in the loop)",
        cause="the connection has clearance (play)"),
    Effect(
        name="series_stiffness", stage="series", order=20, function=series_force, none=(math.inf,),
        parameters=(Parameter("Ks", "kN/mm", (10.0, KS_RIGID),
                              lambda s: (min(0.3 * _stiff(s), 1e-3 * KS_RIGID), KS_RIGID),
                              f"spring in series with the law (oil, seals, rod, frame); "
                              f"Ks >= {KS_RIGID:.0e} is a rigid connection", log=True),),
        equation="F = Ks (d - x) = element(x, dx/dt) (with a gap: Ks dz(d - x, g/2))",
        summary="fluid compressibility / series flexibility: a spring in series with the orifice "
                "(Maxwell model)",
        symptom="force lags the velocity at reversals (tilted loop, force not zero at zero velocity)",
        cause="the fluid is compressible and the connections flex"),
    Effect(
        name="asymmetry", stage="output", order=40, series_slot="r", function=asymmetry_force, none=(0.0,),
        parameters=(Parameter("r", "-", (-0.5, 0.5), lambda s: (-0.5, 0.5),
                              "tension/compression force ratio offset"),),
        equation="F_law (1 + r sign(F_law))",
        summary="tension/compression asymmetry: rod-side and cap-side areas or valves differ",
        symptom="peak forces differ in tension and compression",
        cause="the two piston sides or valves differ"),
    Effect(
        name="thermal_softening", stage="output", order=50, series_slot="theta", function=thermal_force, none=(0.0,),
        parameters=(Parameter("theta", "1/MJ", (0.0, 10.0), lambda s: (0.0, 1.0 / _cycle_energy(s)),
                              "force loss per MJ dissipated", log=True),),
        equation="F_law exp(-theta E), E = 1e-6 integral (F_law exp(-theta E)) u dt [MJ]",
        summary="heating: dissipated energy warms the oil and the force falls cycle after cycle",
        symptom="force falls from cycle to cycle (residual grows with time and dissipated energy)",
        cause="the oil heats up and its viscosity drops"),
    Effect(
        name="friction", stage="parallel", order=60, series_slot="Ff", function=friction_force, none=(0.0,),
        parameters=(Parameter("Ff", "kN", (0.0, 30.0), lambda s: (0.0, 0.3 * s["F"]),
                              "seal friction force"),),
        equation=f"+ Ff tanh(u / v_f), v_f = {FRICTION_V_F:g} mm/s, u the law's velocity",
        summary="seal friction: a nearly constant force opposing motion, dominant at low velocity",
        symptom="loops are too square at low velocity (a constant force the law misses)",
        cause="the seals rub"),
    Effect(
        name="parallel_stiffness", stage="parallel", order=70, function=parallel_force, none=(0.0, 0.0),
        parameters=(Parameter("Kp", "kN/mm", (-5.0, 10.0), lambda s: (-0.5 * _stiff(s), _stiff(s)),
                              "parallel stiffness (accumulator, gas spring)"),
                    Parameter("F0", "kN", (-30.0, 30.0), lambda s: (-0.2 * s["F"], 0.2 * s["F"]),
                              "preload")),
        equation="+ Kp x + F0 (x = d; with a gap: the law's displacement, behind the clearance)",
        summary="accumulator / gas spring and preload: a static stiffness and an offset force",
        symptom="residual grows with displacement and has an offset",
        cause="pressurised fluid acts as a spring with a preload"),
    Effect(
        name="inertia", stage="parallel", order=80, function=inertia_force, none=(0.0,),
        parameters=(Parameter("m", "kg", (0.0, 1e4), lambda s: (0.0, 0.5 * s["F"] / _accel(s) * 1e6),
                              "moving mass (fluid and piston)"),),
        equation="+ m a 1e-6 (a the measured acceleration, also with a gap)",
        summary="inertia: moving fluid and piston mass, a force proportional to acceleration",
        symptom="residual follows the acceleration (grows with frequency, peaks at the reversals)",
        cause="fluid and piston mass are accelerated"),
)

EFFECTS = {e.name: e for e in BUILTIN}
