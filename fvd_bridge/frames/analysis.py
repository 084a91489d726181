"""A frame in OpenSees with one damper per story: build it, shake it with a
ground motion, collect the response (kN, mm, s; mass kN s^2/mm).

Model (openseespy, 2D, 3 DOF per node), from a ``buildings.Building``:

- tags: the frame's own materials and sections use tags 1..999 (the series
  brace material is 999); material tags >= 1000 are left to the dampers, whose
  commands the caller supplies with its own ``damper_tag``.  Nothing is shifted.
- one node per joint (tag 100 level + line + 1), extra nodes at column splices;
  base fixed or pinned; levels 1..ground_level held horizontally; the nodes of
  each above-grade level follow the left node horizontally (``equalDOF``), which
  carries the level's mass.
- members: ``forceBeamColumn`` with ``HingeRadau`` plastic-hinge zones (or
  ``elasticBeamColumn`` when ``building.yielding`` is False), linear geometry.
- dampers: a ``twoNodeLink`` along the diagonal of ``building.damper_bay`` in
  each above-grade story, direction 1 (axial) only, with the damper material;
  the link passes its axial deformation and deformation rate [mm, mm/s] to the
  material.  With ``building.brace_stiffness`` the damper sits in series with
  an elastic brace link (axial and, to hold the massless middle node, transverse
  stiffness K_b) from the lower joint to the diagonal's midpoint.

Inherent damping, Rayleigh on the bare frame (Chopra, Dynamics of Structures,
sec. 11.4): C = a0 M + a1 K_0 with

    a0 = 2 zeta w_i w_j / (w_i + w_j),   a1 = 2 zeta / (w_i + w_j)

(w_i, w_j the circular frequencies of ``building.damping_modes``; K_0 the
initial stiffness, so yielding does not change it).  It is set with the
``rayleigh`` command after the frame members and before the damper and brace
links exist: OpenSees stores the factors on the nodes and elements present at
that moment (Domain::setRayleighDampingFactors), and a twoNodeLink adds Rayleigh
damping only when built with ``-doRayleigh`` -- so a link contributes nothing but
its own material force.

Ground motion: ``UniformExcitation`` in the horizontal direction with a
``Path`` series of the record's acceleration [mm/s^2] (zero after its end),
then ``free_vibration`` seconds at rest.  Transient analysis: Newmark average
acceleration (gamma = 1/2, beta = 1/4), steps of ``dt_analysis``.

Solver.  A viscous material F = C sign(v)|v|^alpha with alpha < 1 has the
damping tangent alpha C |v|^(alpha - 1), unbounded as v -> 0 (OpenSees caps it
at |v| = 1e-11 mm/s); near a velocity reversal Newton overshoots across the
cusp, and with alpha < 0.5 a damper behaves almost like friction (F = C at
1 mm/s) and can stick while the frame deforms.  Each step therefore tries the
``ALGORITHMS`` in turn, with a test on the force residual (a test on the
displacement increment passes while the huge tangent hides a wrong force);
when none converges the step is halved, recursively, down to
dt/2^MAX_HALVINGS; there ``LAST_RESORT`` accepts a sub-step whose displacement
increment converged although its force residual did not.  If that fails too
the run stops.  ``FrameResult.solver`` (SolverReport) counts the (sub)steps of
each algorithm, the split steps and the relaxed ones, and its ``message`` names
every shortcut and failure (also a negative damper energy, which a passive
damper cannot have).  Linear and alpha >= 0.5 dampers converge at the first
try in almost every step; for alpha < 0.5 peak drifts move by a few % with dt_analysis (stick-slip
near the reversals): compare with a halved step.  Strong alpha = 0.3 ``Viscous``
dampers in all nine stories of the 9-story frame defeat this ladder within a
second of the record (the run stops, reported).  A Maxwell model, OpenSees'
``ViscousDamper`` (series stiffness K, the force integrated inside the
material), converges at the first try there, e.g. K = 1000 kN/mm.

openseespy keeps one global model: ``run_frame`` wipes it, and two runs cannot
share a process at the same time.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import openseespy.opensees as ops

from ..errors import InputError
from .buildings import Building, Section
from .motions import G_MM_S2

#: first material tag left to the dampers; the frame uses tags below it
DAMPER_TAGS_FROM = 1000
#: material tag of the series brace (frame side)
BRACE_MATERIAL = 999
#: time integrator (OpenSees ``integrator`` arguments): Newmark average acceleration
INTEGRATOR = ("Newmark", 0.5, 0.25)
#: (algorithm, convergence test) tried in turn at each step, as arguments of the
#: OpenSees ``algorithm`` and ``test`` commands; the test is on the force
#: residual norm [kN at translations, kN mm at rotations]
ALGORITHMS = (
    # plain Newton with room to converge first: at the velocity reversals of a
    # power-law dashpot (alpha < 1) the fallbacks below change the response
    # (the FMU co-simulation of examples/opensees_fmu_cosim.py agrees with
    # this to OF 2e-6, with KrylovNewton first only to 0.04)
    (("Newton",), ("NormUnbalance", 1e-2, 50)),
    (("KrylovNewton",), ("NormUnbalance", 1e-2, 15)),
    (("NewtonLineSearch", "-type", "Bisection"), ("NormUnbalance", 1e-2, 15)),
    (("ModifiedNewton", "-initial"), ("NormUnbalance", 1e-2, 20)),
)
#: a step none of the algorithms completes is halved, at most this many times
MAX_HALVINGS = 3
#: at the smallest sub-step, when all ALGORITHMS fail: a test on the displacement
#: increment [mm] only, which a stuck damper (its force set by round-off-level
#: velocities) can pass; such sub-steps are counted in SolverReport.relaxed_steps
LAST_RESORT = (("KrylovNewton",), ("NormDispIncr", 1e-5, 30))

_GEOM = 1                       # geometric transformation tag
_DAMPER_ELE, _BRACE_ELE, _MID_NODE = 8000, 8100, 5000


@dataclass(frozen=True)
class FrameModel:
    """Tags and modal data of the model ``build_frame`` left in OpenSees.

    floor_nodes   node carrying the mass of each above-grade level (bottom up)
    damper_links  twoNodeLink tag of each story's damper (empty: bare frame)
    periods       [s] eigen periods of the bare frame, mode 1 first
    rayleigh      (a0 [1/s], a1 [s]) of C = a0 M + a1 K_0
    """

    floor_nodes: tuple[int, ...]
    damper_links: tuple[int, ...]
    periods: np.ndarray
    rayleigh: tuple[float, float]


@dataclass(frozen=True)
class SolverReport:
    """How the transient analysis went.

    algorithm_steps  (sub)steps completed by each algorithm, by its arguments
    split_steps      steps that needed sub-steps; smallest_step [s] the finest used
    relaxed_steps    sub-steps accepted by LAST_RESORT (displacement test only)
    completed        False when a step failed even with LAST_RESORT at the finest
                     sub-step, or the response diverged: the histories stop at
                     failed_at [s]
    message          what went wrong, empty when nothing did
    """

    algorithm_steps: dict
    split_steps: int
    smallest_step: float
    relaxed_steps: int
    completed: bool
    failed_at: float | None = None
    message: str = ""

    @property
    def converged(self) -> bool:
        """Every (sub)step met its ALGORITHMS tolerance and the run completed."""
        return self.completed and not self.relaxed_steps

    @property
    def algorithms_used(self) -> list[str]:
        """Names of the algorithms that completed at least one (sub)step."""
        return [name for name, n in self.algorithm_steps.items() if n]


@dataclass(frozen=True)
class FrameResult:
    """Response of a frame to a ground motion (kN, mm, s).

    Histories sampled at ``t`` [s] (n_t samples), per above-grade level or story
    (bottom up): floor_displacement [mm] relative to the ground,
    drift_ratio [-], floor_acceleration [mm/s^2] absolute, ground_acceleration
    [mm/s^2]; damper_deformation [mm] and damper_force [kN] (tension and
    elongation positive), None without dampers or with record_dampers=False.
    The record ends at ``record_end`` [s]; free vibration follows.  periods
    [s] and rayleigh (a0, a1) of the bare frame; ``damper`` the material
    commands used; ``solver`` how the analysis went.
    """

    building: str
    motion: str
    t: np.ndarray
    floor_displacement: np.ndarray
    drift_ratio: np.ndarray
    floor_acceleration: np.ndarray
    ground_acceleration: np.ndarray
    damper_deformation: np.ndarray | None
    damper_force: np.ndarray | None
    periods: np.ndarray
    rayleigh: tuple[float, float]
    record_end: float
    solver: SolverReport
    damper: list = field(default_factory=list)

    @property
    def floor_acceleration_g(self) -> np.ndarray:
        """Absolute floor accelerations [g]."""
        return self.floor_acceleration / G_MM_S2

    @property
    def peak_drift_ratio(self) -> np.ndarray:
        """Peak |interstory drift ratio| of each story [-]."""
        return np.max(np.abs(self.drift_ratio), axis=0)

    @property
    def max_drift_ratio(self) -> float:
        """Largest peak interstory drift ratio over the stories [-]."""
        return float(np.max(self.peak_drift_ratio))

    @property
    def residual_drift_ratio(self) -> np.ndarray:
        """Residual drift ratio of each story [-]: the mean drift ratio over the
        last first-mode period T1 of the free vibration (removes the remaining
        oscillation); NaN when the analysis stopped early."""
        if not self.solver.completed:
            return np.full(self.drift_ratio.shape[1], np.nan)
        last = self.t >= self.t[-1] - self.periods[0]
        return np.mean(self.drift_ratio[last], axis=0)

    @property
    def peak_floor_acceleration_g(self) -> np.ndarray:
        """Peak |absolute floor acceleration| of each level [g]."""
        return np.max(np.abs(self.floor_acceleration_g), axis=0)

    @property
    def peak_damper_force(self) -> np.ndarray | None:
        """Peak |damper force| of each story [kN]."""
        return None if self.damper_force is None else np.max(np.abs(self.damper_force), axis=0)

    @property
    def peak_damper_stroke(self) -> np.ndarray | None:
        """Peak |damper deformation| of each story [mm]."""
        return None if self.damper_deformation is None else np.max(np.abs(self.damper_deformation), axis=0)

    @property
    def damper_energy(self) -> np.ndarray | None:
        """Energy each story's damper dissipated [kN mm = J] (``loop_energy``)."""
        return None if self.damper_force is None else loop_energy(self.damper_force, self.damper_deformation)

    @property
    def total_damper_energy(self) -> float | None:
        """Energy all dampers dissipated [kN mm = J]."""
        e = self.damper_energy
        return None if e is None else float(np.sum(e))

    def summary(self) -> dict:
        """The peak and residual quantities as plain numbers and lists (None
        where a quantity does not apply or is not finite)."""
        def listed(a):
            return None if a is None else [float(x) if np.isfinite(x) else None for x in a]
        return {
            "building": self.building, "motion": self.motion,
            "periods_s": listed(self.periods),
            "peak_drift_ratio": listed(self.peak_drift_ratio), "max_drift_ratio": self.max_drift_ratio,
            "residual_drift_ratio": listed(self.residual_drift_ratio),
            "peak_floor_acceleration_g": listed(self.peak_floor_acceleration_g),
            "peak_damper_force_kN": listed(self.peak_damper_force),
            "peak_damper_stroke_mm": listed(self.peak_damper_stroke),
            "damper_energy_kNmm": listed(self.damper_energy), "total_damper_energy_kNmm": self.total_damper_energy,
            "solver": {"algorithm_steps": dict(self.solver.algorithm_steps), "split_steps": self.solver.split_steps,
                       "smallest_step_s": self.solver.smallest_step, "relaxed_steps": self.solver.relaxed_steps,
                       "completed": self.solver.completed,
                       "failed_at_s": self.solver.failed_at, "message": self.solver.message},
        }


