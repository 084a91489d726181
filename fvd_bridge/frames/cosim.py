"""Co-simulation of a frame with the damper FMU: OpenSees carries the frame,
one instance of the FMI 3.0 co-simulation FMU of ``fvd_bridge.export.fmu``
per story carries the damper (kN, mm, s).

The frame is ``model.build_frame`` without dampers (same members, masses,
Rayleigh damping, ground motion and Newmark average-acceleration analysis as
``analysis.run_frame``, the same ``transient.step_through`` loop); each story's damper becomes a pair of equal and opposite
nodal loads along its diagonal (lower-left joint to upper-right joint of
``building.damper_bay``, unit vector e): +F e at the lower joint, -F e at the
upper one (tension F > 0 pulls them together).  The loads sit in one Plain
pattern with a Constant series; their values change between solves through
OpenSees parameters (``parameter ... loadPattern P loadAtNode N dof`` +
``updateParameter``), so the domain does not change.  The damper's
deformation and rate are the joints' relative displacement and velocity
along e, d = e . (u_top - u_bottom) [mm], v = e . (v_top - v_bottom) [mm/s]:
the twoNodeLink's axial deformation under small displacements.

Each communication step [t, t + h] uses the FMU's end-of-step convention
(``inputs_at_step_end``): d(t + h) (and v(t + h), ``use_velocity_input``)
are set before fmi3DoStep(t, h) and F is the force at t + h.  Newmark puts the loads of t + h into the equilibrium
at t + h, so the frame needs F(t + h) before the FMU can give it:

- ``explicit``: the frame is loaded with the forces of the previous
  communication point, F(t), then each FMU steps with the frame's d(t + h),
  v(t + h).  One OpenSees solve and one FMU step per damper; no rollback;
  the force lags one step (first order in h).  The lag makes a damper whose
  force rises steeply with the velocity unstable: a power-law dashpot
  (alpha < 1: tangent alpha C |v|^(alpha - 1), unbounded at rest) chatters
  at low velocity, its force flipping sign every step (law 2, C 45,
  alpha 0.3, h = 5 ms in the 3-story frame: +-140 kN); a Maxwell damper
  (law 7, tangent at most K) does not.
- ``iterative``: per step, the OpenSees state (``NodeCheckpoint``) and every
  FMU's state (fmi3GetFMUState) are saved; the frame is solved with the
  forces F0 of the previous point, giving d0, v0; the damper forces that
  agree with the frame are then found on the FMU side, where a step costs
  microseconds: the frame's response to other forces is d0 + S_d (F - F0),
  v0 + S_v (F - F0), with S_d, S_v its step flexibility at the dampers [mm/kN,
  mm/s/kN] (probed once with unit loads; exact for a frame that stays
  linear), and F = Phi(F), Phi_i the force of FMU i rolled back and stepped
  with its story's d and v, is solved by Newton's method (``solve_damper_forces``),
  falling back to nonlinear Gauss-Seidel over the stories, each a bracketed
  scalar root (Brent): with a damper force that grows with its deformation
  and rate, Phi_i falls as F_i grows, so the root lies between F_i and
  Phi_i(F_i).  Then OpenSees is rolled back and solved again with these
  forces; the step is accepted when the frame's damper deformations match
  those the FMUs were stepped with (``tol_d``), otherwise the frame's new
  response becomes the reference and the FMU side solves again (at most
  ``max_iterations`` OpenSees solves; a linear frame needs 2).  Damper
  forces converge to ``tol_F`` in the inner solve; at a velocity reversal of
  a power-law dashpot the force is not resolvable to better than
  C |dv|^alpha for round-off dv, hence the test on deformation.

Rollback of OpenSees.  openseespy 3.7.1 has no command that undoes a
committed step (``revertToLastCommit`` is not exposed; ``analyze`` always
commits).  Two ways work for frames with elastic members
(``building.with_(yielding=False)``), bit for bit:
``NodeCheckpoint`` (every node's committed displacement, velocity and
acceleration written back with ``setNodeDisp/Vel/Accel ... -commit``, the
time with ``setTime``, then ``domainChange`` so that the Newmark integrator
reloads them; microseconds per node; each set command starts from the
node's committed vector, so every value is committed on its own), and
``database File`` + ``save`` / ``restore`` + ``domainChange`` (about 3 ms per
save, files on disk).  Neither restores yielding members: the node
checkpoint leaves the elements' committed plastic state at the rejected
trial, and ``restore`` of a ``forceBeamColumn`` (any beam integration)
crashes the process with a segmentation fault (``dispBeamColumn``
restores).  So ``iterative`` needs elastic members; the
explicit scheme runs any frame.
"""

