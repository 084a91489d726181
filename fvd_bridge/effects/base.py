"""What a physical effect is: a named term that composes with any law.

An effect has parameters (units, bounds derived from the record's scales),
the parameter values that switch it off (``none``: the model with the effect
switched off is the model without it, so models are nested), an equation, and
a vectorized function for its *stage* in the composition::

    d, v, a --[input]--> x, xv, xa          the pin's motion (a user's input effects)
    x, xv --[series]--> x_o, u              the law's own motion behind the connection
                                            (a series spring, a contact gap; x_o = x without)
    F_law = law(x_o, u) --[output]--> F_el  the internal element's force
    F = F_el + sum of [parallel] terms(x, xv, xa)

==========  =======================================  ===================================
stage       function signature (P: (pop, n_par))     returns
==========  =======================================  ===================================
input       fn(P, d, v, a, dt)                       (x, xv, xa), each (pop, n_t): the
                                                     motion the damper body sees
output      fn(P, F, x, xv, dt)                      F (pop, n_t): the law's force F
                                                     (pop, n_t) transformed; x, xv the
                                                     law's displacement and velocity
parallel    fn(P, t, x, xv, xa)                      a force (pop, n_t) or broadcastable,
                                                     added to the damper's force
series      fn(P) (None: the parameters fill         a tuple of (pop,) values, one for
            ``slots`` in order; built-in gap and     each of its ``slots``: the
            series_stiffness)                        connection's spring Ks [kN/mm]
                                                     and clearance g [mm]
==========  =======================================  ===================================

d [mm], v [mm/s], a [mm/s^2], t [s] are the record's (n_t,) arrays, dt [s]
its step; x, xv, xa are (pop, n_t) or (1, n_t).  Force is in kN, positive in
tension.  Within a stage effects apply in increasing ``order`` (built-ins:
gap 10, series_stiffness and oil_column 20, asymmetry 40, thermal_softening 50, friction 60,
parallel_stiffness 70, inertia 80; a user effect defaults to 100).

The series stage is the connection (``connection.py``): the law in step form
behind a spring and a clearance.  An effect declares which of its arguments
it fills (``slots``: a series effect, a user's too, sets Ks or g, e.g. Ks
from an oil column's bulk modulus; the built-in element effects fill the
element's r, theta, Ff, Kp, F0 with their parameters); an effect
whose ``inside_with`` names a connection effect of the model is solved inside
that connection, on the law's own motion (asymmetry and heating behind
any connection; seal friction and the accumulator behind a series_stiffness
or a gap, but beside an oil_column, on the rod's full stroke); a user
effect is then applied outside the connection.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..laws.base import OpenSeesForm, Parameter

STAGES = ("input", "series", "output", "parallel")

__all__ = ["Effect", "OpenSeesForm", "Parameter", "STAGES", "Size"]


@dataclass(frozen=True)
class Size:
    """One fitted effect in physical terms (an effect's ``size``)."""

    text: str  # "gap 1.97 mm (7.9% of the stroke)"
    detectable: bool = True
    plausible: bool = True
    why: str = ""  # why not detectable / not plausible


@dataclass(frozen=True)
class Effect:
    """One physical effect (see the module docstring for the stages).

    ``summary``: one line for the user ("seal friction: a nearly constant force
    opposing motion"); ``symptom`` and ``cause``: how the misfit looks and why,
    in the user's words, joined by diagnose into "SYMPTOM: CAUSE; add NAME";
    ``none``: parameter values [units] that switch the effect off (inside the
    bounds, so the model without the effect is nested in the one with it);
    ``off(values)``: which rows (pop, n_par) are switched off (default: at
    ``none``; a gap closed at g <= 0, a spring rigid from KS_RIGID).

    ``source``: where it is declared ("built-in", or a plugin file's name)
    and ``source_sha256`` that file's content hash (hex), which a
    calibration file records and checks when it is read.

    Capabilities (read by composition, diagnose and the exporters):
    ``slots``: the connection kernel's arguments its parameters fill;
    ``inside_with``: connection effects inside which it is solved;
    ``size(values, scales)``: the fitted effect in physical terms
    (``Size``; values {param: value}, scales the record's peaks F, d, v, a,
    dt, its displacement noise sigma_d and dissipated energy W [MJ]);
    ``cause_hysteretic``: the cause in words for a friction or hysteretic
    device; ``reference``: parameter values of the golden files;
    ``opensees``: its OpenSees form (None: not expressible, ``no_opensees``
    says why); ``fmu``: the FMU's C code carries it; ``arrangement_of``: the
    effect it places elsewhere in the damper (oil_column: series_stiffness's
    spring, with the seal and accumulator beside it instead of behind it),
    so that diagnose ranks the two arrangements against each other;
    ``global_search``: a model with it has basins a local solve does not
    always leave (the gap's dead zone), so the default optimizer checks its
    local optimum with DE (``LocalSettings.always_check``);
    ``stepped``: its parameters on which the OF moves in steps, flat
    between them (a gap's clearance g: a contact that closes moves its
    force jump across a sample at once), so a least-squares step sees no
    slope there and the local search searches them along a line
    (``fit.local``);
    ``offset_like``: its force can shift the loop as a load cell's zero
    does (a term that does not vanish at d = 0, v = 0, or whose mean over a
    cycle is not zero), so diagnose credits it only where it helps beyond
    the tests' force zero (``diagnose.zero``).
    """

    name: str
    stage: str
    parameters: tuple
    none: tuple
    function: Callable | None
    equation: str
    summary: str
    symptom: str = "the residual has structure the law cannot follow"
    cause: str = "a missing physical effect"
    order: int = 100
    source: str = "built-in"
    slots: tuple = ()
    inside_with: tuple = ()
    off_rule: Callable | None = None
    size: Callable | None = None
    cause_hysteretic: str = ""
    reference: tuple = ()
    opensees: OpenSeesForm | None = None
    no_opensees: str = ""
    fmu: bool = False
    arrangement_of: str = ""
    global_search: bool = False
    stepped: tuple = ()
    offset_like: bool = False
    source_sha256: str = ""

    @property
    def names(self) -> list[str]:
        """Parameter names as they appear in a model: 'effect.param'."""
        return [f"{self.name}.{p.name}" for p in self.parameters]

    def bounds(self, scales: dict) -> np.ndarray:
        """(n_par, 2) search bounds from the record's peak F [kN], v [mm/s], d [mm]."""
        return np.asarray([p.auto(scales) for p in self.parameters], dtype=float).reshape(-1, 2)

    def off(self, values) -> np.ndarray:
        """Rows of ``values`` (pop, n_par) in which the effect is switched off."""
        values = np.atleast_2d(np.asarray(values, dtype=float))
        if self.off_rule:
            return self.off_rule(values)
        return np.all(values == np.asarray(self.none, dtype=float), axis=1)

    def explanation(self) -> str:
        """'force lags the velocity at reversals: the fluid is compressible; add series_stiffness'."""
        return f"{self.symptom}: {self.cause}; add {self.name}"