def loop_energy(force: np.ndarray, deformation: np.ndarray) -> np.ndarray:
    """Energy [kN mm = J] of each column of force [kN] over deformation [mm]
    (samples down axis 0): E = integral F dDelta, by the trapezoidal rule
    sum (F_k + F_k+1)/2 (Delta_k+1 - Delta_k)."""
    F, d = np.asarray(force, dtype=float), np.asarray(deformation, dtype=float)
    return np.sum(0.5 * (F[1:] + F[:-1]) * np.diff(d, axis=0), axis=0)


# --------------------------------------------------------------------- model


def _node(level: int, line: int) -> int:
    """Tag of the joint of ``level`` on column ``line``."""
    return 100 * level + line + 1


def _splice_node(story: int, line: int) -> int:
    """Tag of the splice node in ``story`` on column ``line``."""
    return 100 * story + 51 + line


def _nodes(b: Building) -> None:
    """Joints, splice nodes, supports and rigid-floor constraints."""
    z, x = b.elevations, b.column_lines
    for level in range(b.levels + 1):
        for line, xj in enumerate(x):
            ops.node(_node(level, line), xj, z[level])
    for story in b.splice_stories:
        for line, xj in enumerate(x):
            ops.node(_splice_node(story, line), xj, z[story] + b.splice_height)
    for line in range(len(x)):
        ops.fix(_node(0, line), 1, 1, 1 if b.base == "fixed" else 0)
        for level in range(1, b.ground_level + 1):
            ops.fix(_node(level, line), 1, 0, 0)
    for level in range(b.ground_level + 1, b.levels + 1):
        for line in range(1, len(x)):
            ops.equalDOF(_node(level, 0), _node(level, line), 1)
        ops.mass(_node(level, 0), b.floor_masses[level - 1], 0.0, 0.0)


