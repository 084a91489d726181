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
series      (built in: gap and series_stiffness; they need the law in step form)
==========  =======================================  ===================================

d [mm], v [mm/s], a [mm/s^2], t [s] are the record's (n_t,) arrays, dt [s]
its step; x, xv, xa are (pop, n_t) or (1, n_t).  Force is in kN, positive in
tension.  Within a stage effects apply in increasing ``order`` (built-ins:
gap 10, series_stiffness 20, asymmetry 40, thermal_softening 50, friction 60,
parallel_stiffness 70, inertia 80; a user effect defaults to 100).

With a series spring or gap the built-in asymmetry, thermal_softening and
friction belong to the internal element that the connection carries
(``series_slot`` names the argument of the series kernel that takes them;
behind a gap parallel_stiffness too, compose.BEHIND_GAP); a user effect is
then applied outside the connection.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..laws.base import Parameter

STAGES = ("input", "series", "output", "parallel")

__all__ = ["Effect", "Parameter", "STAGES"]


@dataclass(frozen=True)
class Effect:
    """One physical effect (see the module docstring for the stages).

    ``summary``: one line for the user ("seal friction: a nearly constant force
    opposing motion"); ``symptom`` and ``cause``: how the misfit looks and why,
    in the user's words, joined by diagnose into "SYMPTOM: CAUSE; add NAME";
    ``none``: parameter values [units] that switch the effect off (inside the
    bounds, so the model without the effect is nested in the one with it).
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
    series_slot: str = ""

    @property
    def names(self) -> list[str]:
        """Parameter names as they appear in a model: 'effect.param'."""
        return [f"{self.name}.{p.name}" for p in self.parameters]

    def bounds(self, scales: dict) -> np.ndarray:
        """(n_par, 2) search bounds from the record's peak F [kN], v [mm/s], d [mm]."""
        return np.asarray([p.auto(scales) for p in self.parameters], dtype=float).reshape(-1, 2)

    def explanation(self) -> str:
        """'force lags the velocity at reversals: the fluid is compressible; add series_stiffness'."""
        return f"{self.symptom}: {self.cause}; add {self.name}"
