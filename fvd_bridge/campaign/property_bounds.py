"""Upper- and lower-bound damper properties of a production series: each
model's property modification factors lambda_max and lambda_min.

The rule (ASCE 7-16 sec. 18.2.4.5, maximum and minimum damper properties;
the form of the isolators' sec. 17.2.8.4, which ASCE 41-17 ch. 15 takes
over, C15.1): a property P (the force at the design velocity, a law's
parameter) is bounded by

    P_max = lambda_max P_nominal,   P_min = lambda_min P_nominal
    lambda_max = (1 + 0.75 (lambda_ae,max - 1)) lambda_test,max lambda_spec,max
    lambda_min = (1 - 0.75 (1 - lambda_ae,min)) lambda_test,min lambda_spec,min

with, here:

- P_nominal: the mean over the series' devices (each device's calibrated
  value, its best run; the force at the design velocity as the acceptance
  computes it: ``acceptance.forces_at_velocity`` on the acceptance
  sinusoid, the mean of tension and compression);
- lambda_test (what the tests measured): the series' scatter,
  ``statistic`` "extremes" (default): the largest and smallest device over
  the nominal, as property modification factors are taken from a range of
  tests (McVitty & Constantinou 2015, MCEER-15-0005, sec. 3); or "sigma":
  1 +- k s / P_nominal, s the sample standard deviation over the devices
  (n - 1), k a setting (default 2);
- lambda_spec = 1 +- ``spec``, the specification's permitted manufacturing
  variation (a setting, default 0.15: the +-15% of the acceptance rule,
  EN 15129:2018 7.3, and the default variation the ASCE 7-16 commentary
  names);
- lambda_ae: aging and environment (not measured by the tests; settings
  ``aging_max``, ``aging_min``, default 1), its effect counted at 75% (the
  0.75 of the rule: not every effect peaks at once).

The measured scatter already holds part of the manufacturing variation,
so counting lambda_test and lambda_spec both is on the safe side.  A
parameter whose mean over the devices is near zero (``stats.near_zero``)
or not positive has no factor (NaN, with the note why); with one device
lambda_test = 1 (no scatter to measure).  A model with a parameter fitted
per test has no bounds (its force at the design velocity is a test's, not
the device's): bounds.json's ``skipped`` says so.  The frame (``frame --property-bounds``)
scales the damper's whole force by the force's factors (OpenSees'
``Multiplier``); the parameters' factors are for the record: bounding
each parameter alone does not bound the force (a larger exponent alpha
lowers the force below 1 mm/s).

Files (in the campaign's output): bounds.csv (model, quantity, unit,
nominal, lambda_test_min/max, lambda_min/max, lower, upper, note) and
bounds.json (settings, rule, source, the design motion, per model its
nominal device and rows, the models without bounds and why; what
``frame --property-bounds`` reads).  ``campaign`` and ``calibrate`` both write
them, with ``compute`` and ``write``, and print them with ``text.property_bounds``.
"""

from __future__ import annotations

import os
from dataclasses import asdict, dataclass

import numpy as np

from ..errors import InputError
from ..io.staging import plain, write_csv_rows, write_json
from ..report.numbers import rounded
from .acceptance import Acceptance, forces_at_velocity, section, series_motion

#: bounds.json's schema
SCHEMA_VERSION = 1
KEYS = ("spec", "statistic", "k", "aging_max", "aging_min")
STATISTICS = ("extremes", "sigma")
RULE = ("lambda_max = (1 + 0.75 (lambda_ae,max - 1)) lambda_test,max lambda_spec,max, "
        "lambda_min = (1 - 0.75 (1 - lambda_ae,min)) lambda_test,min lambda_spec,min; P = lambda P_nominal")
SOURCE = "ASCE 7-16 sec. 18.2.4.5 (maximum and minimum damper properties); ASCE 41-17 ch. 15"
#: the quantity name of the force at the design velocity
FORCE = "F(V)"


@dataclass(frozen=True)
class BoundSettings:
    """spec: permitted manufacturing variation (lambda_spec = 1 +- spec);
    statistic: 'extremes' or 'sigma' (k sample standard deviations);
    aging_max, aging_min: lambda_ae (module doc)."""

    spec: float = 0.15
    statistic: str = "extremes"
    k: float = 2.0
    aging_max: float = 1.0
    aging_min: float = 1.0

    @classmethod
    def from_dict(cls, data, where: str) -> "BoundSettings":
        if data is None:
            return cls()
        values = {}
        for key, value in section(data, "bounds", KEYS, where).items():
            if key == "statistic":
                if value not in STATISTICS:
                    raise InputError(f"{where}: key 'bounds.statistic': '{value}' (expected {' or '.join(STATISTICS)})")
                values[key] = value
                continue
            try:
                x = float(value)
            except (TypeError, ValueError):
                raise InputError(f"{where}: key 'bounds.{key}': '{value}' is not a number") from None
            ok = {"spec": 0 <= x < 1, "k": x > 0, "aging_max": x >= 1, "aging_min": 0 < x <= 1}[key]
            if not (np.isfinite(x) and ok):
                allowed = {"spec": ">= 0 and < 1", "k": "> 0", "aging_max": ">= 1", "aging_min": "> 0 and <= 1"}[key]
                raise InputError(f"{where}: key 'bounds.{key}': {value} must be {allowed}")
            values[key] = x
        return cls(**values)

    def as_dict(self) -> dict:
        return asdict(self)