class _Members:
    """Creates beam-column elements; defines each section's OpenSees section,
    materials and hinge integration once (tags 1..999)."""

    def __init__(self, b: Building):
        self.b, self.defined, self.next_tag = b, {}, 1

    def _tag(self) -> int:
        """The next free frame tag (materials, sections, integrations: 1..998)."""
        tag, self.next_tag = self.next_tag, self.next_tag + 1
        if tag >= BRACE_MATERIAL:
            raise InputError(f"building {self.b.name}: too many section types for frame tags 1..998")
        return tag

    def _integration(self, s: Section, fy: float) -> int:
        """HingeRadau integration tag: hinge zones of length ratio x depth with a
        bilinear moment-curvature (M_y = F_y Z, E I, post-yield ratio), elastic between."""
        key = (s.name, fy)
        if key not in self.defined:
            b = self.b
            axial, moment, hinge, elastic, integ = (self._tag() for _ in range(5))
            ops.uniaxialMaterial("Elastic", axial, b.E * s.area)
            ops.uniaxialMaterial("Steel01", moment, fy * s.plastic_modulus, b.E * s.inertia, b.hardening)
            ops.section("Aggregator", hinge, axial, "P", moment, "Mz")
            ops.section("Elastic", elastic, b.E, s.area, s.inertia)
            lp = b.hinge_length_ratio * s.depth
            ops.beamIntegration("HingeRadau", integ, hinge, lp, hinge, lp, elastic)
            self.defined[key] = integ
        return self.defined[key]

    def add(self, tag: int, i: int, j: int, s: Section, fy: float) -> None:
        """Element ``tag`` from node i to node j with section s, yield strength fy [kN/mm^2]."""
        if self.b.yielding:
            ops.element("forceBeamColumn", tag, i, j, _GEOM, self._integration(s, fy))
        else:
            ops.element("elasticBeamColumn", tag, i, j, s.area, self.b.E, s.inertia, _GEOM)


