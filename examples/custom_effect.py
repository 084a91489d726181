"""A user-defined effect, used with ``--plugin examples/custom_effect.py``.

A plugin file defines ``EFFECTS``, a list of fvd_bridge.effects.Effect.
Each effect names its parameters (unit, bounds from the record's peak force
F [kN], velocity v [mm/s] and displacement d [mm]), the values that switch it
off (inside the bounds, so the model without it is nested in the one with
it), its stage and a vectorized function of the whole population:

  stage 'parallel':  fn(P, t, x, xv, xa) -> force added to the damper's [kN]
  stage 'output':    fn(P, F, x, xv, dt) -> the law's force F transformed [kN]
  stage 'input':     fn(P, d, v, a, dt) -> (x, xv, xa), the motion the law sees

P is (population, parameters); t [s] is (n_t,); x [mm], xv [mm/s], xa
[mm/s^2] are (1 or population, n_t): the pin's motion (d, v, a; a user's
parallel effect stays outside a gap or series spring).  Return
(population, n_t) or broadcastable.

This file adds Stribeck (breakaway) friction: seals stick harder at low
sliding speed than at high speed.  Once loaded it is calibrated, diagnosed
and ranked like the built-in effects:

    fvd-bridge effects --plugin examples/custom_effect.py
    fvd-bridge diagnose RECORD --law 2 --plugin examples/custom_effect.py
    fvd-bridge diagnose RECORD --law 2+stribeck --plugin examples/custom_effect.py
    fvd-bridge calibrate RECORD --laws 2+stribeck --plugin examples/custom_effect.py --out DIR

Run as a script it simulates a damper with Stribeck friction on the virtual
rig and shows that diagnose ranks this effect first.
"""

from __future__ import annotations

import numpy as np

from fvd_bridge.effects import Effect, Parameter

#: Stribeck velocity [mm/s]: the breakaway part fades above it (fixed, not fitted)
V_STRIBECK = 20.0
#: smoothing velocity of the sign [mm/s], as in the built-in friction
V_SMOOTH = 1.0


def stribeck_force(P, t, x, xv, xa):
    """Breakaway friction Fs [kN] on top of any sliding friction:

      + Fs exp(-(xv / v_s)^2) tanh(xv / v_f),  v_s = 20 mm/s, v_f = 1 mm/s,

    xv [mm/s] the damper body's velocity."""
    xv = np.asarray(xv)
    return P[:, 0:1] * np.exp(-(xv / V_STRIBECK) ** 2) * np.tanh(xv / V_SMOOTH)


EFFECTS = [
    Effect(
        name="stribeck",
        stage="parallel",
        parameters=(Parameter("Fs", "kN", (0.0, 30.0), lambda s: (0.0, 0.3 * s["F"]),
                              "breakaway friction at low velocity"),),
        none=(0.0,),
        function=stribeck_force,
        equation=f"+ Fs exp(-(v / {V_STRIBECK:g})^2) tanh(v / {V_SMOOTH:g}), v in mm/s",
        summary="Stribeck friction: seals stick harder at low sliding speed",
        symptom="extra force just after each reversal and in slow cycles, gone at speed",
        cause="the seals break away before they slide",
    ),
]


def main() -> int:
    from fvd_bridge.diagnose import diagnose, diagnose_settings
    from fvd_bridge.text.diagnosis import format_diagnosis
    from fvd_bridge.catalog import catalog
    from fvd_bridge.records import Record
    from fvd_bridge.rig import VirtualDamper, Noise, acceptance, simulate

    cat = catalog([__file__])  # exactly what --plugin does
    rec = simulate(VirtualDamper(C=45.4, alpha=0.3), acceptance(dt=0.005, cycles=2), Noise(1.0), seed=3,
                   name="stribeck_demo")
    extra = stribeck_force(np.array([[15.0]]), rec.t, rec.d[None, :], rec.v[None, :], rec.a[None, :])[0]
    rec = Record(rec.t, rec.d, rec.F + extra, rec.v, rec.a, name=rec.name, provenance=rec.provenance)
    print("a virtual 300 kN damper with 15 kN of Stribeck friction, diagnosed with law 2:\n")
    diag = diagnose(rec, "2", seed=0, settings=diagnose_settings(8, 80), catalog=cat)
    print(format_diagnosis(diag))
    top = diag.candidates[0]
    print(f"\nranked first: {top.effect} (Fs = {top.fit.values[-1]:.3g} kN, planted 15 kN)")
    return 0 if top.effect == "stribeck" else 1


if __name__ == "__main__":
    raise SystemExit(main())
