"""OpenSees export: a calibrated damper model as a list of command tuples.

``opensees_export(model, params, tag)`` maps the model on native OpenSees
uniaxial materials, each command a tuple (ops function name, *args); the
damper is material ``tag``, helpers tag+1, tag+2, ...  ``to_script`` and
``apply`` are thin layers over that one list.  Each material's behaviour was
read in its source, OpenSees SRC/material/uniaxial/<Name>.cpp.

Exact: OpenSees solves the model's own equations and only the time step
differs; approximate: other equations, within a stated bound.  OF = paper
eq. 18 of the OpenSees force against the model's on tests/golden/law<SPEC>.csv
(dt 1 ms, step ratio max|dd|/half-range of d = 0.0113; the files'
parameters), material driven with the file's d and v
(``opensees_check.drive_material``):

======================  ==================================================  ======  ==========
law / effect            OpenSees materials                                  kind    OF
======================  ==================================================  ======  ==========
1 linear viscous        Viscous C 1                                         exact   3e-17
2 generalized viscous   Viscous C alpha                                     exact   7e-17
3 + linear spring       Parallel(Elastic K1, Viscous C alpha)               exact   9e-17
4 + quadratic spring    Parallel(Elastic K1, Viscous, 2 TensionOnly of      exact   1e-16
                        ElasticPowerFunc +-abs(K2) exp 2) [a]
5 Kelvin-Voigt          Parallel(ElasticPowerFunc K beta, Viscous)          exact   9e-17
6 Bouc-Wen              Parallel(BoucWen alpha K 1 beta beta 1 0 0 0,       approx  0.0029
                        Viscous C 1)
7 Lu visco-elastic      ViscousDamper K C alpha (beta = 1 only)             exact   3.4e-5 [b]
8 Lu friction           Parallel(ElasticPP K muN/K, Viscous C 1)            exact   2.9e-5 [c]
9 LuGre                 Parallel(BoucWen 0 beta 1 0 alpha 1 0 0 0,          approx  0.0035
                        Viscous C 1)
series_stiffness        laws 1, 2: ViscousDamper Ks C alpha                 exact   7.9e-5 (2)
                        law 7, beta 1: ViscousDamper K Ks/(K+Ks) C alpha    exact   9.1e-5 [b]
asymmetry               laws 1-5: Parallel(TensionOnly(M),                  exact   9e-17 (2)
                        TensionOnly(Multiplier M -1)) -factors a b [a]
friction                Damper(ElasticMultiLinear table of Ff tanh(v/v_f))  approx  9e-7 (2)
                                                                                    0.0034 (9)
parallel_stiffness      Elastic Kp, InitStressMaterial F0 on it;            exact   7e-17 (2)
                        Kp = 0: flat two-point ElasticMultiLinear F0                0.0034 (9)
======================  ==================================================  ======  ==========

[a] TensionOnly returns 1e-4 f for f < 0 (TENSION_ONLY_RESIDUAL): the
factors undo it exactly.  It is in OpenSeesPy's material table but not in
classic Tcl OpenSees (TclModelBuilderUniaxialMaterialCommand.cpp): the Tcl
script says so.  [b] the error is fvd_bridge's (TR-BDF2, one step per
sample): against the kernel at 32 substeps OpenSees is off by 3.5e-8 (law 7),
against law 7 with K Ks/(K+Ks) by 2.6e-8 (Ks 150; the composed 7 +
series_stiffness, whose spring sees the motion as a cubic Hermite of v and a
where the plain law sees v linear, stays 6.8e-5 from it at any substeps).
[c] ElasticPP sees the sampled displacement only and misses a velocity
reversal inside a step (the kernel splits the step there).  In a zeroLength
element under imposed displacement (``drive_element``, Newmark 0.5 0.25) the
integrator's velocity adds up to 1.8e-4 (Viscous; TRBDF2 2.1e-4) and 5.5e-5
(ViscousDamper, either integrator).

Bounds (``Export.bound(d, F)`` adds them up, s = ``step_ratio(d)``): exact,
EXACT_OF, times (s/STEP_REF)^2 above STEP_REF (laws 7, 8 measured as s^2);
BoucWen (laws 6, 9) integrates z by one implicit Euler step per strain
increment (BoucWenMaterial.cpp), first order: HYSTERESIS_OF_RATE s, measured
0.011 s to 0.33 s on the golden motion (10 parameter sets of laws 6 and 9,
C = 0 among them, x dt 1, 5, 20 ms x amplitude x0.2, 1, 3; worst at small
decay rates, where all of z lags);
friction: |F error| <= FRICTION_TABLE_ERROR Ff.

Not expressible (InputError; use the FMU export): law 7 with beta != 1 (a
power-law spring behind the dashpot); series_stiffness on laws 3-6, 8, 9
(SeriesMaterial passes no strain rate to its members); friction or asymmetry
inside the series spring; asymmetry of laws 6-9 (TensionOnly does not commit
a state under compression); gap (a dead zone in series with the law:
SeriesMaterial passes no strain rate to the law, and ViscousDamper's LGap,
which zeroes its force over a travel LGap after each force reversal and
restarts its Maxwell state, is another model); thermal
softening (no material softens with dissipated energy); inertia (a mass, not
a material); plugin effects.  Effects at their 'off' values are left out.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..effects.catalog import FRICTION_V_F, KS_RIGID_FROM
from ..errors import InputError
from ..model import Model, parse_model

#: OF (eq. 18) of an exact mapping at step ratios up to STEP_REF (the golden input's 0.0113)
EXACT_OF = 2e-4
STEP_REF = 0.012
#: BoucWen (laws 6, 9): OF <= HYSTERESIS_OF_RATE * step ratio (measured: up to 0.33)
HYSTERESIS_OF_RATE = 0.5
#: largest error of the tabulated friction Ff tanh(v / v_f), a fraction of Ff
FRICTION_TABLE_ERROR = 1e-4
#: TensionOnly's stress for f < 0 is this times f (TensionOnlyMaterial.cpp, getStress)
TENSION_ONLY_RESIDUAL = 1e-4
FMU_HINT = "use the FMU export (fvd-bridge export fmu) instead"


def step_ratio(d) -> float:
    """Largest displacement step over the half-range of d [-]: how coarsely
    the analysis steps resolve the motion (golden input: 0.0113)."""
    d = np.asarray(d, dtype=float)
    half = 0.5 * (d.max() - d.min())
    return float(np.max(np.abs(np.diff(d))) / half) if half > 0.0 else 0.0


@dataclass(frozen=True)
class Export:
    """OpenSees commands of one model: ``commands`` (ops function name, *args),
    the damper material's ``tag``, ``exact`` (OpenSees solves the model's own
    equations), ``note`` (the approximations made), ``hysteretic`` (BoucWen
    used) and the tabulated ``friction`` Ff [kN] (0 without)."""

    model: str
    commands: list
    tag: int
    exact: bool
    note: str
    hysteretic: bool = False
    friction: float = 0.0

    def bound(self, d, F) -> float:
        """OF (eq. 18) within which OpenSees reproduces the model force F [kN]
        on the displacement history d [mm] (module docstring: Bounds)."""
        s = step_ratio(d)
        of = EXACT_OF * max(1.0, (s / STEP_REF) ** 2)
        of += HYSTERESIS_OF_RATE * s if self.hysteretic else 0.0
        std = float(np.std(F))
        return of + (FRICTION_TABLE_ERROR * self.friction / std if std > 0.0 else 0.0)


class _Script:
    """Commands under construction; helper materials get tags tag+1, tag+2, ..."""

    def __init__(self, tag: int):
        self.tag, self.next, self.commands, self.notes = tag, tag + 1, [], []

    def mat(self, kind: str, *args) -> int:
        tag, self.next = self.next, self.next + 1
        self.commands.append(("uniaxialMaterial", kind, tag, *args))
        return tag

    def parallel(self, tags: list, factors: list | None = None) -> int:
        """``Parallel``: the sum of the members' stresses (times the factors)."""
        if len(tags) == 1 and factors is None:
            return tags[0]
        return self.mat("Parallel", *tags, *(("-factors", *factors) if factors else ()))

    def finish(self, top: int) -> list:
        """The commands, the damper material ``top`` renamed to the tag asked for
        (it is the last command: nothing refers to it)."""
        return [c[:2] + (self.tag,) + c[3:] if c[2] == top else c for c in self.commands]


