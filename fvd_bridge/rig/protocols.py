"""Imposed-displacement protocols of the virtual rig.

A protocol gives the analytic displacement d(t) [mm], velocity v(t) [mm/s]
and acceleration a(t) [mm/s^2] at any time (the rig integrates against
these, not against samples) and the sample times t0 + k dt [s].

Sinusoidal segments start and end with a cosine taper, as real actuators do:
  d(t) = A w(tau) sin(omega tau),  tau = t - t_start,
  w = (1 - cos(pi tau / T_t)) / 2 over the fade-in tau < T_t, 1 in the middle,
  mirrored over the fade-out; T_t = taper / f (default half a cycle).
  v = A (w' sin + w omega cos),  a = A (w'' sin + 2 w' omega cos - w omega^2 sin).
With the default half-cycle taper d, v and a are continuous everywhere and the
segment starts and ends at rest; ``cycles`` counts the full-amplitude cycles,
the tapers add half a cycle at each end.
"""

from __future__ import annotations

import csv
import math
import os
from dataclasses import dataclass

import numpy as np

from ..errors import InputError, positive, option
from ..records.motions import read_two_column, starts_with_number

#: the paper's identification test (section 3): 10 cycles of 40 mm at 0.5 m/s
PAPER = {"amplitude": 40.0, "velocity": 500.0, "cycles": 10, "dt": 0.002}
#: velocity levels of the acceptance protocol, fractions of Vmax
ACCEPTANCE_LEVELS = (0.01, 0.25, 0.50, 0.75, 1.00)
#: fewest samples per cycle a sinusoid must have
MIN_SAMPLES_PER_CYCLE = 16


@dataclass(frozen=True)
class SineSegment:
    """A tapered sinusoid: amplitude [mm], frequency [Hz], full-amplitude cycles,
    taper (fade-in and fade-out length, each in cycles)."""

    amplitude: float
    frequency: float
    cycles: float
    taper: float = 0.5

    def __post_init__(self):
        positive("protocol amplitude [mm]", self.amplitude)
        positive("protocol frequency [Hz]", self.frequency)
        positive("protocol cycles", self.cycles)
        if not (math.isfinite(self.taper) and self.taper >= 0.0):
            raise InputError(f"protocol taper = {self.taper:g}: must be >= 0 cycles")

    @property
    def omega(self) -> float:
        """Circular frequency [rad/s]."""
        return 2.0 * math.pi * self.frequency

    @property
    def duration(self) -> float:
        """Length [s], tapers included."""
        return (self.cycles + 2.0 * self.taper) / self.frequency

    @property
    def peak_velocity(self) -> float:
        """A omega [mm/s]."""
        return self.amplitude * self.omega

    def motion(self, tau: np.ndarray):
        """d, v, a at local times tau in [0, duration] [s]."""
        A, om, T = self.amplitude, self.omega, self.duration
        w, w1, w2 = np.ones_like(tau), np.zeros_like(tau), np.zeros_like(tau)
        if self.taper > 0.0:
            Tt = self.taper / self.frequency
            k = math.pi / Tt
            for sigma, sgn in ((tau, 1.0), (T - tau, -1.0)):
                m = sigma < Tt
                ph = k * sigma[m]
                w[m] = 0.5 * (1.0 - np.cos(ph))
                w1[m] = sgn * 0.5 * k * np.sin(ph)
                w2[m] = 0.5 * k * k * np.cos(ph)
        s, c = np.sin(om * tau), np.cos(om * tau)
        d = A * w * s
        v = A * (w1 * s + w * om * c)
        a = A * (w2 * s + 2.0 * w1 * om * c - w * om * om * s)
        return d, v, a

    def describe(self) -> dict:
        return {"amplitude_mm": float(self.amplitude), "frequency_Hz": float(self.frequency),
                "peak_velocity_mm_s": float(self.peak_velocity), "cycles": float(self.cycles),
                "taper_cycles": float(self.taper)}


class Protocol:
    """Base: sample times on a uniform grid and analytic motion."""

    name = "protocol"
    t0 = 0.0
    dt = 0.002
    duration = 0.0

    @property
    def n(self) -> int:
        """Number of samples."""
        return int(math.floor(self.duration / self.dt + 1e-9)) + 1

    def times(self) -> np.ndarray:
        """Sample times t0 + k dt [s]."""
        return self.t0 + self.dt * np.arange(self.n)

    def motion(self, t: np.ndarray):
        """Analytic d [mm], v [mm/s], a [mm/s^2] at times t [s] (vectorized)."""
        raise NotImplementedError

    def breakpoints(self) -> np.ndarray:
        """Times [s] where the motion is not smooth (segment ends); the rig
        puts an integration node on each."""
        return np.empty(0)

    def describe(self) -> dict:
        raise NotImplementedError


