"""A fitted effect in physical terms: its size, whether the record can resolve
it, whether a real device could have it, and what it means for this device.

Each effect declares its own size rule (``Effect.size``; the built-in ones
with their plausible ranges in ``fvd_bridge/effects/sizes.py``) and its
cause on a friction or hysteretic device (``Effect.cause_hysteretic``); the
law says which kind of device it describes (``Law.device``).  A user's
(plugin) effect without a size rule is reported by its parameters and
always counts as plausible.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..effects.base import Size

__all__ = ["Size", "effect_size", "effect_values", "explanation", "record_scales"]


def record_scales(record, sigma_d: float) -> dict:
    """The record's scales an effect's size rule reads: peak force F [kN],
    stroke d [mm], velocity v [mm/s], robust peak acceleration a [mm/s^2]
    (99th percentile: robust to a noisy derived a), dt [s], the displacement
    noise sigma_d [mm] and the energy W [MJ] the measured force dissipates
    (1e-6 integral F v dt)."""
    s = record.scales()
    return {"F": s["F"], "d": max(s["d"], 1e-12), "v": s["v"], "a": float(np.percentile(np.abs(record.a), 99)),
            "dt": record.dt, "sigma_d": sigma_d,
            "W": float(abs(np.trapezoid(record.F * record.v, record.t)) * 1e-6)}


def effect_size(effect, values: dict, record, sigma_d: float) -> Size:
    """``values``: the effect's fitted parameters {param: value} (without the
    effect prefix); ``sigma_d`` the record's displacement noise [mm]."""
    if effect.size is None:
        return Size(", ".join(f"{k} = {x:.4g}" for k, x in values.items()))
    return effect.size(values, record_scales(record, sigma_d))


def explanation(effect, law) -> str:
    """'SYMPTOM: CAUSE; add NAME', the cause worded for the kind of device
    the law describes."""
    if law.device != "fluid" and effect.cause_hysteretic:
        effect = replace(effect, cause=effect.cause_hysteretic)
    return effect.explanation()


def effect_values(model, params, name: str) -> dict:
    """{param: value} of effect ``name`` in one parameter vector of ``model``."""
    _, by_effect = model.split(np.asarray(params, dtype=float)[None, :])
    effect = next(e for e in model.effects if e.name == name)
    return {p.name: float(x) for p, x in zip(effect.parameters, by_effect[name][0])}