def _refuse(spec: str, what: str):
    raise InputError(f"model {spec}: OpenSees has no material for {what}; {FMU_HINT}")


# ------------------------------------------------------------------ laws
def _viscous(s, C, alpha=1.0) -> int:
    """C sign(v)|v|^alpha [kN], v [mm/s]: ``Viscous`` (ViscousMaterial.cpp)."""
    return s.mat("Viscous", C, alpha)


def _even_square(s, K2) -> list:
    """K2 d^2 [kN], even in d (law 4): ``ElasticPowerFunc`` gives the odd
    +-|K2| sign(d) d^2 and ``TensionOnly`` T keeps f >= 0 and eps f below
    (eps = TENSION_ONLY_RESIDUAL), so T(+) + T(-) = (1 - eps)|K2| d^2; the
    caller's factors sign(K2)/(1 - eps) make it K2 d^2."""
    pos = s.mat("ElasticPowerFunc", "-coeff", abs(K2), "-exp", 2.0)
    neg = s.mat("ElasticPowerFunc", "-coeff", -abs(K2), "-exp", 2.0)
    return [s.mat("TensionOnly", pos), s.mat("TensionOnly", neg)]


def _bouc_wen(s, alpha, K, beta, gamma) -> int:
    """alpha K d + (1 - alpha) K z, dz/dd = 1 - |z|(gamma + beta sign(dd z)):
    ``BoucWen`` alpha ko=K n=1 gamma beta Ao=1 deltaA=deltaNu=deltaEta=0
    (BoucWenMaterial.cpp; z by one implicit Euler step per increment)."""
    s.notes.append("BoucWen integrates z by one implicit Euler step per strain increment")
    return s.mat("BoucWen", alpha, K, 1.0, gamma, beta, 1.0, 0.0, 0.0, 0.0)