def _members(b: Building) -> None:
    """Columns (split at splices) and moment-connected beams."""
    ops.geomTransf("Linear", _GEOM)
    members = _Members(b)
    lines = len(b.column_lines)
    for story in range(b.levels):
        for line in range(lines):
            bottom, top = _node(story, line), _node(story + 1, line)
            section = b.columns[story][line]
            if story in b.splice_stories:
                splice = _splice_node(story, line)
                members.add(100 * story + 1 + line, bottom, splice, section, b.fy_columns)
                members.add(100 * story + 51 + line, splice, top, b.columns[story + 1][line], b.fy_columns)
            else:
                members.add(100 * story + 1 + line, bottom, top, section, b.fy_columns)
    for level in range(1, b.levels + 1):
        for bay, section in enumerate(b.beams[level - 1]):
            if section is not None:
                members.add(2000 + 100 * level + bay, _node(level, bay), _node(level, bay + 1), section, b.fy_beams)


def _eigen(b: Building, n_modes: int) -> np.ndarray:
    """Eigen periods [s] of the first ``n_modes`` modes: ARPACK when the mass
    DOFs outnumber twice the modes (it fails otherwise), else the dense solver."""
    if 2 * n_modes < b.stories:
        lam = ops.eigen("-genBandArpack", n_modes)
    else:
        lam = ops.eigen("-fullGenLapack", n_modes)
    lam = np.asarray(lam, dtype=float)
    if lam.size != n_modes or np.any(~np.isfinite(lam)) or np.any(lam <= 0):
        raise RuntimeError(f"eigen analysis of {b.name} failed: eigenvalues {lam}")
    return 2 * np.pi / np.sqrt(lam)