def scatter_factors(x, settings: BoundSettings) -> tuple[float, float, str]:
    """(lambda_test,min, lambda_test,max, note) of one quantity's values over
    the devices ``x`` about their mean (module doc); NaN and the reason where
    the mean is not positive."""
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    if not x.size:
        return np.nan, np.nan, "no finite value"
    mean = float(x.mean())
    if not mean > 0:
        return np.nan, np.nan, f"mean over devices {rounded(mean)} is not positive: no factor"
    if x.size < 2:
        return 1.0, 1.0, "one device: no scatter measured (lambda_test = 1)"
    if settings.statistic == "extremes":
        return float(x.min()) / mean, float(x.max()) / mean, ""
    s = float(np.std(x, ddof=1))
    low = 1.0 - settings.k * s / mean
    if not low > 0:
        return np.nan, 1.0 + settings.k * s / mean, f"mean - {settings.k:g} sigma is not positive: no lower factor"
    return low, 1.0 + settings.k * s / mean, ""


def combined(test_min: float, test_max: float, settings: BoundSettings) -> tuple[float, float]:
    """(lambda_min, lambda_max): the rule of the module doc."""
    lam_max = (1.0 + 0.75 * (settings.aging_max - 1.0)) * test_max * (1.0 + settings.spec)
    lam_min = (1.0 - 0.75 * (1.0 - settings.aging_min)) * test_min * (1.0 - settings.spec)
    return lam_min, lam_max


def design_forces(model, params: np.ndarray, motion) -> np.ndarray:
    """(n_dev,) force at the design velocity [kN] of each parameter row of
    ``params`` (n_dev, n_par): the mean of tension and compression."""
    return forces_at_velocity(model.force(motion, np.atleast_2d(params)), motion.v).mean(axis=-1)


def _row(quantity: str, unit: str, values, settings: BoundSettings, note: str = "") -> dict:
    x = np.asarray(values, dtype=float)
    t_min, t_max, why = scatter_factors(x, settings) if not note else (np.nan, np.nan, note)
    l_min, l_max = combined(t_min, t_max, settings)
    nominal = float(np.mean(x)) if x.size else np.nan
    return {"quantity": quantity, "unit": unit, "nominal": nominal, "test_min": t_min, "test_max": t_max,
            "lambda_min": l_min, "lambda_max": l_max, "lower": l_min * nominal, "upper": l_max * nominal,
            "devices_min": float(np.min(x)), "devices_max": float(np.max(x)), "note": why}


def compute(summary: dict, records, cs, acc: Acceptance, settings: BoundSettings) -> dict:
    """The bounds of every model of the campaign (module doc).

    ``summary``: campaign.outputs.summarize's; ``acc``: the acceptance
    settings (design velocity, cycles), whose test motion the acceptance
    uses too (``acceptance.series_motion``)."""
    amplitude, dt, motion = series_motion(acc, records)
    devices = summary["devices"]
    out = {"schema_version": SCHEMA_VERSION, "settings": settings.as_dict(), "rule": RULE, "source": SOURCE,
           "statistic": _statistic_text(settings), "velocity": acc.velocity, "amplitude": amplitude, "dt": dt,
           "cycles": acc.cycles, "devices": list(devices), "models": {}}
    for spec, m in summary["models"].items():
        per_test = cs.per_test_for(spec)
        if per_test:  # a test's force is not the device's
            out.setdefault("skipped", {})[spec] = (
                f"{', '.join(per_test)} fitted per test: the force at the design velocity is each test's, not the "
                f"device's, so law {spec} has no bounds")
            continue
        model = cs.model(spec)
        P = np.array([m["best"][dev].values for dev in devices], dtype=float)
        F = design_forces(model, P, motion)
        rows = [_row(FORCE, "kN", F, settings)]
        near = m.get("near_zero")
        for j, (name, unit) in enumerate(zip(m["names"], m["units"])):
            note = "mean over devices near zero (no relative scatter)" if near is not None and near[j] else ""
            rows.append(_row(name, unit, P[:, j], settings, note))
        nominal_device = devices[int(np.argmin(np.abs(F - F.mean())))]
        out["models"][spec] = {"nominal_device": nominal_device, "rows": rows}
    return out


def _statistic_text(settings: BoundSettings) -> str:
    if settings.statistic == "extremes":
        return "lambda_test: the largest and smallest device over the series' mean"
    return f"lambda_test: 1 -+ {settings.k:g} sample standard deviations over the series' mean"


def write(stage: str, bounds: dict) -> None:
    """bounds.csv and bounds.json into ``stage`` (module doc)."""
    rows = [[spec, r["quantity"], r["unit"], r["nominal"], r["test_min"], r["test_max"], r["lambda_min"],
             r["lambda_max"], r["lower"], r["upper"], r["note"]]
            for spec, m in bounds["models"].items() for r in m["rows"]]
    write_csv_rows(os.path.join(stage, "bounds.csv"),
                   ["model", "quantity", "unit", "nominal", "lambda_test_min", "lambda_test_max", "lambda_min",
                    "lambda_max", "lower", "upper", "note"], rows)
    write_json(os.path.join(stage, "bounds.json"), plain(bounds, finite=True))

