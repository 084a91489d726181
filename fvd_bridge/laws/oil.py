"""Law 10, the bilinear oil damper of Japanese practice, in step form.

A spring K [kN/mm] (the oil column and the body) in series with a dashpot
whose force is C v_d up to the relief force Fr [kN], where the relief valve
opens, and Fr + p C (|v_d| - Fr/C) beyond it (Kasai et al. 2004; OpenSees
``BilinearOilDamper``, Akcelyan and Lignos):

  F = K (x - x_d),  dx_d/dt = v_d(F),
  v_d(F) = F / C                                   for |F| <= Fr,
           sign(F) (Fr / C + (|F| - Fr) / (p C))   beyond,

C [kN s/mm] the pre-relief and p C the post-relief damping coefficient
(p [-]).  The spring force F is the state.  One sub-step h [s] with the
velocity linear from va to vb [mm/s] is TR-BDF2 (Bank et al. 1985, as law
7's: L-stable, so the stiff post-relief branch, time constant p C / K,
neither rings nor lags): a trapezoidal stage to t + gamma h, then BDF2 to
t + h.  Each stage is F + c v_d(F) = R, c > 0, monotone and piecewise
linear in F: solved exactly (``oil_solve``).  Mirrored in C by
``fmu/laws.c``.  Units: kN, mm, s.
"""

from __future__ import annotations

import math

from .fastmath import scalar
from .trbdf2 import TRBDF2_GAMMA


@scalar
def relief_velocity(F, C, Fr, p):
    """Dashpot velocity v_d [mm/s] at the force F [kN]."""
    if abs(F) <= Fr:
        return F / C
    return math.copysign(Fr / C + (abs(F) - Fr) / (p * C), F)


@scalar
def oil_solve(R, c, C, Fr, p):
    """F with F + c v_d(F) = R [kN], c [kN s/mm] > 0: on the elastic branch
    F = R / (1 + c / C); beyond the relief force
    |F| = Fr + (|R| - Fr (1 + c / C)) p C / (p C + c)."""
    F = R / (1.0 + c / C)
    if abs(F) <= Fr:
        return F
    pC = p * C
    return math.copysign(Fr + (abs(R) - Fr * (1.0 + c / C)) * pC / (pC + c), R)


@scalar
def oil_step(K, C, Fr, p, F, va, vb, h):
    """The spring force [kN] after a sub-step h [s] from F, the velocity linear
    from va to vb [mm/s] (module docstring):

      F_g + c_1 v_d(F_g) = F + K psi_g - c_1 v_d(F),       c_1 = K gamma h / 2,
      F_1 + c_2 v_d(F_1) = c_g F_g - c_0 F + K (psi_h - c_g psi_g),  c_2 = K c_h,

    psi_g, psi_h the travel to t + gamma h and t + h, c_g = 1/(gamma (2 -
    gamma)), c_0 = (1 - gamma)^2 c_g, c_h = (1 - gamma)/(2 - gamma) h."""
    g = TRBDF2_GAMMA
    c_g = 1.0 / (g * (2.0 - g))
    c_0 = (1.0 - g) ** 2 * c_g
    c_h = (1.0 - g) / (2.0 - g) * h
    psi_g = g * h * (va + 0.5 * g * (vb - va))
    psi_h = 0.5 * h * (va + vb)
    c_1 = 0.5 * K * g * h
    F_g = oil_solve(F + K * psi_g - c_1 * relief_velocity(F, C, Fr, p), c_1, C, Fr, p)
    return oil_solve(c_g * F_g - c_0 * F + K * (psi_h - c_g * psi_g), K * c_h, C, Fr, p)
