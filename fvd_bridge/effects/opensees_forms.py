"""The effects' OpenSees forms (the registry's ``OpenSeesForm`` of the
built-in effects): an output effect wraps the element's material
(``build(s, tag, p)``), a parallel effect adds a term beside it
(``build(s, p)``); p holds the effect's parameters {name: value} (kN, mm,
s).  Each material's behaviour was read in its source, OpenSees
SRC/material/uniaxial/<Name>.cpp.
"""

from __future__ import annotations

import math

from ..laws.base import OpenSeesForm
from ..laws.opensees_forms import TENSION_ONLY_RESIDUAL
from .steps import FRICTION_V_F

#: largest error of the tabulated friction Ff tanh(v / v_f), a fraction of Ff
FRICTION_TABLE_ERROR = 1e-4


def _asymmetric(s, law: int, p: dict) -> int:
    """F (1 + r) for F > 0, F (1 - r) for F < 0 (asymmetry) of the stateless
    material ``law``: a T(M) + b T(-M), T = ``TensionOnly`` (f, or eps f for
    f < 0), -M = ``Multiplier`` M -1, a = ((1 + r) - eps (1 - r))/(1 - eps^2),
    b = (eps (1 + r) - (1 - r))/(1 - eps^2), eps = TENSION_ONLY_RESIDUAL."""
    r, eps = p["r"], TENSION_ONLY_RESIDUAL
    a = ((1.0 + r) - eps * (1.0 - r)) / (1.0 - eps * eps)
    b = (eps * (1.0 + r) - (1.0 - r)) / (1.0 - eps * eps)
    tension = s.mat("TensionOnly", law)
    compression = s.mat("TensionOnly", s.mat("Multiplier", law, -1.0))
    return s.parallel([tension, compression], [a, b])


def friction_table(Ff: float, tol: float = FRICTION_TABLE_ERROR) -> tuple[list, list]:
    """Points (v [mm/s], F [kN]) of Ff tanh(v / v_f), linear between them to
    within tol Ff: spacing sqrt(8 tol / |f''|) in x = v / v_f, f'' = -2 tanh
    sech^2 (peak 0.7698 at x = 0.6585, |f''| falls beyond), flat at +-Ff from
    where 1 - tanh x <= tol to x = 1e6."""
    x_peak, peak = 0.6585, 0.7698
    xs = [0.0]
    while 1.0 - math.tanh(xs[-1]) > tol:
        x = xs[-1]
        curv = peak if x < x_peak else 2.0 * math.tanh(x) / math.cosh(x) ** 2
        xs.append(x + math.sqrt(8.0 * tol / curv))
    xs.append(1e6)
    ys = [math.tanh(x) for x in xs[:-1]] + [1.0]
    v = [-x * FRICTION_V_F for x in reversed(xs[1:])] + [x * FRICTION_V_F for x in xs]
    F = [-Ff * y for y in reversed(ys[1:])] + [Ff * y for y in ys]
    return v, F


def _friction(s, p: dict) -> int:
    """Ff tanh(v / v_f) [kN]: ``Damper`` (its member sees the strain rate as
    strain, DamperMaterial.cpp) around an ``ElasticMultiLinear`` table."""
    s.notes.append(f"friction tanh tabulated to {FRICTION_TABLE_ERROR:g} Ff")
    s.tabulated += FRICTION_TABLE_ERROR * abs(p["Ff"])
    v, F = friction_table(p["Ff"])  # v in mm/s: in the export's units
    return s.mat("Damper", s.mat("ElasticMultiLinear", "-strain", *(x * s.velocity for x in v), "-stress", *F))


def _parallel_spring(s, p: dict) -> int:
    """Kp d + F0 [kN]: ``Elastic`` Kp, shifted to F0 at d = 0 by
    ``InitStressMaterial``; a constant F0 (Kp = 0) is a flat two-point
    ``ElasticMultiLinear`` (extrapolated beyond its points)."""
    Kp, F0 = p["Kp"], p["F0"]
    if F0 == 0.0:
        return s.mat("Elastic", Kp)
    if Kp == 0.0:
        return s.mat("ElasticMultiLinear", "-strain", -1.0, 1.0, "-stress", F0, F0)
    return s.mat("InitStressMaterial", s.mat("Elastic", Kp), F0)


#: output effect: needs a stateless law (TensionOnly does not commit a state under compression)
asymmetric = OpenSeesForm("Parallel(TensionOnly(M), TensionOnly(Multiplier M -1)) -factors a b", _asymmetric,
                          needs_stateless=True)
friction = OpenSeesForm("Damper(ElasticMultiLinear table of Ff tanh(v/v_f))", _friction, accuracy="table")
parallel_spring = OpenSeesForm("Elastic Kp, InitStressMaterial F0 on it; Kp = 0: flat ElasticMultiLinear F0",
                               _parallel_spring)
