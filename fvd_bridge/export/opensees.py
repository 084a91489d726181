"""OpenSees export: a calibrated damper model as a list of command tuples.

``opensees_export(model, params, tag)`` maps the model on native OpenSees
uniaxial materials, each command a tuple (ops function name, *args); the
damper is material ``tag``, helpers tag+1, tag+2, ...  ``to_script`` and
``apply`` are thin layers over that one list.  Which materials express a law
or an effect is declared with it (its ``OpenSeesForm``:
``laws/opensees_forms.py``, ``effects/opensees_forms.py``); this module
assembles them (the law, or its series form behind a series spring; the
output effects around it; the parallel terms beside it) and refuses what
the model's declarations refuse (``Model.opensees_refusal``).

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
oil_column              as series_stiffness, seal and accumulator beside    exact   7.9e-5 (2)
gap                     laws 1, 2, 7 (beta 1): ViscousDamper Ks C alpha     approx  0.0156 (2)
                        LGap g; without a series spring Ks a stiff contact
asymmetry               laws 1-5: Parallel(TensionOnly(M),                  exact   9e-17 (2)
                        TensionOnly(Multiplier M -1)) -factors a b [a]
friction                Damper(ElasticMultiLinear table of Ff tanh(v/v_f))  approx  9e-7 (2)
                                                                                    0.0034 (9)
parallel_stiffness      Elastic Kp, InitStressMaterial F0 on it;            exact   7e-17 (2)
                        Kp = 0: flat two-point ElasticMultiLinear F0                0.0034 (9)
======================  ==================================================  ======  ==========

[a] TensionOnly returns 1e-4 f for f < 0 (laws/opensees_forms.py,
TENSION_ONLY_RESIDUAL): the
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
friction: |F error| <= FRICTION_TABLE_ERROR Ff (effects/opensees_forms.py);
a pin gap (ViscousDamper's LGap): GAP_OF_RATE g/A + GAP_STEP_RATE s, A the
half-range of d: the model's pin starts centred in its clearance where
LGap starts in contact, LGap's force is held at zero from the reversal
interpolated in a step but contact is found at a step's end (up to one
step late), and a gap without a series spring gets a contact spring
(CONTACT_DEFLECTION); measured OF/(g/A) up to 0.11 on sines (laws 1, 2, 7,
g/A 0.025 to 0.4, springs 150 kN/mm to rigid, s up to 0.025) and 0.0156 on
the golden motion (g/A 0.04, s 0.0113).

Behind laws 3-6, 8, 9 a connection (series_stiffness, gap: SeriesMaterial
passes no strain rate to its members) is a second material through an
internal node (``Export.connection``): the dead zone Ks dz(w, g/2) as an
ElasticMultiLinear (Elastic Ks without a gap), the law with the effects
inside the connection as material ``tag``; ``--check`` drives the two in
zeroLength elements (``opensees_check.drive_element``, TRBDF2).

Not expressible (InputError; use the FMU export): law 7 with beta != 1 (a
power-law spring behind the dashpot); laws 3-5 behind a connection with
alpha < NEWTON_ALPHA (their Viscous dashpot defeats Newton at the internal
node); friction, the accumulator or asymmetry inside the ViscousDamper of
laws 1, 2, 7 (series_stiffness or gap; oil_column holds the seal and
accumulator beside it); behind laws 3-9, an effect beside the connection;
asymmetry of laws 6-9 (TensionOnly does not commit a state under
compression); thermal
softening (no material softens with dissipated energy); inertia (a mass, not
a material); plugin effects.  Effects at their 'off' values are left out.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..catalog import parse_model
from ..effects.compose import ordered
from ..errors import InputError, command
from ..model import Model
from ..laws.opensees_forms import NEWTON_ALPHA
from ..opensees_commands import NOT_IN_TCL, Tag, apply, define, listed  # noqa: F401 (re-exported)
from ..opensees_commands import to_script as commands_script
from ..units import SYSTEM, factor, in_system, unit_system

#: OF (eq. 18) of an exact mapping at step ratios up to STEP_REF (the golden input's 0.0113)
EXACT_OF = 2e-4
STEP_REF = 0.012
#: BoucWen (laws 6, 9): OF <= HYSTERESIS_OF_RATE * step ratio (measured: up to 0.33)
HYSTERESIS_OF_RATE = 0.5
#: a pin gap as ViscousDamper's LGap: OF <= GAP_OF_RATE g / half-range of d + GAP_STEP_RATE step ratio
#: (module docstring: Bounds)
GAP_OF_RATE, GAP_STEP_RATE = 0.15, 1.0
#: a pin gap's rigid contact deflects this share of the tested stroke under the tested force
CONTACT_DEFLECTION = 0.001
#: the solving spring deflects this share of the tested stroke under the
#: dashpot's force at the tested velocity
SOLVING_DEFLECTION = 0.005


def stiff_spring(force: float, stroke: float, share: float) -> float:
    """Ks [force/length] of a spring that deflects ``share`` of ``stroke``
    under ``force``: Ks = force / (share stroke).  The solving spring behind
    a Newton-defeating dashpot (force C v^alpha at the tested velocity,
    SOLVING_DEFLECTION), a rigid pin's contact (the tested force,
    CONTACT_DEFLECTION) and a CSI link's stiff spring use this one rule."""
    return force / (share * stroke)


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
    used), ``tabulated`` the largest error of tabulated curves [kN] (0
    without), ``global_step`` (a material integrates over the analysis'
    global time step), ``clearance`` a pin gap's [mm] (0 without) and
    ``connection`` the offset from ``tag`` of the connection's material
    when the damper is two materials in series (0: one material): element
    node_i -> internal node (tag + connection), internal node -> node_j
    (tag)."""

    model: str
    commands: list
    tag: int
    exact: bool
    note: str
    hysteretic: bool = False
    tabulated: float = 0.0
    global_step: bool = False
    units: dict = field(default_factory=lambda: dict(SYSTEM))
    clearance: float = 0.0
    connection: int = 0

    def to_kN(self, F) -> np.ndarray:
        """The material's force in its units -> kN."""
        return np.asarray(F, dtype=float) * factor("F", self.units["F"])

    def bound(self, d, F) -> float:
        """OF (eq. 18) within which OpenSees reproduces the model force F [kN]
        on the displacement history d [mm] (module docstring: Bounds)."""
        s = step_ratio(d)
        of = EXACT_OF * max(1.0, (s / STEP_REF) ** 2)
        of += HYSTERESIS_OF_RATE * s if self.hysteretic else 0.0
        half = 0.5 * float(np.ptp(d))
        of += GAP_OF_RATE * self.clearance / half + GAP_STEP_RATE * s if self.clearance and half > 0.0 else 0.0
        std = float(np.std(F))
        return of + (float(self.to_kN(self.tabulated)) / std if std > 0.0 else 0.0)