def rayleigh_coefficients(zeta: float, omega_i: float, omega_j: float) -> tuple[float, float]:
    """(a0 [1/s], a1 [s]) giving damping ratio zeta at omega_i and omega_j
    [rad/s]: a0 = 2 zeta w_i w_j / (w_i + w_j), a1 = 2 zeta / (w_i + w_j)."""
    return 2 * zeta * omega_i * omega_j / (omega_i + omega_j), 2 * zeta / (omega_i + omega_j)


def _dampers(b: Building, damper: list[tuple], damper_tag: int) -> tuple[int, ...]:
    """Damper material commands, then one damper link per above-grade story."""
    for command in damper:
        getattr(ops, command[0])(*command[1:])
    if b.brace_stiffness is not None:
        ops.uniaxialMaterial("Elastic", BRACE_MATERIAL, b.brace_stiffness)
    links = []
    for story in range(b.ground_level, b.levels):
        bottom, top = _node(story, b.damper_bay), _node(story + 1, b.damper_bay + 1)
        link = _DAMPER_ELE + story
        if b.brace_stiffness is not None:
            mid = _MID_NODE + story
            (x0, z0), (x1, z1) = ops.nodeCoord(bottom), ops.nodeCoord(top)
            ops.node(mid, 0.5 * (x0 + x1), 0.5 * (z0 + z1))
            ops.fix(mid, 0, 0, 1)
            ops.element("twoNodeLink", _BRACE_ELE + story, bottom, mid, "-mat", BRACE_MATERIAL, BRACE_MATERIAL,
                        "-dir", 1, 2)
            bottom = mid
        ops.element("twoNodeLink", link, bottom, top, "-mat", damper_tag, "-dir", 1)
        links.append(link)
    return tuple(links)


def build_frame(building: Building, damper: list[tuple] | None = None, damper_tag: int = DAMPER_TAGS_FROM,
                n_modes: int | None = None) -> FrameModel:
    """Wipe OpenSees and build ``building`` with Rayleigh damping and, when
    ``damper`` (OpenSees command tuples defining uniaxial material
    ``damper_tag`` in kN and mm) is given, one damper per above-grade story.
    ``n_modes``: eigen periods to compute (default min(3, stories), at least
    the Rayleigh modes)."""
    b = building
    if damper is not None and damper_tag < DAMPER_TAGS_FROM:
        raise InputError(f"damper_tag {damper_tag}: damper materials need tags >= {DAMPER_TAGS_FROM} "
                         f"(the frame uses 1..{DAMPER_TAGS_FROM - 1})")
    wanted = max(min(3, b.stories) if n_modes is None else n_modes, *b.damping_modes)
    if wanted > b.stories:
        raise InputError(f"building {b.name}: {wanted} modes asked (damping_modes {b.damping_modes}) "
                         f"but only {b.stories} stories have mass")
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    _nodes(b)
    _members(b)
    periods = _eigen(b, wanted)
    omega = 2 * np.pi / periods
    a0, a1 = rayleigh_coefficients(b.damping_ratio, omega[b.damping_modes[0] - 1], omega[b.damping_modes[1] - 1])
    ops.rayleigh(a0, 0.0, a1, 0.0)   # before the links: frame only (see module docstring)
    links = _dampers(b, damper, damper_tag) if damper else ()
    floors = tuple(_node(level, 0) for level in range(b.ground_level + 1, b.levels + 1))
    return FrameModel(floors, links, periods, (float(a0), float(a1)))


