"""The transient analysis of a frame built by ``model.build_frame``: the
ground motion, the step-by-step solver with its fallbacks, the loop that
records the response, and the report of how it went (kN, mm, s).  Both
``analysis.run_frame`` (damper links in OpenSees) and
``cosim.cosimulate_frame`` (damper FMUs) step through ``step_through``.

Ground motion: ``UniformExcitation`` in the horizontal direction with a
``Path`` series of the record's acceleration [mm/s^2] (zero after its end),
then free vibration at rest.  Newmark average acceleration (gamma = 1/2,
beta = 1/4), steps of the analysis step h (``Excitation``);
``transient_commands`` lists the commands.

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
the run stops.  ``SolverReport`` counts the (sub)steps of
each algorithm, the split steps and the relaxed ones, and its ``message`` names
every shortcut and failure (also a negative damper energy, which a passive
damper cannot have).  Linear and alpha >= 0.5 dampers converge at the first
try in almost every step; for alpha < 0.5 peak drifts move by a few % with dt_analysis (stick-slip
near the reversals): compare with a halved step.  Strong alpha = 0.3 ``Viscous``
dampers in all nine stories of the 9-story frame defeat this ladder (El Centro,
elastic members: the run stops at 13.8 s, its relaxed sub-steps 10-40% off the
co-simulation's peak drifts).  ``fvd-bridge frame`` therefore puts such a
dashpot behind a stiff spring (``export.opensees.solving_springs``: OpenSees'
``ViscousDamper``, which integrates the force inside the material and reports
no tangent) and starts each step with KrylovNewton (``algorithms_for``): that
run reaches the record's end in 10 s, its peak drifts within 0.1% of the FMU
co-simulation's (tests/frames/test_frames_solving.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import openseespy.opensees as ops

from ..errors import InputError
from ..opensees_commands import apply

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
#: ALGORITHMS for dampers with a material that reports no tangent (OpenSees'
#: ``ViscousDamper``, which integrates its force inside the material): Newton
#: then iterates on the frame's stiffness alone and stalls where the damper is
#: stiffer; KrylovNewton accelerates those iterations and converges at once
ZERO_TANGENT_MATERIALS = ("ViscousDamper",)
ZERO_TANGENT_ALGORITHMS = (ALGORITHMS[1], ALGORITHMS[0]) + ALGORITHMS[2:]
#: a step none of the algorithms completes is halved, at most this many times
MAX_HALVINGS = 3
#: at the smallest sub-step, when all ALGORITHMS fail: a test on the displacement
#: increment [mm] only, which a stuck damper (its force set by round-off-level
#: velocities) can pass; such sub-steps are counted in SolverReport.relaxed_steps
LAST_RESORT = (("KrylovNewton",), ("NormDispIncr", 1e-5, 30))
#: tag of the ground motion's time series and load pattern
EXCITATION = 1


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


# --------------------------------------------------------------- the motion


@dataclass(frozen=True)
class Excitation:
    """A ground motion checked for the analysis: ``name``, ``dt`` [s] and
    ``accel`` [mm/s^2] of the record, ``h`` [s] the analysis step."""

    name: str
    dt: float
    accel: np.ndarray
    h: float

    @classmethod
    def of(cls, motion, dt_analysis: float | None = None) -> Excitation:
        """From a GroundMotion-like object (name, dt [s], accel [mm/s^2]);
        ``dt_analysis`` [s] default the record's dt."""
        name = str(getattr(motion, "name", "motion"))
        dt = float(motion.dt)
        accel = np.asarray(motion.accel, dtype=float)
        if not dt > 0 or accel.ndim != 1 or accel.size < 2 or not np.all(np.isfinite(accel)):
            raise InputError(f"ground motion {name}: needs dt > 0 s and a finite 1-D accel [mm/s^2] "
                             f"of >= 2 samples")
        h = dt if dt_analysis is None else float(dt_analysis)
        if not h > 0:
            raise InputError(f"dt_analysis = {dt_analysis}: must be > 0 s")
        return cls(name, dt, accel, h)

    @property
    def record_end(self) -> float:
        """[s] time of the record's last sample."""
        return (self.accel.size - 1) * self.dt

    def steps(self, free_vibration: float) -> int:
        """Analysis steps through the record and ``free_vibration`` [s] after it."""
        return int(round((self.record_end + float(free_vibration)) / self.h))

    def ground(self, t) -> np.ndarray:
        """Ground acceleration [mm/s^2] at the times t [s] (zero after the record)."""
        return np.interp(t, np.arange(self.accel.size) * self.dt, self.accel, right=0.0)