class _Script:
    """Commands under construction; helper materials get tags tag+1, tag+2, ...;
    ``velocity``: 1 mm/s in the export's units (forms that tabulate in velocity)."""

    def __init__(self, tag: int, velocity: float = 1.0):
        self.tag, self.next, self.commands, self.notes = tag, tag + 1, [], []
        self.tabulated, self.global_step, self.velocity = 0.0, False, velocity

    def mat(self, kind: str, *args, global_step: bool = False) -> int:
        """A material of this kind with the next tag (a Tag, relative to the
        damper's); ``global_step``: it integrates over the analysis' global
        time step."""
        tag, self.next = Tag(self.next, self.next - self.tag), self.next + 1
        self.commands.append(("uniaxialMaterial", kind, tag, *args))
        self.global_step |= global_step
        return tag

    def parallel(self, tags: list, factors: list | None = None) -> int:
        """``Parallel``: the sum of the members' stresses (times the factors)."""
        if len(tags) == 1 and factors is None:
            return tags[0]
        return self.mat("Parallel", *tags, *(("-factors", *factors) if factors else ()))

    def finish(self, top: int) -> list:
        """The commands, the damper material ``top`` renamed to the tag asked for
        (it is the last command: nothing refers to it)."""
        own = Tag(self.tag, 0)
        return [c[:2] + (own,) + c[3:] if c[2] == top else c for c in self.commands]