class SineProtocol(Protocol):
    """Tapered sinusoidal segments separated by pauses at rest.

    Layout: ``rest`` [s] at rest, segment 1, ``pause`` [s], segment 2, ...,
    ``rest`` [s]; sampled every ``dt`` [s].
    """

    def __init__(self, segments, dt: float, name: str = "sine", rest: float = 0.1, pause: float = 0.2):
        self.segments = tuple(segments)
        if not self.segments:
            raise InputError("protocol: no segments")
        self.dt = positive("protocol dt [s]", dt)
        if not (math.isfinite(rest) and rest >= 0.0):
            raise InputError(f"protocol rest = {rest:g}: must be >= 0 s")
        if not (math.isfinite(pause) and pause >= 0.0):
            raise InputError(f"protocol pause = {pause:g}: must be >= 0 s")
        for s in self.segments:
            if 1.0 / (s.frequency * self.dt) < MIN_SAMPLES_PER_CYCLE:
                raise InputError(f"protocol dt = {self.dt:g} s is too coarse for {s.frequency:.3g} Hz: "
                                 f"at least {MIN_SAMPLES_PER_CYCLE} samples per cycle are needed")
        self.name, self.rest, self.pause = name, float(rest), float(pause)
        starts, t = [], self.rest
        for s in self.segments:
            starts.append(t)
            t += s.duration + self.pause
        self.starts = np.asarray(starts)
        self.duration = t - self.pause + self.rest

    def motion(self, t):
        t = np.asarray(t, dtype=float)
        d, v, a = np.zeros_like(t), np.zeros_like(t), np.zeros_like(t)
        for s, t_s in zip(self.segments, self.starts):
            m = (t >= t_s) & (t <= t_s + s.duration)
            if np.any(m):
                d[m], v[m], a[m] = s.motion(t[m] - t_s)
        return d, v, a

    def breakpoints(self):
        out = []
        for s, t_s in zip(self.segments, self.starts):
            Tt = s.taper / s.frequency
            out += [t_s, t_s + Tt, t_s + s.duration - Tt, t_s + s.duration]
        return np.asarray(out)

    def describe(self):
        return {"name": self.name, "kind": "sine", "dt_s": self.dt, "samples": self.n,
                "duration_s": float(self.duration), "rest_s": self.rest, "pause_s": self.pause,
                "segments": [s.describe() for s in self.segments]}


class HistoryProtocol(Protocol):
    """A user-given displacement history d(t), interpolated by a cubic spline
    (C2: v and a are its first and second derivatives). Sampled on a uniform
    grid with the median step of the given times."""

    def __init__(self, t, d, name: str = "history", where: str = "history"):
        from scipy.interpolate import CubicSpline  # lazily: +60 ms on `fvd-bridge --help`

        t, d = np.asarray(t, dtype=float).ravel(), np.asarray(d, dtype=float).ravel()
        if t.size != d.size:
            raise InputError(f"{where}: t has {t.size} values, d has {d.size}")
        if t.size < 4:
            raise InputError(f"{where}: at least 4 samples are needed, got {t.size}")
        for key, x in (("t", t), ("d", d)):
            bad = np.flatnonzero(~np.isfinite(x))
            if bad.size:
                raise InputError(f"{where}: sample {bad[0]}, column '{key}': value {x[bad[0]]} is not finite")
        steps = np.diff(t)
        bad = np.flatnonzero(steps <= 0)
        if bad.size:
            raise InputError(f"{where}: sample {bad[0] + 1}, column 't': time {t[bad[0] + 1]:g} s does not increase")
        self.name, self.source = name, where
        self.t0, self.dt = float(t[0]), float(np.median(steps))
        self.duration = float(t[-1] - t[0])
        self._spline = CubicSpline(t, d)
        self._given = t.size

    def motion(self, t):
        t = np.clip(np.asarray(t, dtype=float), self.t0, self.t0 + self.duration)
        s = self._spline
        return s(t), s(t, 1), s(t, 2)

    def describe(self):
        return {"name": self.name, "kind": "history", "source": self.source, "dt_s": self.dt,
                "samples": self.n, "duration_s": self.duration,
                "interpolation": "cubic spline (not-a-knot) through the given samples"}