from __future__ import annotations

import math
import tempfile
import time
from dataclasses import dataclass

import numpy as np
import openseespy.opensees as ops
from scipy.optimize import brentq

from ..errors import InputError
from .analysis import FrameResult, frame_result, free_vibration_time
from .damper_fmu import damper_fmus
from .model import build_frame, damper_diagonals
from .transient import Excitation, Stepper, start_transient, step_through

SCHEMES = ("explicit", "iterative")
#: tags of the damper load pattern and its Constant series (the ground motion uses transient.EXCITATION = 1)
LOAD_PATTERN = 2
#: first OpenSees parameter tag of the damper loads
PARAMETER_TAGS_FROM = 1
#: unit load [kN] of the flexibility probes
PROBE_FORCE = 100.0


# ------------------------------------------------------- OpenSees rollback

class NodeCheckpoint:
    """The committed state of every node (displacement, velocity,
    acceleration) and the time; ``restore`` writes them back as committed
    values and calls ``domainChange`` so that the integrator reloads them.
    Exact for models whose elements keep no state of their own (elastic
    members, links with elastic materials); see the module docstring."""

    def __init__(self):
        self.nodes = tuple(ops.getNodeTags())
        self.time, self.state = 0.0, ()

    def save(self) -> None:
        self.time = ops.getTime()
        self.state = tuple((n, ops.nodeDisp(n), ops.nodeVel(n), ops.nodeAccel(n)) for n in self.nodes)

    def restore(self) -> None:
        # each set command starts from the node's committed vector and changes
        # one dof of the trial one: commit after every value
        for n, disp, vel, accel in self.state:
            for dof, (u, v, a) in enumerate(zip(disp, vel, accel), start=1):
                ops.setNodeDisp(n, dof, u, "-commit")
                ops.setNodeVel(n, dof, v, "-commit")
                ops.setNodeAccel(n, dof, a, "-commit")
        ops.setTime(self.time)
        ops.domainChange()


# --------------------------------------------------------------- the frame

class FrameDampers:
    """The damper forces of a frame built by ``build_frame`` as nodal loads,
    and the damper deformations read from the nodes (see the module
    docstring).  ``set_forces(F)`` [kN, one per story]; ``read()`` -> (d [mm],
    v [mm/s])."""

    def __init__(self, building):
        self.pairs, self.axes = [], []
        for bottom, top in damper_diagonals(building):
            (x0, z0), (x1, z1) = ops.nodeCoord(bottom), ops.nodeCoord(top)
            length = math.hypot(x1 - x0, z1 - z0)
            self.pairs.append((bottom, top))
            self.axes.append(((x1 - x0) / length, (z1 - z0) / length))
        nodes = sorted({n for pair in self.pairs for n in pair})
        self.n = len(self.pairs)
        # B: nodal load components (node, dof 1 or 2) per unit damper force
        rows = [(node, dof) for node in nodes for dof in (1, 2)]
        self.B = np.zeros((len(rows), self.n))
        for i, ((bottom, top), (ex, ez)) in enumerate(zip(self.pairs, self.axes)):
            for node, sign in ((bottom, 1.0), (top, -1.0)):
                self.B[rows.index((node, 1)), i] += sign * ex
                self.B[rows.index((node, 2)), i] += sign * ez
        ops.timeSeries("Constant", LOAD_PATTERN)
        ops.pattern("Plain", LOAD_PATTERN, LOAD_PATTERN)
        for node in nodes:
            ops.load(node, 0.0, 0.0, 0.0)
        self.parameters = []
        for k, (node, dof) in enumerate(rows):
            tag = PARAMETER_TAGS_FROM + k
            ops.parameter(tag, "loadPattern", LOAD_PATTERN, "loadAtNode", node, dof)
            self.parameters.append(tag)

    def set_forces(self, F) -> None:
        for tag, value in zip(self.parameters, self.B @ np.asarray(F, dtype=float)):
            ops.updateParameter(tag, float(value))

    def read(self) -> tuple[np.ndarray, np.ndarray]:
        d, v = np.empty(self.n), np.empty(self.n)
        for i, ((bottom, top), (ex, ez)) in enumerate(zip(self.pairs, self.axes)):
            ub, ut = ops.nodeDisp(bottom), ops.nodeDisp(top)
            vb, vt = ops.nodeVel(bottom), ops.nodeVel(top)
            d[i] = ex * (ut[0] - ub[0]) + ez * (ut[1] - ub[1])
            v[i] = ex * (vt[0] - vb[0]) + ez * (vt[1] - vb[1])
        return d, v


