"""A frame with one damper per story shaken by a ground motion: ``run_frame``
builds it (``model.build_frame``, from the command list of
``model.frame_commands``), steps through the record and the free vibration
after it (``transient``) and collects the response in a ``FrameResult``
(kN, mm, s; mass kN s^2/mm).  ``cosim.cosimulate_frame`` collects its
response the same way (``frame_result``).

openseespy keeps one global model: ``run_frame`` wipes it, and two runs cannot
share a process at the same time.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import openseespy.opensees as ops

from ..records.cycles import loop_energy  # noqa: F401  (sizing imports it from here too)
from ..records.motions import G_MM_S2
from .buildings import Building
from .model import DAMPER_TAGS_FROM, FrameModel, build_frame
from .transient import (Excitation, SolverReport, Stepper, Steps, algorithms_for, solver_report, start_transient,
                        step_through)


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
            "analysis_end_s": float(self.t[-1]) if self.t.size else 0.0, "record_end_s": float(self.record_end),
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


def histories(building: Building, excitation: Excitation, steps: Steps) -> tuple:
    """The valid samples (up to ``steps.done``) of an analysis' histories,
    with the ground acceleration [mm/s^2] at t (zero after the record), the
    drift ratios [-] and the absolute floor accelerations [mm/s^2]:
    (t, u, drift, a_abs, ag, dmp_d, dmp_f)."""
    keep = slice(0, steps.done + 1)
    t, u, a_rel = steps.t[keep], steps.u[keep], steps.a_rel[keep]
    ag = excitation.ground(t)
    heights = np.asarray(building.story_heights[building.ground_level:])
    drift = np.diff(np.column_stack([np.zeros(len(t)), u]), axis=1) / heights
    return t, u, drift, a_rel + ag[:, None], ag, steps.dmp_d[keep], steps.dmp_f[keep]


def frame_result(building: Building, excitation: Excitation, model: FrameModel, steps: Steps, stepper: Stepper,
                 damper: list, with_dampers: bool = True) -> FrameResult:
    """The FrameResult of an analysis: its histories, the bare frame's modal
    data, the solver report; ``with_dampers`` False leaves the damper
    fields None."""
    t, u, drift, a_abs, ag, dmp_d, dmp_f = histories(building, excitation, steps)
    energy = loop_energy(dmp_f, dmp_d) if with_dampers else None
    return FrameResult(building.name, excitation.name, t, u, drift, a_abs, ag,
                       dmp_d if with_dampers else None, dmp_f if with_dampers else None,
                       model.periods, model.rayleigh, excitation.record_end,
                       solver_report(stepper, steps.failed_at, t[-1], energy), list(damper))


def free_vibration_time(periods, given: float | None = None) -> float:
    """[s] at rest after the record: ``given``, else max(5 s, 4 T1) (T1 = periods[0] [s])."""
    return max(5.0, 4.0 * float(periods[0])) if given is None else float(given)


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
    excitation = Excitation.of(motion, dt_analysis)
    model = build_frame(building, damper, damper_tag)
    t_free = free_vibration_time(model.periods, free_vibration)
    start_transient(excitation.dt, excitation.accel)
    links = model.damper_links if record_dampers else ()
    stepper, h = Stepper(algorithms_for(damper)), excitation.h

    def advance(t: float):
        if not stepper.step(h):
            return None
        return ([ops.eleResponse(link, "basicDeformation")[0] for link in links],
                [ops.eleResponse(link, "basicForce")[0] for link in links])

    steps = step_through(model.floor_nodes, building.elevations[-1], excitation.steps(t_free), h, len(links),
                         advance)
    ops.wipe()
    return frame_result(building, excitation, model, steps, stepper, list(damper or []), bool(links))