def _values(model, params: dict) -> dict:
    p = {}
    for name in model.names:
        if name not in params:
            raise InputError(f"model {model.spec}: parameter '{name}' is missing")
        p[name] = float(params[name])
        if not np.isfinite(p[name]):
            raise InputError(f"model {model.spec}: parameter '{name}' is not finite")
    return p


def opensees_export(model, params: dict, tag: int = 1, units=None, tested: dict | None = None) -> Export:
    """The model's OpenSees materials; the damper is material ``tag``.

    ``model``: a Model or its spec ('2+friction'); ``params``: {name: value}
    in the model's units (``Calibration.named()``); ``units``: the OpenSees
    model's FORCE,LENGTH,TIME ('kN,m,s', or a dict {F, d, t}; default kN,
    mm, s): every value is written in them (``units.in_system``, from each
    parameter's declared unit); ``tested``: the tested range {d [mm], F
    [kN]} (``Calibration.tested``), which a pin gap without a series spring
    needs (``contact_stiffness``).  Raises InputError for what OpenSees
    cannot express (module docstring)."""
    model = model if isinstance(model, Model) else parse_model(model)
    system = unit_system(units)
    p = _values(model, params)
    refusal = model.opensees_refusal(p)
    if refusal:
        raise InputError(f"model {model.spec}: OpenSees has no material for {refusal}; "
                         f"use the FMU export ({command('export fmu')}) instead")
    active = ordered(model.active_effects(p))
    exponents = {n: p[n] for n in model.law.names}
    p = {n: in_system(p[n], q.unit, system, exponents) for n, q in zip(model.names, model.parameters)}
    form = model.law.opensees
    law = {n: p[n] for n in model.law.names}

    def own(e):  # the effect's parameters without its prefix
        return {q.name: p[n] for q, n in zip(e.parameters, e.names)}

    s = _Script(int(tag), in_system(1.0, "mm/s", system))
    series = {e.name: own(e) for e in active if e.stage == "series"}
    clearance = series.get("gap", {}).get("g", 0.0)
    Ks = _connection_spring(s, model.spec, series, tested, system) if series else None
    two = bool(series) and form.series is None  # the connection and the law as two materials in series
    if series and not two:  # one material: ViscousDamper (its LGap for the clearance)
        if clearance > 0.0:
            s.notes.append(f"pin gap {clearance:.4g} {system['d']} as ViscousDamper's LGap (force zero over that "
                           f"travel after each force reversal, the Maxwell state then restarted)")
        element = form.series(s, law, Ks, clearance)
    else:
        element = form.build(s, law)
    for e in (e for e in active if e.stage == "output"):
        element = e.opensees.build(s, element, own(e))
    tags = [element] + [e.opensees.build(s, own(e)) for e in active if e.stage == "parallel"]
    top = s.parallel(tags)
    connection = _dead_zone(s, Ks, 0.5 * clearance).offset if two else 0  # after the law: the law is `tag`
    if two:
        s.notes.append("two materials in series through an internal node: the connection (material tag + "
                       f"{connection}: {'the pin gap ' if clearance else ''}dead zone and spring) and the law "
                       "(material tag)")
    commands = s.finish(top)
    return Export(model.spec, commands, s.tag, not s.notes, "; ".join(s.notes) or "exact",
                  hysteretic=form.accuracy == "hysteretic", tabulated=s.tabulated, global_step=s.global_step,
                  units=system, clearance=clearance / in_system(1.0, "mm", system), connection=connection)


def _connection_spring(s, spec: str, series: dict, tested: dict | None, system: dict) -> float:
    """The connection's spring in the export's units: the series spring's Ks
    (series_stiffness or oil_column), else the pin's contact
    (``contact_stiffness``, said in the notes)."""
    spring = [q["Ks"] for q in series.values() if "Ks" in q]
    if spring:
        return spring[0]
    Ks = in_system(contact_stiffness(spec, tested), "kN/mm", system)
    s.notes.append(f"the pin's contact as a spring Ks {Ks:.6g} {system['F']}/{system['d']} "
                   f"({100 * CONTACT_DEFLECTION:g}% of the tested stroke under the tested force)")
    return Ks