def frame_periods(building: Building, n_modes: int | None = None) -> np.ndarray:
    """Eigen periods [s] of the first ``n_modes`` modes of the bare frame
    (default min(3, stories)), mode 1 first."""
    periods = build_frame(building, n_modes=n_modes).periods
    return periods if n_modes is None else periods[:n_modes]


# ------------------------------------------------------------------ analysis


class _Stepper:
    """Advances the transient analysis one step: the ALGORITHMS in turn, then
    halves (recursively), then LAST_RESORT at the smallest sub-step; counts
    what it used."""

    def __init__(self):
        self.counts = {_name(a, t): 0 for a, t in ALGORITHMS + (LAST_RESORT,)}
        self.split_steps, self.relaxed_steps, self.smallest = 0, 0, np.inf

    def _solve(self, dt: float, algorithm: tuple, test: tuple) -> bool:
        ops.test(*test)
        ops.algorithm(*algorithm)
        if ops.analyze(1, dt) != 0:
            return False
        self.counts[_name(algorithm, test)] += 1
        self.smallest = min(self.smallest, dt)
        return True

    def _try(self, dt: float, depth: int) -> bool:
        if any(self._solve(dt, a, t) for a, t in ALGORITHMS):
            return True
        if depth < MAX_HALVINGS:
            return self._try(0.5 * dt, depth + 1) and self._try(0.5 * dt, depth + 1)
        if self._solve(dt, *LAST_RESORT):
            self.relaxed_steps += 1
            return True
        return False

    def step(self, dt: float) -> bool:
        """True when the step of length dt [s] converged."""
        before = sum(self.counts.values())
        ok = self._try(dt, 0)
        if sum(self.counts.values()) - before > 1:
            self.split_steps += 1
        return ok


def _name(algorithm: tuple, test: tuple) -> str:
    """'KrylovNewton', or with LAST_RESORT 'KrylovNewton (NormDispIncr only)'."""
    name = " ".join(map(str, algorithm))
    return f"{name} ({test[0]} only)" if (algorithm, test) == LAST_RESORT else name


def _transient(dt: float, accel: np.ndarray) -> None:
    """Horizontal uniform excitation by accel [mm/s^2] sampled at dt [s], and
    the transient analysis objects."""
    ops.timeSeries("Path", 1, "-dt", dt, "-values", *accel)
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
    ops.constraints("Transformation")          # the equalDOF rigid floors
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.test(*ALGORITHMS[0][1])
    ops.integrator(*INTEGRATOR)
    ops.algorithm(*ALGORITHMS[0][0])
    ops.analysis("Transient")


def _motion_arrays(motion) -> tuple[str, float, np.ndarray]:
    """(name, dt [s], accel [mm/s^2]) of a GroundMotion-like object, checked."""
    name = str(getattr(motion, "name", "motion"))
    dt = float(motion.dt)
    accel = np.asarray(motion.accel, dtype=float)
    if not dt > 0 or accel.ndim != 1 or accel.size < 2 or not np.all(np.isfinite(accel)):
        raise InputError(f"ground motion {name}: needs dt > 0 s and a finite 1-D accel [mm/s^2] of >= 2 samples")
    return name, dt, accel