def transient_commands(dt: float, accel) -> list:
    """Horizontal uniform excitation by accel [mm/s^2] sampled at dt [s], and
    the transient analysis objects (ALGORITHMS[0], INTEGRATOR)."""
    return [("timeSeries", "Path", EXCITATION, "-dt", dt, "-values", *accel),
            ("pattern", "UniformExcitation", EXCITATION, 1, "-accel", EXCITATION),
            ("constraints", "Transformation"),          # the equalDOF rigid floors
            ("numberer", "RCM"),
            ("system", "BandGeneral"),
            ("test", *ALGORITHMS[0][1]),
            ("integrator", *INTEGRATOR),
            ("algorithm", *ALGORITHMS[0][0]),
            ("analysis", "Transient")]


def start_transient(dt: float, accel) -> None:
    """Define ``transient_commands`` in OpenSees (after ``build_frame``)."""
    apply(transient_commands(dt, accel), ops)


# ---------------------------------------------------------------- stepping


def algorithm_name(algorithm: tuple, test: tuple) -> str:
    """'KrylovNewton', or with LAST_RESORT 'KrylovNewton (NormDispIncr only)'."""
    name = " ".join(map(str, algorithm))
    return f"{name} ({test[0]} only)" if (algorithm, test) == LAST_RESORT else name


def algorithms_for(damper) -> tuple:
    """The (algorithm, test) pairs to try in turn with these damper commands:
    ZERO_TANGENT_ALGORITHMS when a material reports no tangent, else ALGORITHMS."""
    materials = {c[1] for c in damper or () if c[0] == "uniaxialMaterial"}
    return ZERO_TANGENT_ALGORITHMS if materials & set(ZERO_TANGENT_MATERIALS) else ALGORITHMS


class Stepper:
    """Advances the transient analysis one step: the ``algorithms`` (default
    ALGORITHMS) in turn, then halves (recursively), then LAST_RESORT at the
    smallest sub-step; counts what it used."""

    def __init__(self, algorithms: tuple = ALGORITHMS):
        self.algorithms = algorithms
        self.counts = {algorithm_name(a, t): 0 for a, t in algorithms + (LAST_RESORT,)}
        self.split_steps, self.relaxed_steps, self.smallest = 0, 0, np.inf

    def _solve(self, dt: float, algorithm: tuple, test: tuple) -> bool:
        ops.test(*test)
        ops.algorithm(*algorithm)
        if ops.analyze(1, dt) != 0:
            return False
        self.counts[algorithm_name(algorithm, test)] += 1
        self.smallest = min(self.smallest, dt)
        return True

    def _try(self, dt: float, depth: int) -> bool:
        if any(self._solve(dt, a, t) for a, t in self.algorithms):
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


@dataclass(frozen=True)
class Steps:
    """The raw histories of ``step_through``: t [s], u [mm] and a_rel [mm/s^2]
    (floor displacement and acceleration relative to the ground), damper
    deformation dmp_d [mm] and force dmp_f [kN]; valid up to sample ``done``;
    ``failed_at`` [s] where the run stopped (None: it completed)."""

    t: np.ndarray
    u: np.ndarray
    a_rel: np.ndarray
    dmp_d: np.ndarray
    dmp_f: np.ndarray
    done: int
    failed_at: float | None


def step_through(floor_nodes, height: float, n_steps: int, h: float, n_dampers: int, advance) -> Steps:
    """Run the analysis ``n_steps`` steps of h [s]: ``advance(t)`` takes
    OpenSees from t to t + h and returns the dampers' (deformation [mm],
    force [kN]) at t + h, or None when the step failed; the floors' response
    is read from OpenSees after each step.  Stops at a failed step, or when a
    floor moves beyond ``height`` [mm] (or to NaN): the response diverged."""
    t = np.zeros(n_steps + 1)
    u = np.zeros((n_steps + 1, len(floor_nodes)))
    a_rel = np.zeros_like(u)
    dmp_d = np.zeros((n_steps + 1, n_dampers))
    dmp_f = np.zeros_like(dmp_d)
    done, failed_at = n_steps, None
    for k in range(1, n_steps + 1):
        dampers = advance(t[k - 1])
        if dampers is None:
            done, failed_at = k - 1, float(t[k - 1] + h)
            break
        t[k] = ops.getTime()
        for i, node in enumerate(floor_nodes):
            u[k, i] = ops.nodeDisp(node, 1)
            a_rel[k, i] = ops.nodeAccel(node, 1)
        if not np.all(np.abs(u[k]) < height):
            done, failed_at = k - 1, float(t[k])
            break
        dmp_d[k], dmp_f[k] = dampers
    return Steps(t, u, a_rel, dmp_d, dmp_f, done, failed_at)


def solver_report(stepper: Stepper, failed_at: float | None, t_end: float, energy) -> SolverReport:
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