def _dead_zone(s, Ks: float, half: float) -> Tag:
    """Ks dz(w, h) (effects/connection.py ``dead_zone``): ``Elastic`` Ks for
    h = 0, else an ``ElasticMultiLinear`` through (-h, 0), (h, 0) and one
    more point each side at slope Ks (extrapolated beyond its last points)."""
    if half <= 0.0:
        return s.mat("Elastic", Ks)
    reach = half + max(half, 1.0)
    return s.mat("ElasticMultiLinear", "-strain", -reach, -half, half, reach,
                 "-stress", -Ks * (reach - half), 0.0, 0.0, Ks * (reach - half))


def contact_stiffness(spec: str, tested: dict | None) -> float:
    """Ks [kN/mm] of a pin's rigid contact, as the ViscousDamper spring a
    gap without a series spring needs: it deflects CONTACT_DEFLECTION of the
    tested stroke d [mm] under the tested force F [kN] (``tested``:
    ``Calibration.tested``)."""
    if not tested or not tested.get("d") or not tested.get("F"):
        raise InputError(f"model {spec}: a pin gap without a series spring needs the tested stroke and force "
                         f"for its contact spring (opensees_export(..., tested={{'d': mm, 'F': kN}}), as "
                         f"Calibration.to_opensees passes them)")
    return stiff_spring(float(tested["F"]), float(tested["d"]), CONTACT_DEFLECTION)


def _newton_defeating(c) -> bool:
    """A ``Viscous C alpha`` command with alpha < NEWTON_ALPHA."""
    return c[0] == "uniaxialMaterial" and c[1] == "Viscous" and len(c) > 4 and float(c[4]) < NEWTON_ALPHA


def solving_springs(export: Export, stroke: float | None, velocity: float | None) -> Export:
    """The export with each ``Viscous C alpha`` of alpha < NEWTON_ALPHA behind a
    stiff series spring: ``ViscousDamper Ks C alpha`` under the same tag, Ks =
    C v^alpha / (SOLVING_DEFLECTION d) for the tested stroke d [mm] and
    velocity v [mm/s] (converted to the export's units): the spring deflects
    0.5% of the stroke.  ViscousDamper integrates the force inside the
    material and reports no tangent, so Newton never meets the dashpot's
    unbounded tangent at a velocity reversal (start with KrylovNewton:
    ``frames.transient.algorithms_for``).  The export itself without such a
    dashpot or a tested range."""
    if not stroke or not velocity or not any(_newton_defeating(c) for c in export.commands):
        return export
    d, v = in_system(stroke, "mm", export.units), in_system(velocity, "mm/s", export.units)
    commands, springs = [], []
    for c in export.commands:
        if _newton_defeating(c):
            C, alpha = float(c[3]), float(c[4])
            Ks = stiff_spring(C * v ** alpha, d, SOLVING_DEFLECTION)
            c = ("uniaxialMaterial", "ViscousDamper", c[2], Ks, C, alpha)
            springs.append(f"Viscous {C:.6g} {alpha:.4g} behind Ks {Ks:.6g} {export.units['F']}/{export.units['d']}")
        commands.append(c)
    note = (f"{'; '.join(springs)} (solving springs: {100 * SOLVING_DEFLECTION:g}% of the tested stroke "
            f"{stroke:.4g} mm at {velocity:.4g} mm/s)")
    return replace(export, commands=commands, exact=False, global_step=True,
                   note=note if export.note == "exact" else f"{export.note}; {note}")


def solving_advice(export: Export, solved: Export) -> list[str]:
    """Header lines of a script whose export ``solving_springs`` changed: the
    ViscousDamper that fvd-bridge frame runs in place of each such Viscous."""
    units = f"{export.units['F']}/{export.units['d']}"
    return [f"frame analyses: fvd-bridge frame runs material {'tag' if not mine[2].offset else f'tag + {mine[2].offset}'}"
            f" as ViscousDamper {theirs[3]:.6g} {theirs[4]:.6g} {theirs[5]:.6g} (a solving spring Ks [{units}] that "
            f"deflects {100 * SOLVING_DEFLECTION:g}% of the tested stroke), starting each step with KrylovNewton"
            for mine, theirs in zip(export.commands, solved.commands) if mine != theirs]


