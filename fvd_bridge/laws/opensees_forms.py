"""The laws' OpenSees forms: which native uniaxial materials express each law
(the registry's ``OpenSeesForm`` of laws 1-9; a law may also declare its form
inline).  Each builder adds materials to a script builder s (``s.mat``,
``s.parallel``, ``s.notes``: ``fvd_bridge.export.opensees``; a material
that integrates over the analysis' global time step is made with
``s.mat(..., global_step=True)``) from the law's
parameters p {name: value} (kN, mm, s) and returns the tag of the law's
material.  Each material's behaviour was read in its source, OpenSees
SRC/material/uniaxial/<Name>.cpp.
"""

from __future__ import annotations

import math

from .base import OpenSeesForm

#: TensionOnly's stress for f < 0 is this times f (TensionOnlyMaterial.cpp, getStress)
TENSION_ONLY_RESIDUAL = 1e-4


#: a ``Viscous`` dashpot with an exponent below this defeats Newton at velocity
#: reversals (its tangent is unbounded there: frames/transient.py)
NEWTON_ALPHA = 0.5


def viscous(s, C, alpha=1.0) -> int:
    """C sign(v)|v|^alpha [kN], v [mm/s]: ``Viscous`` (ViscousMaterial.cpp)."""
    return s.mat("Viscous", C, alpha)


def even_square(s, K2) -> list:
    """K2 d^2 [kN], even in d (law 4): ``ElasticPowerFunc`` gives the odd
    +-|K2| sign(d) d^2 and ``TensionOnly`` T keeps f >= 0 and eps f below
    (eps = TENSION_ONLY_RESIDUAL), so T(+) + T(-) = (1 - eps)|K2| d^2; the
    caller's factors sign(K2)/(1 - eps) make it K2 d^2."""
    pos = s.mat("ElasticPowerFunc", "-coeff", abs(K2), "-exp", 2.0)
    neg = s.mat("ElasticPowerFunc", "-coeff", -abs(K2), "-exp", 2.0)
    return [s.mat("TensionOnly", pos), s.mat("TensionOnly", neg)]


def bouc_wen(s, alpha, K, beta, gamma) -> int:
    """alpha K d + (1 - alpha) K z, dz/dd = 1 - |z|(gamma + beta sign(dd z)):
    ``BoucWen`` alpha ko=K n=1 gamma beta Ao=1 deltaA=deltaNu=deltaEta=0
    (BoucWenMaterial.cpp; z by one implicit Euler step per increment)."""
    s.notes.append("BoucWen integrates z by one implicit Euler step per strain increment")
    return s.mat("BoucWen", alpha, K, 1.0, gamma, beta, 1.0, 0.0, 0.0, 0.0)


def maxwell(s, Ks, C, alpha=1.0, gap=0.0) -> int:
    """A spring Ks [kN/mm] in series with C sign(v)|v|^alpha: ``ViscousDamper``
    K C alpha, dF/dt = K (v - sign(F)|F/C|^(1/alpha)) (ViscousDamper.cpp);
    behind a pin clearance ``gap`` [mm] (total) its LGap: the force stays
    zero while the strain travels LGap from each force reversal (the zero
    crossing, interpolated in the step), then the Maxwell state restarts
    from zero force: the pin crossing its clearance (effect ``gap``)."""
    return s.mat("ViscousDamper", Ks, C, alpha, *((gap,) if gap > 0.0 else ()), global_step=True)


def _law4(s, p) -> int:
    tags = [s.mat("Elastic", p["K1"]), viscous(s, p["C"], p["alpha"])]
    if p["K2"] == 0.0:
        return s.parallel(tags)
    f = math.copysign(1.0 / (1.0 - TENSION_ONLY_RESIDUAL), p["K2"])
    return s.parallel(tags + even_square(s, p["K2"]), [1.0, 1.0, f, f])


def _law8(s, p) -> int:
    """z mu N with z in [-1, 1]: elastic-perfectly-plastic, E = K, yield mu N."""
    mu_N, tags = p["mu"] * p["N"], [viscous(s, p["C"])]
    if mu_N > 0.0 and p["K"] > 0.0:
        tags.insert(0, s.mat("ElasticPP", p["K"], mu_N / p["K"]))
    return s.parallel(tags)


def _law7_refuse(p) -> str:
    return "" if p["beta"] == 1.0 else f"law 7 with beta = {p['beta']:g} (a power-law spring behind the dashpot)"


LAW1 = OpenSeesForm("Viscous C 1", lambda s, p: viscous(s, p["C"]), stateless=True,
                    series=lambda s, p, Ks, g=0.0: maxwell(s, Ks, p["C"], 1.0, g))
LAW2 = OpenSeesForm("Viscous C alpha", lambda s, p: viscous(s, p["C"], p["alpha"]), stateless=True,
                    series=lambda s, p, Ks, g=0.0: maxwell(s, Ks, p["C"], p["alpha"], g))
LAW3 = OpenSeesForm("Parallel(Elastic K1, Viscous C alpha)",
                    lambda s, p: s.parallel([s.mat("Elastic", p["K1"]), viscous(s, p["C"], p["alpha"])]),
                    stateless=True, exponent="alpha")
LAW4 = OpenSeesForm("Parallel(Elastic K1, Viscous, 2 TensionOnly of ElasticPowerFunc +-abs(K2) exp 2)",
                    _law4, stateless=True, exponent="alpha")
LAW5 = OpenSeesForm("Parallel(ElasticPowerFunc K beta, Viscous)",
                    lambda s, p: s.parallel([s.mat("ElasticPowerFunc", "-coeff", p["K"], "-exp", p["beta"]),
                                             viscous(s, p["C"], p["alpha"])]), stateless=True, exponent="alpha")
# law 6: A = n = 1, gamma = beta (fvd_bridge.laws.steps.law6_bouc_wen)
LAW6 = OpenSeesForm("Parallel(BoucWen alpha K 1 beta beta 1 0 0 0, Viscous C 1)",
                    lambda s, p: s.parallel([bouc_wen(s, p["alpha"], p["K"], p["beta"], p["beta"]),
                                             viscous(s, p["C"])]), accuracy="hysteretic")
# law 7's own linear spring K adds in series with a series spring Ks: K Ks/(K + Ks)
LAW7 = OpenSeesForm("ViscousDamper K C alpha (beta = 1 only)",
                    lambda s, p: maxwell(s, p["K"], p["C"], p["alpha"]), refuse=_law7_refuse,
                    series=lambda s, p, Ks, g=0.0: maxwell(s, p["K"] * Ks / (p["K"] + Ks), p["C"], p["alpha"], g))
LAW8 = OpenSeesForm("Parallel(ElasticPP K muN/K, Viscous C 1)", _law8)
# law 9: dz/dd = 1 - alpha sign(dd) z: Bouc-Wen with alpha = 0, gamma = 0
LAW9 = OpenSeesForm("Parallel(BoucWen 0 beta 1 0 alpha 1 0 0 0, Viscous C 1)",
                    lambda s, p: s.parallel([bouc_wen(s, 0.0, p["beta"], p["alpha"], 0.0), viscous(s, p["C"])]),
                    accuracy="hysteretic")