@dataclass(frozen=True)
class CosimStats:
    """How a co-simulation went.

    scheme            'explicit' or 'iterative'
    steps             communication steps (= OpenSees analysis steps)
    opensees_solves   mean OpenSees solves per step (1 for explicit)
    max_solves        most OpenSees solves in one step
    fmu_steps         mean FMU steps per damper per step (1 for explicit)
    unconverged       steps accepted after max_iterations solves without meeting tol_d
    probe_solves      OpenSees solves spent probing the step flexibility (iterative)
    wall_s            wall time [s] of the time stepping (the FMU build not included)
    """

    scheme: str
    steps: int
    opensees_solves: float
    max_solves: int
    fmu_steps: float
    unconverged: int
    probe_solves: int
    wall_s: float


def solve_damper_forces(fmus, states, t, h, *, d0, v0, F0, S_d, S_v, tol_F=1e-6, newton_iterations=6,
                        max_sweeps=50):
    """The damper forces F [kN] with F_i = Phi_i(F) (see the module
    docstring): FMU i rolled back to states[i] and stepped over [t, t + h]
    with d0 + S_d (F - F0), v0 + S_v (F - F0) of its story.

    Newton first: the Jacobian of Phi is taken as a_i S_d[i, j] / S_d[i, i],
    a_i = dPhi_i/dF_i by a finite difference of FMU i (exact when each
    story's rate response is a fixed multiple of its deformation response,
    as with Newmark); it stops when no force changes Phi by more than tol_F,
    and gives way when the residual stops falling (a velocity reversal of a
    power-law dashpot).  Then nonlinear Gauss-Seidel over the dampers, each a
    Brent root in the bracket [F_i, Phi_i(F_i)], sweeps until no force moves
    by more than tol_F.  Returns (F, converged); every FMU is left stepped
    at its story's motion under F (its outputs are the damper forces)."""
    F0 = np.asarray(F0, dtype=float)
    F = F0.copy()
    n = F.size

    def phi(i, x):
        dF = F - F0
        dF[i] = x - F0[i]
        fmus[i].restore(states[i])
        return fmus[i].step(t, h, d0[i] + S_d[i] @ dF, v0[i] + S_v[i] @ dF, rollback=True)

    coupling = S_d / np.diag(S_d)[:, None]
    best, best_norm = F.copy(), math.inf
    for _ in range(newton_iterations):
        G = np.array([phi(i, F[i]) for i in range(n)]) - F
        norm = float(np.max(np.abs(G)))
        if norm <= tol_F:
            return F, True
        if norm >= best_norm:
            break
        best, best_norm = F.copy(), norm
        step = 1e-4 * np.maximum(1.0, np.abs(F))
        a = np.array([(phi(i, F[i] + step[i]) - (F[i] + G[i])) / step[i] for i in range(n)])
        F = F + np.linalg.solve(np.eye(n) - a[:, None] * coupling, G)
    F = best

    converged = False
    for _ in range(max_sweeps):
        moved = 0.0
        for i in range(n):
            a = F[i]
            g_a = phi(i, a) - a
            if abs(g_a) <= tol_F:
                continue
            b = a + g_a
            g_b = phi(i, b) - b
            if g_b == 0.0 or g_a * g_b > 0.0:  # root at b, or round-off at a flat end
                root = b
            else:
                root = brentq(lambda x: phi(i, x) - x, a, b, xtol=tol_F, rtol=4 * np.finfo(float).eps)
            moved = max(moved, abs(root - a))
            F[i] = root
        if moved <= tol_F:
            converged = True
            break
    for i in range(n):  # leave each FMU stepped with the accepted forces
        phi(i, F[i])
    return F, converged


