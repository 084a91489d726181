"""Dampers sized for a target supplemental damping ratio of the first mode.

The energy method (FEMA 274, 1997, sec. C9.3; FEMA 356, 2000, eqs. 9-36
and 9-37; Whittaker et al. 2003, Earthquake Spectra 19(4); Christopoulos &
Filiatrault 2006, ch. 6): in a cycle of the first mode at roof amplitude
A [mm] and circular frequency omega_1 [rad/s],

    xi_d = sum_j W_j / (4 pi W_k)

W_k = 1/2 omega_1^2 sum_i m_i (A phi_i)^2 [kN mm] the frame's largest
strain energy (the mode shape phi normalised to 1 at the roof, m_i the
floor masses [kN s^2/mm]), W_j [kN mm] the energy the damper of story j
dissipates in one cycle of its axial deformation u_j = A |psi_j| (psi_j
the damper's elongation per mm of roof displacement in the mode: the
diagonal's f_j cos theta_j, column shortening included).  For a
power-law dashpot F = C |v|^alpha sign(v),

    W_j = lambda C omega_1^alpha u_j^(1 + alpha),
    lambda = 2^(2 + alpha) Gamma(1 + alpha/2)^2 / Gamma(2 + alpha)

(FEMA 274 eq. C9-38 and table C9-4; lambda = pi for alpha = 1, 4 for
alpha = 0).  Here W_j is not taken from that closed form but computed on
the calibrated model itself (``cycle_energy``: the model driven through
sinusoidal cycles of u_j at omega_1, the last cycle's loop energy), so any
law (a Maxwell element, LuGre friction) is sized by what it dissipates; the
closed form checks it for a dashpot (tests/frames/test_sizing.py).

Distribution: one factor for every story (the same device in each story,
the calibrated law's force times it: OpenSees' ``Multiplier``), so the
stories with the largest drift in the mode take the largest stroke and
force.  The loop energy scales with the factor, so the factor is
target / xi_d(1).  The brace is taken as rigid and the members elastic;
``decay.py`` measures what the frame achieves, brace and all.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
import openseespy.opensees as ops

from ..errors import InputError
from ..records.record import Record
from .analysis import loop_energy
from .model import build_frame, damper_diagonals, floor_nodes

#: sinusoidal cycles the model runs through for its loop energy (the last one counts)
CYCLES = 3
#: samples per cycle of that motion
SAMPLES_PER_CYCLE = 400


@dataclass(frozen=True)
class FirstMode:
    """The bare frame's first mode (elastic members; kN, mm, s).

    omega         [rad/s] circular frequency
    floor_shape   horizontal displacement of each above-grade level, 1 at the roof
    damper_shape  each story's damper elongation [mm] per mm of roof displacement
    masses        [kN s^2/mm] each above-grade level's mass
    roof_height   [mm] roof above the ground level
    """

    omega: float
    floor_shape: np.ndarray
    damper_shape: np.ndarray
    masses: np.ndarray
    roof_height: float

    @property
    def period(self) -> float:
        """[s] 2 pi / omega."""
        return 2.0 * math.pi / self.omega

    @property
    def modal_mass(self) -> float:
        """phi^T M phi [kN s^2/mm] (phi 1 at the roof)."""
        return float(np.sum(self.masses * self.floor_shape ** 2))

    @property
    def participation(self) -> float:
        """Gamma_1 = phi^T M 1 / phi^T M phi [-]: the roof's share of a ground velocity kick."""
        return float(np.sum(self.masses * self.floor_shape)) / self.modal_mass

    def strain_energy(self, roof_amplitude: float) -> float:
        """W_k = 1/2 omega^2 sum m_i (A phi_i)^2 [kN mm] at roof amplitude A [mm]."""
        return 0.5 * self.omega ** 2 * roof_amplitude ** 2 * self.modal_mass

    def modal_coordinate(self, floor_displacement: np.ndarray) -> np.ndarray:
        """q_1(t) = phi^T M u(t) / phi^T M phi [mm]: the first mode's roof
        displacement in floor histories u (n_t x levels); the other modes of
        the bare frame drop out (M-orthogonal)."""
        return np.asarray(floor_displacement) @ (self.masses * self.floor_shape) / self.modal_mass


