"""A user-defined series effect, used with ``--plugin examples/bulk_modulus.py``.

A series effect sets the damper's connection (the built-in one: a spring Ks
[kN/mm] and a clearance g [mm] in series with the law, solved with the law
in step form) from parameters of the user's own: here the oil column of a
damper whose geometry the user knows, so that the fit returns the oil's
effective bulk modulus B [MPa] instead of a bare stiffness:

  Ks = B A / L * 1e-3 [kN/mm],  A the piston area [mm^2], L the oil column [mm]

(1 MPa = 1 N/mm^2; B = inf is a rigid column, the model without the effect).
A series effect's function takes the population's parameters P (pop, n_par)
and returns one (pop,) array per slot it names (``slots=("Ks",)``, or
``("g",)``, or both).

    fvd-bridge effects --plugin examples/bulk_modulus.py
    fvd-bridge calibrate RECORD --laws 2+bulk_modulus --plugin examples/bulk_modulus.py --out DIR

Run as a script it calibrates law 2 with this oil column on a virtual damper
with a 112.5 kN/mm oil column (B 1500 MPa) and prints the bulk modulus found.
"""

from __future__ import annotations

import numpy as np

from fvd_bridge.effects import Effect, Parameter

#: the device's geometry: piston area [mm^2] and oil column length [mm]
AREA, LENGTH = 15000.0, 200.0
#: bulk moduli [MPa] from this value up count as a rigid column (the upper bound)
B_RIGID = 1e6


def bulk_modulus(P):
    """(Ks,): the oil column's stiffness B A / L * 1e-3 [kN/mm] for each row's
    bulk modulus B [MPa] (inf: rigid)."""
    return (P[:, 0] * AREA / LENGTH * 1e-3,)


EFFECTS = [
    Effect(
        name="bulk_modulus",
        stage="series",
        slots=("Ks",),
        parameters=(Parameter("B", "MPa", (100.0, B_RIGID), lambda s: (50.0, B_RIGID),
                              "effective bulk modulus of the oil (with entrained air)", log=True),),
        none=(np.inf,),
        off_rule=lambda values: values[:, 0] >= B_RIGID,
        function=bulk_modulus,
        equation=f"Ks = B A / L, A = {AREA:g} mm^2, L = {LENGTH:g} mm",
        summary="oil column: the fluid's compressibility as a spring in series with the orifice",
        symptom="force lags the velocity at reversals (tilted loop)",
        cause="the oil and the air in it compress",
    ),
]


def main() -> int:
    from fvd_bridge import calibrate
    from fvd_bridge.catalog import catalog
    from fvd_bridge.rig import VirtualDamper, Noise, paper, simulate

    rec = simulate(VirtualDamper(C=45.4, alpha=0.3, Ks=112.5), paper(cycles=3), Noise(1.0, 0.005), seed=3, name="oil")
    cal = calibrate(rec, catalog([__file__]).model("2+bulk_modulus"), runs=1, seed=0, plugins=[__file__])
    B = cal.named()["bulk_modulus.B"]
    print(f"law 2 + oil column: OF {cal.of:.4f}, C {cal.named()['C']:.4g}, alpha {cal.named()['alpha']:.3g}, "
          f"bulk modulus {B:.4g} MPa (Ks {B * AREA / LENGTH * 1e-3:.4g} kN/mm; the device's: 1500 MPa, 112.5)")
    return 0 if abs(B / 1500.0 - 1.0) < 0.1 else 1


if __name__ == "__main__":
    raise SystemExit(main())