def probe_flexibility(dampers: FrameDampers, checkpoint: NodeCheckpoint, stepper: Stepper, h: float):
    """(S_d [mm/kN], S_v [mm/s/kN]): the change of the damper deformations
    and rates at the end of one step of h [s] per kN of damper force, column
    j for damper j, from n + 1 solves (zero forces, then PROBE_FORCE on each
    damper) from the saved state; OpenSees is left restored."""
    n = dampers.n
    checkpoint.save()
    response = []
    for j in range(-1, n):
        F = np.zeros(n)
        if j >= 0:
            F[j] = PROBE_FORCE
        checkpoint.restore()
        dampers.set_forces(F)
        if not stepper.step(h):
            raise RuntimeError("the flexibility probe's OpenSees step did not converge")
        response.append(dampers.read())
    checkpoint.restore()
    (d0, v0), rest = response[0], response[1:]
    S_d = np.column_stack([(d - d0) / PROBE_FORCE for d, _ in rest])
    S_v = np.column_stack([(v - v0) / PROBE_FORCE for _, v in rest])
    return S_d, S_v


def cosimulate_frame(building, motion, fmu_path, scheme: str = "iterative", *, dt_analysis: float | None = None,
                     free_vibration: float | None = 0.0, use_velocity: bool = True, tol_d: float = 1e-6,
                     tol_F: float = 1e-6, max_iterations: int = 10,
                     force_scale: float = 1.0) -> tuple[FrameResult, CosimStats]:
    """Shake ``building`` (without dampers; rigid braces) with ``motion``
    (name, dt [s], accel [mm/s^2]) while one instance of the damper FMU at
    ``fmu_path`` per above-grade story gives its damper's force; returns the
    response as ``run_frame`` does (damper deformation and force histories:
    the frame's and the FMUs') and CosimStats.

    scheme          'explicit' or 'iterative' (elastic members only)
    dt_analysis     [s] communication and analysis step (default the record's dt)
    free_vibration  [s] at rest after the record (None: as ``run_frame``, max(5 s, 4 T1))
    use_velocity    send the frame's damper rate v to the FMU (else it derives v from d)
    tol_d           [mm] iterative: frame and FMU damper deformations agree
    tol_F           [kN] iterative: damper forces of the FMU-side solve
    max_iterations  iterative: OpenSees solves per step at most
    force_scale     each story's damper force is the FMU's times this
    """
    if scheme not in SCHEMES:
        raise InputError(f"co-simulation scheme '{scheme}': expected one of {', '.join(SCHEMES)}")
    b = building
    if b.brace_stiffness is not None:
        raise InputError(f"building {b.name}: co-simulation needs rigid braces (brace_stiffness None); "
                         "the FMU's nodal loads act at the diagonal's joints")
    if scheme == "iterative" and b.yielding:
        raise InputError(f"building {b.name}: the iterative scheme rolls OpenSees back, which openseespy "
                         "does only for elastic members: use building.with_(yielding=False), or "
                         "scheme 'explicit'")
    excitation = Excitation.of(motion, dt_analysis)
    h = excitation.h
    model = build_frame(b)
    free_vibration = free_vibration_time(model.periods, free_vibration)
    start_transient(excitation.dt, excitation.accel)
    dampers = FrameDampers(b)
    n = dampers.n
    stepper = Stepper()
    checkpoint = NodeCheckpoint() if scheme == "iterative" else None

    with tempfile.TemporaryDirectory(prefix="fvd_cosim-") as work:
        fmus = damper_fmus(fmu_path, n, use_velocity, work, force_scale)
        try:
            wall = time.perf_counter()
            S_d = S_v = None
            if scheme == "iterative":
                S_d, S_v = probe_flexibility(dampers, checkpoint, stepper, h)
            coupling = _Coupling(scheme, fmus, dampers, checkpoint, stepper, h, S_d=S_d, S_v=S_v, tol_d=tol_d,
                                 tol_F=tol_F, max_iterations=max_iterations)
            steps = step_through(model.floor_nodes, b.elevations[-1], excitation.steps(free_vibration), h, n,
                                 coupling)
            wall = time.perf_counter() - wall
            fmu_steps = sum(f.steps for f in fmus)
        finally:
            for f in fmus:
                f.close()
    ops.wipe()

    result = frame_result(b, excitation, model, steps, stepper, [("fmu", str(fmu_path))])
    done = max(steps.done, 1)
    stats = CosimStats(scheme, steps.done, coupling.solves / done, coupling.max_solves,
                       fmu_steps / (n * done), coupling.unconverged, n + 1 if scheme == "iterative" else 0, wall)
    return result, stats