def _law(s, spec: str, number: int, p: dict) -> int:
    """The law's material (parameters p by name; kN, mm, s); returns its tag."""
    if number in (1, 2):
        return _viscous(s, p["C"], p.get("alpha", 1.0))
    if number == 3:
        return s.parallel([s.mat("Elastic", p["K1"]), _viscous(s, p["C"], p["alpha"])])
    if number == 4:
        tags = [s.mat("Elastic", p["K1"]), _viscous(s, p["C"], p["alpha"])]
        if p["K2"] == 0.0:
            return s.parallel(tags)
        f = math.copysign(1.0 / (1.0 - TENSION_ONLY_RESIDUAL), p["K2"])
        return s.parallel(tags + _even_square(s, p["K2"]), [1.0, 1.0, f, f])
    if number == 5:  # ElasticPowerFunc: sum of c_i sign(d)|d|^e_i
        spring = s.mat("ElasticPowerFunc", "-coeff", p["K"], "-exp", p["beta"])
        return s.parallel([spring, _viscous(s, p["C"], p["alpha"])])
    if number == 6:  # law 6: A = n = 1, gamma = beta (fvd_bridge.laws.steps.law6_bouc_wen)
        return s.parallel([_bouc_wen(s, p["alpha"], p["K"], p["beta"], p["beta"]), _viscous(s, p["C"])])
    if number == 7:
        if p["beta"] != 1.0:
            _refuse(spec, f"law 7 with beta = {p['beta']:g} (a power-law spring behind the dashpot)")
        return s.mat("ViscousDamper", p["K"], p["C"], p["alpha"])
    if number == 8:  # z mu N with z in [-1, 1]: elastic-perfectly-plastic, E = K, yield mu N
        mu_N, tags = p["mu"] * p["N"], [_viscous(s, p["C"])]
        if mu_N > 0.0 and p["K"] > 0.0:
            tags.insert(0, s.mat("ElasticPP", p["K"], mu_N / p["K"]))
        return s.parallel(tags)
    if number == 9:  # dz/dd = 1 - alpha sign(dd) z: Bouc-Wen with alpha = 0, gamma = 0
        return s.parallel([_bouc_wen(s, 0.0, p["beta"], p["alpha"], 0.0), _viscous(s, p["C"])])
    _refuse(spec, f"law {number}")


