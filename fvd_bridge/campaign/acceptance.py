"""Acceptance of a production series: each device's calibrated force at the
design velocity against the nominal force +- a tolerance.

The test motion is the paper's sinusoid reaching the design velocity V
[mm/s]: amplitude A [mm] (default: the median peak displacement of the
series' records), frequency V / (2 pi A), ``cycles`` full cycles between
half-cycle fades, sampled at the records' median dt [s].  The force at the
design velocity is the model's force (calibrated parameters: each device's
best run) at the last sample of peak velocity, in tension (v = +V) and in
compression (v = -V) [kN].  A device passes when both are within
``tolerance`` of the nominal force: |F - F_nominal| <= tolerance F_nominal
(``RULE``, after ``SOURCE``; the tolerance is a setting).

The nominal force is the campaign file's ``nominal_force``; without it, a
``Rating`` the caller gives (a rig series': its nominal damper's orifice C
and alpha), whose force at the design velocity is the rating law's (law 2,
F = C sign(v)|v|^alpha: C V^alpha) on the same sinusoid as the devices'.
The rig's own simulation is the tests' truth and feeds no result here: a
virtual damper's friction, heating or spring are what it is, not what it
is rated.

The rule is written for the force at a stated design velocity: without a
nominal force it is not applicable (``evaluate`` says why), and where the
design velocity lies beyond the velocities the records reached, the models
extrapolate to it and the result says so (``note``).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ..catalog import parse_model
from ..errors import InputError
from ..records import Record
from ..rig.protocols import MIN_SAMPLES_PER_CYCLE, paper

KEYS = ("velocity", "nominal_force", "tolerance", "amplitude", "cycles")
#: the rule every device of the series is held to
RULE = "force at the design velocity within the tolerance of the nominal force, in tension and in compression"
#: where the rule comes from
SOURCE = "EN 15129:2018 7.3 (production tests of fluid viscous dampers)"
#: a design velocity more than this share above the records' peak velocity is an extrapolation
TESTED_MARGIN = 0.05
#: the law a damper is rated by: its orifice, F = C sign(v)|v|^alpha
RATING_LAW = "2"


def section(data, name: str, keys, where: str) -> dict:
    """A campaign file's ``name`` block, checked to be a mapping of known
    ``keys`` (one line naming the file ``where`` and the key otherwise)."""
    if not isinstance(data, dict):
        raise InputError(f"{where}: key '{name}': expected a mapping ({', '.join(keys)})")
    unknown = [k for k in data if k not in keys]
    if unknown:
        raise InputError(f"{where}: unknown key '{name}.{unknown[0]}' (known: {', '.join(keys)})")
    return data


@dataclass(frozen=True)
class Acceptance:
    """Design velocity [mm/s], nominal force [kN] (None: from the ``Rating`` the
    caller gives ``evaluate``, if any), relative tolerance, test amplitude [mm]
    (None: from the records), full-amplitude cycles."""

    velocity: float = 500.0
    nominal_force: float | None = None
    tolerance: float = 0.15
    amplitude: float | None = None
    cycles: float = 3.0

    @classmethod
    def from_dict(cls, data, where: str) -> "Acceptance":
        if data is None:
            return cls()
        values = {}
        for key, value in section(data, "acceptance", KEYS, where).items():
            if value is None:
                continue
            try:
                x = float(value)
            except (TypeError, ValueError):
                raise InputError(f"{where}: key 'acceptance.{key}': '{value}' is not a number") from None
            if not (np.isfinite(x) and x > 0) or (key == "tolerance" and x >= 1):
                raise InputError(f"{where}: key 'acceptance.{key}': {value} must be > 0"
                                 f"{' and < 1' if key == 'tolerance' else ''}")
            values[key] = x
        return cls(**values)

    def as_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class Rating:
    """A damper's rating: its orifice's ``C`` [kN/(mm/s)^alpha] and ``alpha`` [-]
    (``RATING_LAW``) and where they come from (``source``, e.g. 'rig nominal device')."""

    C: float
    alpha: float
    source: str

    def force(self, motion: Record) -> float:
        """The rated force [kN] at the design velocity of ``motion`` (``design_motion``):
        the rating law's force there, C V^alpha, taken as a device's is (``forces_at_velocity``,
        the mean of tension and compression)."""
        model = parse_model(RATING_LAW)
        given = {"C": self.C, "alpha": self.alpha}
        F = model.force(motion, np.array([[given[name] for name in model.names]]))
        return float(forces_at_velocity(F, motion.v).mean())

    def text(self) -> str:
        """'rig nominal device: C V^alpha, law 2 with C 45.4, alpha 0.3': where the nominal force comes from."""
        return f"{self.source}: C V^alpha, law {RATING_LAW} with C {self.C:g}, alpha {self.alpha:g}"


def design_motion(acc: Acceptance, amplitude: float, dt: float):
    """The acceptance sinusoid as a noise-free Record (F = 0): t [s], d [mm], v [mm/s], a."""
    proto = paper(amplitude=amplitude, velocity=acc.velocity, cycles=acc.cycles, dt=dt)
    t = proto.times()
    d, v, a = proto.motion(t)
    return Record(t, d, np.zeros_like(t), v, a, name=f"acceptance_{acc.velocity:g}mm_s")


def series_motion(acc: Acceptance, records) -> tuple[float, float, Record]:
    """(amplitude [mm], dt [s], the design motion) of a series' records: the
    given amplitude or their median peak displacement, their median dt, finer
    where the design sine needs it (twice MIN_SAMPLES_PER_CYCLE a cycle: a
    design velocity far above the tests' asks a faster sine than their dt holds)."""
    amplitude = acc.amplitude or float(np.median([r.scales()["d"] for r in records]))
    frequency = acc.velocity / (2.0 * np.pi * amplitude)
    dt = min(float(np.median([r.dt for r in records])), 1.0 / (2 * MIN_SAMPLES_PER_CYCLE * frequency))
    return amplitude, dt, design_motion(acc, amplitude, dt)


def forces_at_velocity(F: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(..., 2): force at the last sample of peak velocity, tension (v max) and
    compression (v min, as a magnitude) [kN]; F (..., n_t)."""
    i_t, i_c = _last_peak(v), _last_peak(-v)
    return np.stack([F[..., i_t], -F[..., i_c]], axis=-1)


def _last_peak(v: np.ndarray) -> int:
    """Index of the last local maximum of v within 0.1% of its global maximum."""
    i = int(np.flatnonzero(v >= (1 - 1e-3) * v.max())[-1])
    while i > 0 and v[i - 1] > v[i]:
        i -= 1
    return i


def evaluate(summary: dict, records, cs, acc: Acceptance, *, rating: Rating | None = None) -> dict:
    """Per model: each device's force at the design velocity and its verdict,
    against ``acc.nominal_force``, else the force of ``rating`` (module doc).

    Returns {"settings", "rule", "source", "applies", "why_not", "note",
    "nominal_force", "nominal_source", "amplitude", "dt",
    "models": {spec: {"F": (n_dev, 2) [kN], "deviation": (n_dev,), "passed": (n_dev,) bool}}}
    ("applies" False, "why_not" the reason and no models without a nominal force).
    """
    amplitude, dt, motion = series_motion(acc, records)
    tested = max(r.scales()["v"] for r in records)  # a record or a device: its peak velocity [mm/s]
    said = {"settings": acc.as_dict(), "rule": RULE, "source": SOURCE, "applies": True, "why_not": "",
            "note": (f"the design velocity {acc.velocity:g} mm/s lies beyond the records' peak velocity "
                     f"{tested:.4g} mm/s: the models extrapolate to it" if acc.velocity > (1 + TESTED_MARGIN) * tested
                     else ""),
            "amplitude": amplitude, "dt": dt}
    if acc.nominal_force is not None:
        nominal, source = acc.nominal_force, "campaign file"
    elif rating is not None:
        nominal, source = rating.force(motion), rating.text()
    else:
        return {**said, "applies": False, "nominal_force": None, "nominal_source": None, "models": {},
                "why_not": "no nominal force: give acceptance.nominal_force in the campaign file (or a rig "
                           "nominal device)"}
    out = {**said, "nominal_force": nominal, "nominal_source": source, "models": {}}
    devices = summary["devices"]
    for spec, m in summary["models"].items():
        per_test = cs.per_test_for(spec)
        if per_test:  # a test's force is not the device's (as the bounds: campaign.property_bounds)
            out.setdefault("skipped", {})[spec] = (
                f"{', '.join(per_test)} fitted per test: the force at the design velocity is each test's, not the "
                f"device's, so law {spec} is not checked against the nominal")
            continue
        P = np.array([m["best"][dev].values for dev in devices])
        F = forces_at_velocity(cs.model(spec).force(motion, P), motion.v)
        deviation = np.max(np.abs(F / nominal - 1.0), axis=1)
        out["models"][spec] = {"F": F, "deviation": deviation, "passed": deviation <= acc.tolerance}
    return out