class _Coupling:
    """``advance`` of ``transient.step_through`` for the co-simulation: one
    communication step of the scheme from t; returns (d, F) of the dampers
    at t + h, or None when OpenSees failed.  Counts the OpenSees solves."""

    def __init__(self, scheme, fmus, dampers, checkpoint, stepper, h, *, S_d, S_v, tol_d, tol_F, max_iterations):
        self.scheme, self.fmus, self.dampers, self.checkpoint, self.stepper = scheme, fmus, dampers, checkpoint, stepper
        self.h, self.S_d, self.S_v = h, S_d, S_v
        self.tol_d, self.tol_F, self.max_iterations = tol_d, tol_F, max_iterations
        self.F = np.zeros(dampers.n)
        self.solves, self.max_solves, self.unconverged = 0, 0, 0

    def __call__(self, t: float):
        h = self.h
        if self.scheme == "explicit":
            self.dampers.set_forces(self.F)
            ok, used = self.stepper.step(h), 1
            if ok:
                d, v = self.dampers.read()
                self.F = np.array([f.step(t, h, d[i], v[i]) for i, f in enumerate(self.fmus)])
        else:
            ok, used, self.F, accepted = _iterative_step(self.fmus, self.dampers, self.checkpoint, self.stepper,
                                                         t, h, F_prev=self.F, S_d=self.S_d, S_v=self.S_v,
                                                         tol_d=self.tol_d, tol_F=self.tol_F,
                                                         max_iterations=self.max_iterations)
            self.unconverged += not accepted
            if ok:
                d, _ = self.dampers.read()
        self.solves += used
        self.max_solves = max(self.max_solves, used)
        return (d, self.F) if ok else None


def _iterative_step(fmus, dampers, checkpoint, stepper, t, h, *, F_prev, S_d, S_v, tol_d, tol_F, max_iterations):
    """One iterative communication step (module docstring): returns (OpenSees
    step converged, OpenSees solves, damper forces F(t + h), tol_d met)."""
    checkpoint.save()
    states = [f.save() for f in fmus]
    try:
        F_ref = np.asarray(F_prev, dtype=float)
        dampers.set_forces(F_ref)
        if not stepper.step(h):
            return False, 1, F_ref, False
        d_ref, v_ref = dampers.read()
        solves, accepted = 1, False
        while True:
            F, _ = solve_damper_forces(fmus, states, t, h, d0=d_ref, v0=v_ref, F0=F_ref, S_d=S_d, S_v=S_v, tol_F=tol_F)
            d_fmu = d_ref + S_d @ (F - F_ref)
            checkpoint.restore()
            dampers.set_forces(F)
            if not stepper.step(h):
                return False, solves + 1, F, False
            solves += 1
            d, v = dampers.read()
            if np.max(np.abs(d - d_fmu)) <= tol_d:
                accepted = True
                break
            if solves >= max_iterations:
                break
            F_ref, d_ref, v_ref = F, d, v
        forces = np.array([f.outputs()[0] for f in fmus])
        return True, solves, forces, accepted
    finally:
        for f, s in zip(fmus, states):
            f.free(s)
