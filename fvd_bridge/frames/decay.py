"""The damping ratio a frame achieves, measured by its free-vibration decay.

Independent of the sizing formula (``sizing.py``): the frame with its
dampers, as the analyses run it (the exported material, the brace, the
column shortening, every mode), is kicked by a short half-sine ground
pulse and left to vibrate.  Its first-mode coordinate q_1(t)
(``FirstMode.modal_coordinate``) swings through extrema a_0, a_1, ...
half a damped period apart; for a linear viscous system the ratio of two
consecutive ones is exp(-pi xi / sqrt(1 - xi^2)) (the logarithmic
decrement, Chopra, Dynamics of Structures, sec. 2.2.4, eq. 2.2.6, taken
over half a cycle), so each half cycle gives

    delta_k = ln |a_k / a_k+1|,   xi_k = delta_k / sqrt(pi^2 + delta_k^2)

at the amplitude sqrt(|a_k a_k+1|) [mm].  A nonlinear damper's ratio
depends on the amplitude: the ratio at a roof amplitude A is interpolated
(linearly in log amplitude) between the half cycles around it, the pulse
scaled until the first half cycle swings above A.  The supplemental ratio
is the frame's with dampers less the bare frame's, both measured so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..records.motions import GroundMotion

#: analysis steps per first-mode period
STEPS_PER_PERIOD = 100
#: the pulse lasts this share of the first-mode period (short: a kick)
PULSE_SHARE = 0.125
#: free vibration after the pulse, in first-mode periods
FREE_PERIODS = 12
#: the first half cycle's amplitude is aimed at this multiple of the one measured at
AIM = 1.4
#: pulses tried at most
ATTEMPTS = 4


def kick(period: float, velocity: float) -> GroundMotion:
    """A half-sine ground acceleration pulse [mm/s^2] of PULSE_SHARE x
    ``period`` [s] whose velocity change is ``velocity`` [mm/s], sampled at
    period / STEPS_PER_PERIOD, with a zero sample after it."""
    dt = period / STEPS_PER_PERIOD
    n = max(2, int(round(PULSE_SHARE * period / dt)))
    tau = n * dt
    t = np.arange(n + 2) * dt
    a = np.where(t < tau, 0.5 * math.pi * velocity / tau * np.sin(math.pi * t / tau), 0.0)
    return GroundMotion("pulse", dt, a, {"pulse_velocity_mm_s": float(velocity)})


def extrema(q: np.ndarray, start: int = 0) -> np.ndarray:
    """The extreme values of q after sample ``start``, each refined by the
    parabola through it and its neighbours."""
    dq = np.diff(q[start:])
    k = start + 1 + np.flatnonzero(dq[:-1] * dq[1:] < 0)
    lo, mid, hi = q[k - 1], q[k], q[k + 1]
    curvature = lo - 2.0 * mid + hi
    with np.errstate(divide="ignore", invalid="ignore"):
        shift = np.where(curvature != 0.0, 0.5 * (lo - hi) / curvature, 0.0)
    return mid - 0.25 * (lo - hi) * shift


def half_cycles(peaks: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(amplitude [mm], damping ratio [-]) of each half cycle between
    consecutive extrema of opposite sign (module docstring)."""
    a = np.abs(peaks)
    pairs = [(i, i + 1) for i in range(len(peaks) - 1) if peaks[i] * peaks[i + 1] < 0 and a[i + 1] > 0]
    if not pairs:
        return np.array([]), np.array([])
    i, j = np.array(pairs).T
    delta = np.log(a[i] / a[j])
    return np.sqrt(a[i] * a[j]), delta / np.sqrt(math.pi ** 2 + delta ** 2)


@dataclass(frozen=True)
class Decay:
    """A free-vibration decay: ``damping`` [-] at ``amplitude`` [mm] (NaN:
    the half cycles did not reach it), and each half cycle's amplitude [mm]
    and damping ratio [-]."""

    amplitude: float
    damping: float
    amplitudes: tuple
    ratios: tuple


def ratio_at(amplitudes: np.ndarray, ratios: np.ndarray, amplitude: float) -> float:
    """The damping ratio at ``amplitude``: interpolated linearly in log
    amplitude between the half cycles around it; NaN outside them."""
    inside = [k for k in range(len(amplitudes) - 1) if amplitudes[k] >= amplitude >= amplitudes[k + 1]]
    if not inside:
        return float("nan")
    k = inside[0]
    x0, x1 = math.log(amplitudes[k]), math.log(amplitudes[k + 1])
    w = 0.0 if x0 == x1 else (math.log(amplitude) - x0) / (x1 - x0)
    return float((1.0 - w) * ratios[k] + w * ratios[k + 1])


def measure(run, mode, amplitude: float) -> Decay:
    """The first-mode damping ratio of a frame at roof amplitude
    ``amplitude`` [mm]: ``run(motion, free_vibration)`` analyses the frame
    (elastic members) under a GroundMotion with ``free_vibration`` [s]
    after it and returns its FrameResult; ``mode`` the bare frame's
    FirstMode.  The pulse starts from the undamped guess (roof velocity
    Gamma_1 dv = omega A) and is scaled until the first half cycle swings
    above ``amplitude``."""
    velocity = AIM * amplitude * mode.omega / mode.participation
    amps, ratios = np.array([]), np.array([])
    for _ in range(ATTEMPTS):
        motion = kick(mode.period, velocity)
        result = run(motion, FREE_PERIODS * mode.period)
        q = mode.modal_coordinate(result.floor_displacement)
        amps, ratios = half_cycles(extrema(q, start=motion.accel.size))
        if amps.size and amps[0] >= amplitude:
            break
        top = amps[0] if amps.size else np.max(np.abs(q))
        velocity *= AIM * amplitude / max(float(top), 1e-9 * amplitude)
    return Decay(float(amplitude), ratio_at(amps, ratios, amplitude), tuple(map(float, amps)),
                 tuple(map(float, ratios)))