def run_frame(building: Building, motion, damper: list[tuple] | None = None, damper_tag: int = DAMPER_TAGS_FROM,
              dt_analysis: float | None = None, record_dampers: bool = True,
              free_vibration: float | None = None) -> FrameResult:
    """Shake ``building`` with ``motion`` (name, dt [s], accel [mm/s^2]) and
    collect the response.

    damper          OpenSees command tuples defining uniaxial material
                    ``damper_tag`` (>= 1000; force kN, deformation mm, rate mm/s),
                    one copy per above-grade story; None = bare frame
    dt_analysis     [s] analysis step (default the record's dt)
    record_dampers  read damper deformation and force at each step
    free_vibration  [s] at rest after the record (default max(5 s, 4 T1))
    """
    name, dt, accel = _motion_arrays(motion)
    model = build_frame(building, damper, damper_tag)
    h = dt if dt_analysis is None else float(dt_analysis)
    if not h > 0:
        raise InputError(f"dt_analysis = {dt_analysis}: must be > 0 s")
    record_end = (accel.size - 1) * dt
    t_free = max(5.0, 4.0 * model.periods[0]) if free_vibration is None else float(free_vibration)
    n_steps = int(round((record_end + t_free) / h))

    _transient(dt, accel)
    floors, links = model.floor_nodes, model.damper_links if record_dampers else ()
    t = np.zeros(n_steps + 1)
    u = np.zeros((n_steps + 1, len(floors)))
    a_rel = np.zeros_like(u)
    dmp_d = np.zeros((n_steps + 1, len(links)))
    dmp_f = np.zeros_like(dmp_d)
    stepper, done, failed_at = _Stepper(), n_steps, None
    height = building.elevations[-1]
    for k in range(1, n_steps + 1):
        if not stepper.step(h):
            done, failed_at = k - 1, float(t[k - 1] + h)
            break
        t[k] = ops.getTime()
        for i, node in enumerate(floors):
            u[k, i] = ops.nodeDisp(node, 1)
            a_rel[k, i] = ops.nodeAccel(node, 1)
        if not np.all(np.abs(u[k]) < height):      # NaN or beyond the building's height: diverged
            done, failed_at = k - 1, float(t[k])
            break
        for i, link in enumerate(links):
            dmp_d[k, i] = ops.eleResponse(link, "basicDeformation")[0]
            dmp_f[k, i] = ops.eleResponse(link, "basicForce")[0]
    ops.wipe()

    t, u, drift, a_abs, ag, dmp_d, dmp_f = histories(building, accel, dt, done, t, u, a_rel, dmp_d, dmp_f)
    has = bool(links)
    energy = loop_energy(dmp_f, dmp_d) if has else None
    return FrameResult(building.name, name, t, u, drift, a_abs, ag,
                       dmp_d if has else None, dmp_f if has else None, model.periods, model.rayleigh,
                       record_end, _report(stepper, failed_at, t[-1], energy), list(damper or []))


def histories(building, accel, dt: float, done: int, t, u, a_rel, dmp_d, dmp_f) -> tuple:
    """The first ``done`` + 1 samples of an analysis' histories, with the ground
    acceleration [mm/s^2] at t (zero after the record), the drift ratios [-]
    and the absolute floor accelerations [mm/s^2]: (t, u, drift, a_abs, ag, dmp_d, dmp_f)."""
    keep = slice(0, done + 1)
    t, u, a_rel, dmp_d, dmp_f = t[keep], u[keep], a_rel[keep], dmp_d[keep], dmp_f[keep]
    ag = np.interp(t, np.arange(accel.size) * dt, accel, right=0.0)
    heights = np.asarray(building.story_heights[building.ground_level:])
    drift = np.diff(np.column_stack([np.zeros(len(t)), u]), axis=1) / heights
    return t, u, drift, a_rel + ag[:, None], ag, dmp_d, dmp_f


def _report(stepper: _Stepper, failed_at: float | None, t_end: float, energy) -> SolverReport:
    """The SolverReport, its message naming every shortcut and failure.  A
    negative damper energy (a passive damper's integral F dDelta is >= 0 at
    rest) flags damper forces that did not converge."""
    notes = []
    if stepper.relaxed_steps:
        notes.append(f"{stepper.relaxed_steps} sub-steps accepted on the displacement increment only "
                     f"(force residual above {ALGORITHMS[0][1][1]} kN)")
    if failed_at is not None:
        notes.append(f"the response diverged or a step failed at t = {failed_at:.4f} s; "
                     f"the histories stop at t = {t_end:.4f} s")
    if energy is not None and np.any(energy < 0):
        stories = ", ".join(str(i + 1) for i in np.flatnonzero(energy < 0))
        notes.append(f"negative damper energy in story {stories}: its damper forces are not trustworthy")
    return SolverReport(dict(stepper.counts), stepper.split_steps, float(stepper.smallest),
                        stepper.relaxed_steps, failed_at is None, failed_at, "; ".join(notes))