def paper(amplitude: float = PAPER["amplitude"], velocity: float = PAPER["velocity"],
          cycles: float = PAPER["cycles"], dt: float = PAPER["dt"], taper: float = 0.5,
          rest: float = 0.1) -> SineProtocol:
    """The paper's identification test: ``cycles`` cycles of ``amplitude`` [mm]
    at peak velocity ``velocity`` [mm/s] (f = v / (2 pi A), about 2 Hz), dt [s]."""
    amplitude, velocity = positive("protocol amplitude [mm]", amplitude), positive("protocol velocity [mm/s]", velocity)
    seg = SineSegment(amplitude, velocity / (2.0 * math.pi * amplitude), cycles, taper)
    return SineProtocol([seg], dt, name="paper", rest=rest)


def acceptance(levels=ACCEPTANCE_LEVELS, vmax: float = 500.0, amplitude: float = 20.0,
               *, cycles: float = 3, dt: float = 0.002, max_period: float = 2.0, taper: float = 0.5,
               rest: float = 0.1, pause: float = 0.2) -> SineProtocol:
    """Acceptance test: ``cycles`` cycles at each velocity level (fraction of
    ``vmax`` [mm/s]) at a fixed ``amplitude`` [mm], so the frequency changes
    with the level (which separates inertia from stiffness). A level whose
    period would exceed ``max_period`` [s] keeps that period and a smaller
    amplitude (the 1% level: 1.6 mm at 0.5 Hz by default)."""
    vmax, amplitude = positive("protocol vmax [mm/s]", vmax), positive("protocol amplitude [mm]", amplitude)
    max_period = positive("protocol max_period [s]", max_period)
    segs = []
    for lev in levels:
        lev = positive("protocol velocity level", lev)
        vel = lev * vmax
        amp = min(amplitude, vel * max_period / (2.0 * math.pi))
        segs.append(SineSegment(amp, vel / (2.0 * math.pi * amp), cycles, taper))
    return SineProtocol(segs, dt, name="acceptance", rest=rest, pause=pause)


def history(t, d, name: str = "history") -> HistoryProtocol:
    """A displacement history d [mm] at times t [s] (strictly increasing)."""
    return HistoryProtocol(t, d, name=name, where=name)


def read_history(path: str) -> HistoryProtocol:
    """A CSV with a header holding columns t [s] and d [mm] (other columns
    ignored, '#' comment lines skipped): a rig or lab record can be replayed.
    A file without header is read as plain 2-column text t [s], d [mm]
    (blank, comma or semicolon separated)."""
    if not os.path.exists(path):
        raise InputError(f"{path}: no such file")
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    first = next((i for i, r in enumerate(rows) if r and not r[0].lstrip().startswith("#")), None)
    if first is None:
        raise InputError(f"{path}: empty file (expected a header with columns t,d)")
    if starts_with_number(",".join(rows[first])):  # no header: plain 2-column text
        t, d = read_two_column(path)
        base = os.path.splitext(os.path.basename(path))[0]
        return HistoryProtocol(t, d, name=f"history:{base}", where=path)
    header = [h.strip() for h in rows[first]]
    for col in ("t", "d"):
        if col not in header:
            raise InputError(f"{path}: column '{col}' not found; header has: {', '.join(header)}")
    it, idd = header.index("t"), header.index("d")
    t, d = [], []
    for row_no, r in enumerate(rows[first + 1:], start=first + 2):
        if not r or not any(c.strip() for c in r) or r[0].lstrip().startswith("#"):
            continue
        if len(r) != len(header):
            raise InputError(f"{path}: row {row_no} has {len(r)} cells, the header has {len(header)}")
        for col, c, out in (("t", it, t), ("d", idd, d)):
            try:
                out.append(float(r[c]))
            except ValueError:
                raise InputError(f"{path}: row {row_no}, column '{col}': '{r[c].strip()}' is not a number") from None
    base = os.path.splitext(os.path.basename(path))[0]
    return HistoryProtocol(t, d, name=f"history:{base}", where=path)


def from_spec(spec: str, **options) -> Protocol:
    """'paper', 'acceptance' or 'history:FILE.csv' (the CLI's --protocol)."""
    spec = str(spec).strip()
    if spec == "paper":
        return paper(**{k: v for k, v in options.items() if k in ("amplitude", "velocity", "cycles", "dt")})
    if spec == "acceptance":
        opts = {k: v for k, v in options.items() if k in ("amplitude", "cycles", "dt")}
        if "velocity" in options:
            opts["vmax"] = options["velocity"]
        return acceptance(**opts)
    if spec.startswith("history:"):
        return read_history(spec.partition(":")[2])
    raise InputError(f"{option('--protocol', spec)}: expected paper, acceptance or history:FILE.csv")