def _maxwell(s, spec: str, number: int, p: dict, Ks: float) -> int:
    """The law behind a series spring Ks [kN/mm]: ``ViscousDamper`` K C alpha,
    dF/dt = K (v - sign(F)|F/C|^(1/alpha)) (ViscousDamper.cpp); law 7's own
    linear spring K adds in series: K Ks/(K + Ks)."""
    if number in (1, 2):
        return s.mat("ViscousDamper", Ks, p["C"], p.get("alpha", 1.0))
    if number == 7 and p["beta"] == 1.0:
        return s.mat("ViscousDamper", p["K"] * Ks / (p["K"] + Ks), p["C"], p["alpha"])
    _refuse(spec, f"law {number} behind series_stiffness" + (f" with beta = {p['beta']:g}" if number == 7 else ""))


# ------------------------------------------------------------------ effects
def _asymmetric(s, law: int, r: float) -> int:
    """F (1 + r) for F > 0, F (1 - r) for F < 0 (asymmetry) of the stateless
    material ``law``: a T(M) + b T(-M), T = ``TensionOnly`` (f, or eps f for
    f < 0), -M = ``Multiplier`` M -1, a = ((1 + r) - eps (1 - r))/(1 - eps^2),
    b = (eps (1 + r) - (1 - r))/(1 - eps^2), eps = TENSION_ONLY_RESIDUAL."""
    eps = TENSION_ONLY_RESIDUAL
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


def _friction(s, Ff: float) -> int:
    """Ff tanh(v / v_f) [kN]: ``Damper`` (its member sees the strain rate as
    strain, DamperMaterial.cpp) around an ``ElasticMultiLinear`` table."""
    s.notes.append(f"friction tanh tabulated to {FRICTION_TABLE_ERROR:g} Ff")
    v, F = friction_table(Ff)
    return s.mat("Damper", s.mat("ElasticMultiLinear", "-strain", *v, "-stress", *F))


def _parallel_spring(s, Kp: float, F0: float) -> int:
    """Kp d + F0 [kN]: ``Elastic`` Kp, shifted to F0 at d = 0 by
    ``InitStressMaterial``; a constant F0 (Kp = 0) is a flat two-point
    ``ElasticMultiLinear`` (extrapolated beyond its points)."""
    if F0 == 0.0:
        return s.mat("Elastic", Kp)
    if Kp == 0.0:
        return s.mat("ElasticMultiLinear", "-strain", -1.0, 1.0, "-stress", F0, F0)
    return s.mat("InitStressMaterial", s.mat("Elastic", Kp), F0)


# ------------------------------------------------------------------ model
#: why an active effect cannot be exported (always)
NEVER = {"gap": "the pin gap (a contact gap in series with the law: no force in the clearance)",
         "thermal_softening": "thermal_softening (force falling with dissipated energy)",
         "inertia": "inertia (a mass, not a material)"}


def _values(model, params: dict) -> dict:
    p = {}
    for name in model.names:
        if name not in params:
            raise InputError(f"model {model.spec}: parameter '{name}' is missing")
        p[name] = float(params[name])
        if not math.isfinite(p[name]):
            raise InputError(f"model {model.spec}: parameter '{name}' is not finite")
    return p


