"""The built-in effects' physical sizes (each effect's ``size``): what a
fitted value means for the device, whether the record can resolve it and
whether a real device could have it.

``values``: the effect's fitted parameters {param: value}; ``scales``: the
record's peak force F [kN], stroke d [mm], velocity v [mm/s], robust peak
acceleration a [mm/s^2], sample step dt [s], displacement noise sigma_d
[mm] and the energy W [MJ] its measured force dissipates.  Plausible ranges:
README, "What diagnose suggests".
"""

from __future__ import annotations

from .base import Size

#: moving mass a device can plausibly have [kg per kN of its peak force]
MASS_PER_KN = 15.0


def gap(values, s) -> Size:
    """Clearance g [mm]: plausible up to 0.2 d; detectable above 3 sigma_d
    when the pin's crossing after a reversal, sqrt(2 g / a), lasts over two
    samples."""
    g, d = values["g"], s["d"]
    resolution = max(3.0 * s["sigma_d"], 2.0 * s["a"] * s["dt"] ** 2)
    text = f"clearance {g:.3g} mm ({g / d:.1%} of the stroke)"
    if g <= resolution:
        return Size(text, detectable=False, why=f"not larger than the record resolves ({resolution:.3g} mm: "
                                                f"3x the displacement noise, or a crossing of two samples)")
    return Size(text, plausible=g <= 0.2 * d, why="" if g <= 0.2 * d else "more than 20% of the stroke")


def series_spring(values, s) -> Size:
    """Ks [kN/mm] and its stretch F / Ks [mm]: plausible up to 0.5 d,
    detectable above 3 sigma_d."""
    Ks = values["Ks"]
    stroke = s["F"] / Ks
    text = f"series stiffness {Ks:.4g} kN/mm (it stretches {stroke:.3g} mm at the peak force)"
    if stroke <= 3.0 * s["sigma_d"]:
        return Size(text, detectable=False, why=f"its stretch is within 3x the displacement noise "
                                                f"({3.0 * s['sigma_d']:.3g} mm)")
    ok = stroke <= 0.5 * s["d"]
    return Size(text, plausible=ok, why="" if ok else "stretches more than half the stroke")


def asymmetry(values, s) -> Size:
    """r as a share of the force: plausible up to 30%."""
    r = values["r"]
    return Size(f"tension {1 + r:.3g}x, compression {1 - r:.3g}x the law force ({abs(r):.1%} asymmetry)",
                plausible=abs(r) <= 0.3, why="" if abs(r) <= 0.3 else "more than 30% asymmetry")


def heating(values, s) -> Size:
    """Force lost over the record, 1 - 1/(1 + theta W): plausible up to 50%."""
    theta, W = values["theta"], s["W"]
    loss = 1.0 - 1.0 / (1.0 + theta * W)
    return Size(f"the force falls {loss:.1%} over the record ({W:.3g} MJ dissipated, theta {theta:.3g}/MJ)",
                plausible=loss <= 0.5, why="" if loss <= 0.5 else "more than half the force lost")


def friction(values, s) -> Size:
    """Ff [kN] and as a share of F: plausible up to 30%."""
    Ff, F = values["Ff"], s["F"]
    return Size(f"friction {Ff:.3g} kN ({Ff / F:.1%} of the peak force)",
                plausible=Ff <= 0.3 * F, why="" if Ff <= 0.3 * F else "more than 30% of the peak force")


#: a negative parallel stiffness whose force at the peak stroke stays within this share
#: of the peak force is a stiffness the fit left at about zero, not a negative spring
NEGATIVE_KP_SHARE = 0.01


def parallel_spring(values, s) -> Size:
    """Kp d and F0 as shares of F: plausible up to 50% and 20%.  A negative
    Kp (beyond NEGATIVE_KP_SHARE of F at the peak stroke) is no damper's
    property: a gas spring or accumulator pushes back as the rod goes in
    (Kp > 0), and a force falling with d under one frequency is inertia's
    -m w^2 d (PHYSICS.md, "Accumulator / gas spring" and "Inertia"); a
    device built with a negative stiffness is fitted by naming the effect
    (``--law 2+parallel_stiffness``), which no plausibility rule stops."""
    Kp, F0, F, d = values["Kp"], values["F0"], s["F"], s["d"]
    text = (f"parallel stiffness {Kp:.3g} kN/mm ({abs(Kp) * d / F:.1%} of the peak force at the peak "
            f"stroke), preload {F0:.3g} kN ({abs(F0) / F:.1%})")
    if Kp * d < -NEGATIVE_KP_SHARE * F:
        return Size(text, plausible=False, why="a negative parallel stiffness (a gas spring pushes back, Kp > 0; "
                                               "a force falling with d is inertia's -m w^2 d)")
    ok = abs(Kp) * d <= 0.5 * F and abs(F0) <= 0.2 * F
    return Size(text, plausible=ok, why="" if ok else "spring or preload too large for the device")


def inertia(values, s) -> Size:
    """m [kg] and m a as a share of F: plausible up to MASS_PER_KN kg per kN."""
    m, F = values["m"], s["F"]
    force = m * s["a"] * 1e-6
    limit = MASS_PER_KN * F
    return Size(f"moving mass {m:.4g} kg (inertia force {force:.3g} kN = {force / F:.1%} of "
                f"the peak force)", plausible=m <= limit,
                why="" if m <= limit else f"heavier than {MASS_PER_KN:g} kg per kN of peak force ({limit:.0f} kg)")