# ------------------------------------------------------------------ output
# listed, apply and NOT_IN_TCL come from fvd_bridge.opensees_commands (the
# frames build their models from command lists too) and stay importable here.
#: the damper's definition function in an exported script
DEFINE = "define_damper"


class OpenSeesCommands(list):
    """A damper's OpenSees commands, (ops function name, *args) each, as a
    list; ``apply(ops)`` defines them in an OpenSees module, ``to_script``
    writes the script ``fvd-bridge export opensees`` writes.  ``export``:
    the Export; ``comments``: the script header's lines of the calibration."""

    def __init__(self, export: Export, comments=()):
        super().__init__(export.commands)
        self.export, self.comments = export, tuple(comments)

    @property
    def tag(self) -> int:
        """The damper's uniaxial material tag."""
        return self.export.tag

    def apply(self, ops) -> int:
        """Define the damper in an OpenSees model.

        Parameters
        ----------
        ops : module
            ``openseespy.opensees`` (a model already begun with ``ops.model``).

        Returns
        -------
        int
            The damper's material tag.
        """
        apply(self.export.commands, ops)
        return self.export.tag

    def to_script(self, lang: str = "py") -> str:
        """The script that defines the damper, as ``fvd-bridge export opensees`` writes it.

        Parameters
        ----------
        lang : {'py', 'tcl'}
            OpenSeesPy (``define_damper(ops, tag)``) or Tcl (``proc define_damper {tag}``).

        Returns
        -------
        str
        """
        return to_script(self.export, lang, self.comments)


def to_script(commands, lang: str = "py", comments=()) -> str:
    """An Export as an OpenSeesPy ('py') or Tcl ('tcl') script defining
    ``define_damper(ops, tag)`` (``opensees_commands.define``: importable,
    callable again after ops.wipe() and once per damper, run as it is it
    defines material ``tag``), its header the model, the units, the mapping,
    the ``comments`` given (record, tested range) and how to solve a model
    with a power-law dashpot; plain command lists as top-level commands.
    Numbers are written to full precision."""
    if not isinstance(commands, Export):
        return commands_script(commands, lang, comments)
    ex = commands
    units = f"{ex.units['F']}, {ex.units['d']}, {ex.units['t']}"
    head = [f"# fvd_bridge export of model {ex.model}: {DEFINE}(ops, tag) defines the damper as uniaxial "
            f"material tag (default {ex.tag})",
            f"# units: force {ex.units['F']}, length {ex.units['d']}, time {ex.units['t']} (the OpenSees model's "
            f"must be these: {units})",
            f"# mapping: {ex.note}", *[f"# {line}" for line in comments]]
    if ex.connection:
        head += [f"# TWO MATERIALS IN SERIES: more than one material; place them in two elements through an internal "
                 f"node m without mass: node_i -> m material tag + {ex.connection} (the connection), m -> node_j "
                 f"material tag (the law), e.g. in 1-D:",
                 f"#   ops.node(m, 0.0); ops.element('zeroLength', e1, node_i, m, '-mat', tag + {ex.connection}, "
                 f"'-dir', 1); ops.element('zeroLength', e2, m, node_j, '-mat', tag, '-dir', 1)",
                 "# solving: TRBDF2 follows the contact better than average acceleration (Newmark 0.5 0.25 rings "
                 "when the gap closes); fvd-bridge export --check runs it so"]
    if any(_newton_defeating(c) for c in ex.commands):
        head.append("# solving: a power-law dashpot with alpha < 0.5 has an unbounded tangent at velocity "
                    "reversals, where Newton diverges; put it behind a stiff spring (ViscousDamper Ks C alpha) or "
                    "test the force residual (NormUnbalance) and retry a failed step with KrylovNewton, "
                    "NewtonLineSearch, then halved steps")
    return define(ex.commands, lang, DEFINE, ex.tag, head,
                  f"Define the {ex.model} damper ({units})")