def first_mode(building) -> FirstMode:
    """The first mode of ``building``'s bare frame with elastic members
    (OpenSees' eigen analysis; wipes the model)."""
    b = building.with_(yielding=False)
    model = build_frame(b, n_modes=1)
    omega = 2.0 * math.pi / float(model.periods[0])

    def vector(node):
        return np.array([ops.nodeEigenvector(node, 1, 1), ops.nodeEigenvector(node, 1, 2)])

    nodes = floor_nodes(b)
    roof = vector(nodes[-1])[0]
    floors = np.array([vector(n)[0] for n in nodes]) / roof
    shape = []
    for bottom, top in damper_diagonals(b):
        axis = np.subtract(ops.nodeCoord(top), ops.nodeCoord(bottom))
        shape.append(float(np.dot(vector(top) - vector(bottom), axis / np.linalg.norm(axis))) / roof)
    ops.wipe()
    z = b.elevations
    return FirstMode(omega, floors, np.abs(np.array(shape)), np.array(b.floor_masses[b.ground_level:]),
                     float(z[-1] - z[b.ground_level]))


def power_law_lambda(alpha: float) -> float:
    """lambda = 2^(2 + alpha) Gamma(1 + alpha/2)^2 / Gamma(2 + alpha) (FEMA 274 table C9-4)."""
    return 2.0 ** (2.0 + alpha) * math.gamma(1.0 + alpha / 2.0) ** 2 / math.gamma(2.0 + alpha)


def cycle_energy(cal, amplitude: float, omega: float) -> tuple[float, float]:
    """(energy [kN mm], peak |force| [kN]) of the calibrated model ``cal``
    in one cycle of u(t) = amplitude sin(omega t) [mm, rad/s]: the last of
    CYCLES cycles, so a model with a state (a spring, friction) is in its
    steady cycle."""
    n = CYCLES * SAMPLES_PER_CYCLE
    t = np.arange(n + 1) * (2.0 * math.pi / omega) / SAMPLES_PER_CYCLE
    d = amplitude * np.sin(omega * t)
    v = amplitude * omega * np.cos(omega * t)
    record = Record(t, d, np.zeros_like(t), v, -omega ** 2 * d, name="design cycle")  # the exact motion
    F = cal.force(record)
    last = slice(n - SAMPLES_PER_CYCLE, n + 1)
    return float(loop_energy(F[last, None], d[last, None])[0]), float(np.max(np.abs(F[last])))


@dataclass(frozen=True)
class StoryDamper:
    """A story's damper in the design cycle: its stroke amplitude [mm],
    peak velocity omega u [mm/s], loop energy [kN mm] and peak force [kN] of
    the calibrated device (factor 1)."""

    amplitude: float
    velocity: float
    energy: float
    force: float


@dataclass(frozen=True)
class Design:
    """Dampers sized for ``target`` (or, with target None, the damping the
    devices as they are give): the factor on the calibrated device's force
    in every story (all dampers of a story together), at roof amplitude
    ``roof_amplitude`` [mm] (roof drift ratio ``roof_drift``)."""

    target: float | None
    roof_amplitude: float
    roof_drift: float
    period: float
    stories: tuple[StoryDamper, ...]
    strain_energy: float
    factor: float

    @property
    def damping(self) -> float:
        """xi_d = factor sum W_j / (4 pi W_k) [-] (module docstring)."""
        return self.factor * sum(s.energy for s in self.stories) / (4.0 * math.pi * self.strain_energy)


def design(mode: FirstMode, cal, roof_drift: float, target: float | None = None, factor: float = 1.0) -> Design:
    """The dampers of ``cal``'s device in every story at roof drift ratio
    ``roof_drift`` [-]: sized for the supplemental damping ratio ``target``
    (the factor that gives it), else as they are (``factor``)."""
    if not roof_drift > 0:
        raise InputError(f"--design-drift {roof_drift}: must be > 0")
    A = roof_drift * mode.roof_height
    stories = []
    for psi in mode.damper_shape:
        u = A * psi
        energy, force = cycle_energy(cal, u, mode.omega)
        stories.append(StoryDamper(float(u), float(mode.omega * u), energy, force))
    as_is = Design(None, A, roof_drift, mode.period, tuple(stories), mode.strain_energy(A), 1.0)
    if target is None:
        return replace(as_is, factor=factor)
    if not as_is.damping > 0:
        raise InputError(f"--target-damping {target}: law {cal.spec} dissipates no energy in the design cycle; "
                         "it cannot be sized for damping")
    return replace(as_is, target=target, factor=target / as_is.damping)
