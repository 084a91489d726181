"""A fitted effect in physical terms: its size, whether the record can resolve
it, whether a real device could have it, and what it means for this device.

Plausible ranges (README, "What diagnose suggests"), with F, d, v, a the
record's peak force [kN], stroke [mm], velocity [mm/s] and acceleration
[mm/s^2] (a = v^2 / d for a sinusoid):

==================  ==========================================  ==========================================
effect              size reported                               plausible
==================  ==========================================  ==========================================
gap                 clearance g [mm]                            g <= 0.2 d; detectable only if g > 3 sigma_d
                                                                and the pin's crossing after a reversal lasts
                                                                over two samples: sqrt(2 g / a) > 2 dt
series_stiffness    Ks [kN/mm]; its stroke F / Ks [mm]          F / Ks <= 0.5 d; detectable if F / Ks > 3 sigma_d
asymmetry           r as % of the force                         |r| <= 30 %
thermal_softening   force lost over the record [%]              loss <= 50 %
friction            Ff [kN] and as % of F                       Ff <= 30 % of F
parallel_stiffness  Kp d and F0 as % of F                       |Kp| d <= 50 % of F, |F0| <= 20 % of F
inertia             m [kg]; m a as % of F                       m <= 15 kg per kN of F
==================  ==========================================  ==========================================

A user's (plugin) effect is reported by its parameters and always counts
as plausible.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

#: laws of a fluid device (viscous orifice, Maxwell); the others (6, 8, 9) are
#: hysteretic or friction laws, which fit friction and hysteretic devices too
FLUID_LAWS = (1, 2, 3, 4, 5, 7)
#: moving mass a device can plausibly have [kg per kN of its peak force]
MASS_PER_KN = 15.0


@dataclass(frozen=True)
class Size:
    """One fitted effect in physical terms."""

    text: str  # "gap 1.97 mm (7.9% of the stroke)"
    detectable: bool = True
    plausible: bool = True
    why: str = ""  # why not detectable / not plausible


def _peaks(record) -> tuple[float, float, float, float]:
    s = record.scales()
    F, d, v = s["F"], max(s["d"], 1e-12), s["v"]
    return F, d, v, float(np.percentile(np.abs(record.a), 99))  # robust to a noisy derived a


def effect_size(name: str, values: dict, record, sigma_d: float) -> Size:
    """``values``: the effect's fitted parameters {param: value} (without the
    effect prefix); ``sigma_d`` the record's displacement noise [mm]."""
    F, d, v, a = _peaks(record)
    if name == "gap":
        g = values["g"]
        # the pin crosses g after a reversal in t = sqrt(2 g / a): resolved when t > 2 dt
        resolution = max(3.0 * sigma_d, 2.0 * a * record.dt ** 2)
        text = f"clearance {g:.3g} mm ({g / d:.1%} of the stroke)"
        if g <= resolution:
            return Size(text, detectable=False, why=f"not larger than the record resolves ({resolution:.3g} mm: "
                                                    f"3x the displacement noise, or a crossing of two samples)")
        return Size(text, plausible=g <= 0.2 * d, why="" if g <= 0.2 * d else "more than 20% of the stroke")
    if name == "series_stiffness":
        Ks = values["Ks"]
        stroke = F / Ks
        text = f"series stiffness {Ks:.4g} kN/mm (it stretches {stroke:.3g} mm at the peak force)"
        if stroke <= 3.0 * sigma_d:
            return Size(text, detectable=False, why=f"its stretch is within 3x the displacement noise "
                                                    f"({3.0 * sigma_d:.3g} mm)")
        return Size(text, plausible=stroke <= 0.5 * d, why="" if stroke <= 0.5 * d else "stretches more than half the stroke")
    if name == "asymmetry":
        r = values["r"]
        return Size(f"tension {1 + r:.3g}x, compression {1 - r:.3g}x the law force ({abs(r):.1%} asymmetry)",
                    plausible=abs(r) <= 0.3, why="" if abs(r) <= 0.3 else "more than 30% asymmetry")
    if name == "thermal_softening":
        theta = values["theta"]
        W = _dissipated(record)
        loss = 1.0 - 1.0 / (1.0 + theta * W)
        return Size(f"the force falls {loss:.1%} over the record ({W:.3g} MJ dissipated, theta {theta:.3g}/MJ)",
                    plausible=loss <= 0.5, why="" if loss <= 0.5 else "more than half the force lost")
    if name == "friction":
        Ff = values["Ff"]
        return Size(f"friction {Ff:.3g} kN ({Ff / F:.1%} of the peak force)",
                    plausible=Ff <= 0.3 * F, why="" if Ff <= 0.3 * F else "more than 30% of the peak force")
    if name == "parallel_stiffness":
        Kp, F0 = values["Kp"], values["F0"]
        ok = abs(Kp) * d <= 0.5 * F and abs(F0) <= 0.2 * F
        return Size(f"parallel stiffness {Kp:.3g} kN/mm ({abs(Kp) * d / F:.1%} of the peak force at the peak "
                    f"stroke), preload {F0:.3g} kN ({abs(F0) / F:.1%})", plausible=ok,
                    why="" if ok else "spring or preload too large for the device")
    if name == "inertia":
        m = values["m"]
        limit = MASS_PER_KN * F
        return Size(f"moving mass {m:.4g} kg (inertia force {m * a * 1e-6:.3g} kN = {m * a * 1e-6 / F:.1%} of "
                    f"the peak force)", plausible=m <= limit,
                    why="" if m <= limit else f"heavier than {MASS_PER_KN:g} kg per kN of peak force ({limit:.0f} kg)")
    return Size(", ".join(f"{k} = {x:.4g}" for k, x in values.items()))


def _dissipated(record) -> float:
    """Energy [MJ] the measured force dissipates over the record: 1e-6 integral F v dt."""
    return float(abs(np.trapezoid(record.F * record.v, record.t)) * 1e-6)


#: what an effect means on a device that is not a fluid damper (laws 6, 8, 9)
NON_FLUID_CAUSE = {
    "parallel_stiffness": "the device or its supports carry a static spring (an elastic element beside "
                          "the friction or hysteretic element) and a preload",
    "series_stiffness": "the device's body, connections or supports flex in series with it",
    "thermal_softening": "the dissipated energy heats the sliding surfaces and the friction coefficient falls",
    "asymmetry": "the device is stronger in one direction (clamping or contact conditions differ)",
    "friction": "an extra rubbing contact (seals, guides) adds a nearly constant force",
    "inertia": "accelerated mass of the moving parts",
    "gap": "the connection has play: no force passes while the pin crosses its clearance",
}


def device_kind(law_number: int) -> str:
    """'fluid' for the fluid-damper laws, 'hysteretic' for laws 6, 8, 9."""
    return "fluid" if law_number in FLUID_LAWS else "hysteretic"


def explanation(effect, law_number: int) -> str:
    """'SYMPTOM: CAUSE; add NAME', the cause worded for the device's kind."""
    if device_kind(law_number) != "fluid" and effect.name in NON_FLUID_CAUSE:
        effect = replace(effect, cause=NON_FLUID_CAUSE[effect.name])
    return effect.explanation()


def effect_values(model, params, name: str) -> dict:
    """{param: value} of effect ``name`` in one parameter vector of ``model``."""
    _, by_effect = model.split(np.asarray(params, dtype=float)[None, :])
    effect = next(e for e in model.effects if e.name == name)
    return {p.name: float(x) for p, x in zip(effect.parameters, by_effect[name][0])}