def _active(model, p: dict) -> set:
    """Names of the effects not at their 'off' values (a rigid series spring is off)."""
    on = set()
    for e in model.effects:
        if e.name == "series_stiffness":
            if p[e.names[0]] < KS_RIGID_FROM:
                on.add(e.name)
        elif any(p[n] != off for n, off in zip(e.names, e.none)):
            on.add(e.name)
        if e.name in on and (e.source != "built-in" or e.name in NEVER):
            _refuse(model.spec, NEVER.get(e.name, f"effect '{e.name}' ({e.source})"))
    return on


def opensees_export(model, params: dict, tag: int = 1) -> Export:
    """The model's OpenSees materials; the damper is material ``tag``.

    ``model``: a Model or its spec ('2+friction'); ``params``: {name: value}
    in the model's units (``Calibration.named()``).  Raises InputError for
    what OpenSees cannot express (module docstring)."""
    model = model if isinstance(model, Model) else parse_model(model)
    spec, number = model.spec, model.law.number
    p = _values(model, params)
    on = _active(model, p)
    law = {n: p[n] for n in model.law.names}
    s = _Script(int(tag))
    if "series_stiffness" in on:
        inside = sorted(on & {"asymmetry", "friction"})
        if inside:
            _refuse(spec, f"{inside[0]} inside the series spring")
        element = _maxwell(s, spec, number, law, p["series_stiffness.Ks"])
    else:
        element = _law(s, spec, number, law)
    if "asymmetry" in on:
        if number > 5:
            _refuse(spec, f"asymmetry of law {number} (TensionOnly loses its state in compression)")
        element = _asymmetric(s, element, p["asymmetry.r"])
    tags = [element]
    Ff = p["friction.Ff"] if "friction" in on else 0.0
    if Ff:
        tags.append(_friction(s, Ff))
    if "parallel_stiffness" in on:
        tags.append(_parallel_spring(s, p["parallel_stiffness.Kp"], p["parallel_stiffness.F0"]))
    commands = s.finish(s.parallel(tags))
    return Export(spec, commands, s.tag, not s.notes, "; ".join(s.notes) or "exact",
                  hysteretic=number in (6, 9), friction=abs(Ff))


# ------------------------------------------------------------------ output
def listed(commands) -> list:
    """The command tuples of an Export, or the given list of them."""
    return commands.commands if isinstance(commands, Export) else list(commands)


def apply(commands, ops) -> None:
    """Define the commands (or an Export's) in an OpenSees module: ops.<name>(*args)."""
    for name, *args in listed(commands):
        getattr(ops, name)(*args)


#: materials of OpenSeesPy's table that classic Tcl OpenSees lacks
NOT_IN_TCL = ("TensionOnly",)


def to_script(commands, lang: str = "py") -> str:
    """The commands (or an Export's, with its note) as an OpenSeesPy ('py')
    or Tcl ('tcl') script; numbers are written to full precision."""
    head = []
    if isinstance(commands, Export):
        head = [f"# fvd_bridge export of model {commands.model} (kN, mm, s): damper material {commands.tag}",
                f"# mapping: {commands.note}"]
    missing = sorted({c[1] for c in listed(commands) if c[1] in NOT_IN_TCL})
    if lang == "tcl" and missing:
        head.append(f"# needs {', '.join(missing)}: in OpenSeesPy and OpenSees built on its material table, "
                    f"not in classic Tcl OpenSees")
    if lang == "py":
        lines = head + ["import openseespy.opensees as ops", ""]
        lines += [f"ops.{name}({', '.join(map(repr, args))})" for name, *args in listed(commands)]
    elif lang == "tcl":
        lines = head + [" ".join([name] + [a if isinstance(a, str) else repr(a) for a in args])
                        for name, *args in listed(commands)]
    else:
        raise InputError(f"script language '{lang}': expected 'py' or 'tcl'")
    return "\n".join(lines) + "\n"
