"""A co-simulation master for the damper FMU, written with FMPy's low-level
FMI 3 API: a linear SDOF structure under El Centro 1940 NS, the damper
between the ground and the mass, against the same SDOF in OpenSees with the
damper's native material.

The structure: mass m = 500 t, period T = 1 s, 2% viscous damping
(c = 2 zeta m omega), ground motion from ../shared/records (kN, mm, s; mass
in kN s^2/mm).  The master integrates

    m u'' + c u' + k u + F = -m a_g(t)        (u relative to the ground)

with Newmark's average acceleration in steps of h (the record's dt divided
by --substeps; a_g linear between samples, as OpenSees' Path series), the
damper force F(t + h) coming from the FMU of the calibrated damper (here the
golden reference parameters of law 2, C sign(v)|v|^alpha, C 45, alpha 0.3,
and law 7 with beta = 1, a Maxwell model, C 45, alpha 0.3, K 100 kN/mm).
FMU convention: before fmi3DoStep(t, h) the master sets d(t + h) = u(t + h)
and, with use_velocity_input, v(t + h) = u'(t + h): the FMU gets the
velocity of the Newmark solution, as an OpenSees twoNodeLink passes it.

- explicit: the step is solved with the force of the previous point, F(t),
  then the FMU steps once with the resulting u(t + h), u'(t + h): no
  rollback, the force lags one step.
- iterative: the FMU state is saved (fmi3GetFMUState) and the damper force
  F(t + h) that agrees with the Newmark step is found by a bracketed root
  search (Brent): for a trial F the master's step gives u(F), u'(F) (linear
  in F), the FMU, rolled back (fmi3SetFMUState), steps with them and
  returns Phi(F); the root of Phi(F) - F lies between F(t) and Phi(F(t)),
  since Phi falls as F grows (a stronger damper force moves the mass less).

The same SDOF in OpenSees (two twoNodeLinks: Elastic k and the damper's
exported material, mass-proportional Rayleigh damping, UniformExcitation,
Newmark average acceleration, Newton then KrylovNewton, force residual
1e-8 kN) is the reference where the material is exact: law 2 ``Viscous``,
law 7 ``ViscousDamper``.  Printed: peak displacement, peak damper force and
the OF (paper eq. 18) between the OpenSees and the co-simulated damper
force histories, FMU steps per time step and wall times.  Measured on the
whole record (53.7 s, h = 5 ms, 10748 steps, about 12 s in all): iterative
within 3e-8 of OpenSees in peak displacement and 3e-6 in peak force, OF
3.5e-6 (law 2) and 4.8e-6 (law 7), 8.3 and 7.0 FMU steps per time step;
explicit +0.9% (law 2) and +1.0% (law 7) in peak displacement, +0.3% in peak
force, OF 0.043 and 0.028.

Only the SDOF: the 3-story frame needs OpenSees on the structure side, which
is examples/opensees_fmu_cosim.py.

    python examples/fmu_cosim.py [--laws 2,7] [--duration S] [--substeps N] [--out DIR]

Writes the FMUs and summary.json (every figure printed) into DIR.  Needs
../shared/records (exits 0 with a note when it is absent), cmake and a C
compiler (the FMU build).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

RECORD = Path(__file__).resolve().parents[1] / ".." / "shared" / "records" / "elcentro_1940_NS_2688pts_g_dt0.02.dat"
#: the SDOF: mass [kN s^2/mm] (500 t), period [s], damping ratio
MASS, PERIOD, ZETA = 0.5, 1.0, 0.02
#: damper force tolerance of the iterative master [kN]
TOL_F = 1e-6
#: native OpenSees material per law: exact mappings only
NATIVE = {2: "Viscous", 7: "ViscousDamper"}


class Sdof:
    """m u'' + c u' + k u + F = -m a_g by Newmark's average acceleration
    (gamma 1/2, beta 1/4) in steps of h: ``trial(F)`` is the step's end
    state (u, u', u'') for a damper force F(t + h) [kN]; ``accept`` keeps it."""

    def __init__(self, m: float, period: float, zeta: float, h: float):
        self.m, self.h = m, h
        omega = 2 * math.pi / period
        self.k, self.c = m * omega ** 2, 2 * zeta * m * omega
        self.k_eff = self.k + 2 * self.c / h + 4 * m / h ** 2
        self.u = self.v = self.a = 0.0

    def trial(self, F: float, ag: float) -> tuple[float, float, float]:
        m, c, h = self.m, self.c, self.h
        rhs = (-m * ag - F + m * (4 / h ** 2 * self.u + 4 / h * self.v + self.a)
               + c * (2 / h * self.u + self.v))
        u = rhs / self.k_eff
        v = 2 / h * (u - self.u) - self.v
        a = 4 / h ** 2 * (u - self.u) - 4 / h * self.v - self.a
        return u, v, a

    def accept(self, state) -> None:
        self.u, self.v, self.a = state


def cosimulate(fmu_path: str, scheme: str, t: np.ndarray, ag: np.ndarray, h: float) -> dict:
    """The master: the SDOF and one damper FMU instance, low-level FMPy calls."""
    from fmpy import extract, read_model_description
    from fmpy.fmi3 import FMU3Slave
    from scipy.optimize import brentq

    md = read_model_description(fmu_path)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    inputs, force = [vr["d"], vr["v"]], [vr["F"]]
    sdof = Sdof(MASS, PERIOD, ZETA, h)
    u, F = np.zeros(t.size), np.zeros(t.size)
    fmu_steps = 0
    with tempfile.TemporaryDirectory(prefix="fmu_cosim-") as tmp:
        fmu = FMU3Slave(guid=md.guid, unzipDirectory=extract(fmu_path, tmp),
                        modelIdentifier=md.coSimulation.modelIdentifier, instanceName="damper")
        fmu.instantiate()
        # structural parameters (before initialization): d(t + h), v(t + h) set before each step
        fmu.setBoolean([vr["inputs_at_step_end"], vr["use_velocity_input"]], [True, True])
        fmu.enterInitializationMode(startTime=t[0])
        fmu.setFloat64(inputs, [0.0, 0.0])                       # at rest
        fmu.exitInitializationMode()
        wall = time.perf_counter()
        for k in range(t.size - 1):
            if scheme == "explicit":
                state = sdof.trial(F[k], ag[k + 1])              # the force of the previous point
                fmu.setFloat64(inputs, [state[0], state[1]])     # d(t + h), v(t + h)
                fmu.doStep(t[k], h)
                F[k + 1] = fmu.getFloat64(force)[0]
                fmu_steps += 1
            else:
                saved = fmu.getFMUState()

                def phi(F_trial):
                    """The FMU's force when the structure carries F_trial at t + h."""
                    nonlocal fmu_steps
                    u1, v1, _ = sdof.trial(F_trial, ag[k + 1])
                    fmu.setFMUState(saved)
                    fmu.setFloat64(inputs, [u1, v1])
                    fmu.doStep(t[k], h, noSetFMUStatePriorToCurrentPoint=False)
                    fmu_steps += 1
                    return fmu.getFloat64(force)[0]

                a = F[k]
                b = phi(a)                                       # the root lies in [a, phi(a)]
                if abs(b - a) > TOL_F:
                    g_b = phi(b) - b
                    root = b if g_b * (b - a) >= 0.0 else brentq(lambda x: phi(x) - x, a, b, xtol=TOL_F)
                else:
                    root = a
                F[k + 1] = phi(root)                             # leave the FMU stepped at the root
                fmu.freeFMUState(saved)
                state = sdof.trial(root, ag[k + 1])
            sdof.accept(state)
            u[k + 1] = sdof.u
        wall = time.perf_counter() - wall
        fmu.terminate()
        fmu.freeInstance()
    return {"u": u, "F": F, "fmu_steps": fmu_steps / (t.size - 1), "wall_s": wall}


def opensees_sdof(commands, motion, h: float, n_steps: int, tag: int = 1000) -> dict:
    """The same SDOF in OpenSees with the damper's exported material ``tag``."""
    import openseespy.opensees as ops

    omega = 2 * math.pi / PERIOD
    k, c = MASS * omega ** 2, 2 * ZETA * MASS * omega
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 2)
    ops.node(1, 0.0, 0.0)
    ops.node(2, 1000.0, 0.0)
    ops.fix(1, 1, 1)
    ops.fix(2, 0, 1)
    ops.mass(2, MASS, 0.0)
    ops.rayleigh(c / MASS, 0.0, 0.0, 0.0)                        # c u' from the mass
    ops.uniaxialMaterial("Elastic", 1, k)
    for command in commands:
        getattr(ops, command[0])(*command[1:])
    ops.element("twoNodeLink", 1, 1, 2, "-mat", 1, "-dir", 1)
    ops.element("twoNodeLink", 2, 1, 2, "-mat", tag, "-dir", 1)  # passes the deformation rate
    ops.timeSeries("Path", 1, "-dt", motion.dt, "-values", *motion.accel)
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
    ops.constraints("Plain")
    ops.numberer("Plain")
    ops.system("FullGeneral")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.test("NormUnbalance", 1e-8, 50)
    ops.algorithm("Newton")
    ops.analysis("Transient")
    ops.logFile(os.devnull, "-noEcho")  # Newton's failures at velocity reversals, rescued below, stay quiet
    u, F = np.zeros(n_steps + 1), np.zeros(n_steps + 1)
    rescued = 0
    wall = time.perf_counter()
    for i in range(1, n_steps + 1):
        for j, algorithm in enumerate((("Newton",), ("KrylovNewton",), ("NewtonLineSearch", "-type", "Bisection"))):
            ops.test("NormUnbalance", 1e-8, 50)
            ops.algorithm(*algorithm)
            if ops.analyze(1, h) == 0:
                rescued += j > 0
                break
        else:
            ops.wipe()
            raise RuntimeError(f"OpenSees SDOF: step {i} (t = {i * h:.3f} s) did not converge")
        u[i] = ops.nodeDisp(2, 1)
        F[i] = ops.eleResponse(2, "basicForce")[0]
    wall = time.perf_counter() - wall
    ops.wipe()
    return {"u": u, "F": F, "rescued_steps": rescued, "wall_s": wall}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--laws", default="2,7", help="laws with an exact OpenSees material: 2, 7 or 2,7")
    ap.add_argument("--duration", type=float, help="use the first S seconds of the record (default all)")
    ap.add_argument("--substeps", type=int, default=4, help="steps per record sample (default 4: h = 5 ms)")
    ap.add_argument("--out", default="fmu_cosim_out")
    args = ap.parse_args(argv)
    if not RECORD.is_file():
        print(f"fmu_cosim: {RECORD} is absent; nothing to do")
        return 0
    laws = [int(x) for x in args.laws.split(",")]
    if any(law not in NATIVE for law in laws) or args.substeps < 1:
        print(f"fmu_cosim: --laws takes {', '.join(map(str, NATIVE))} and --substeps >= 1", file=sys.stderr)
        return 2

    from fvd_bridge.calibration import Calibration
    from fvd_bridge.export.fmu import build_fmu
    from fvd_bridge.export.opensees import opensees_export
    from fvd_bridge.fit.objective import objective
    from fvd_bridge.records.motions import read_motion
    from fvd_bridge.golden import REFERENCE
    from fvd_bridge.catalog import parse_model

    motion = read_motion(RECORD)
    if args.duration:
        motion = motion.window(args.duration)
    h = motion.dt / args.substeps
    n_steps = int(round(motion.duration / h))
    t = h * np.arange(n_steps + 1)
    ag = np.interp(t, motion.t, motion.accel)
    print(f"{motion.name}: {motion.duration:.1f} s, PGA {motion.pga_g:.3f} g; SDOF m {MASS * 1e3:.0f} t, "
          f"T {PERIOD:.2f} s, zeta {ZETA:.0%}; h = {h:g} s (record dt / {args.substeps}), {n_steps} steps")
    os.makedirs(args.out, exist_ok=True)
    summary = {"record": motion.name, "duration_s": motion.duration, "h_s": h, "steps": n_steps,
               "sdof": {"mass_t": MASS * 1e3, "period_s": PERIOD, "zeta": ZETA}, "laws": {}}
    for law in laws:
        model = parse_model(str(law))
        params = dict(zip(model.names, REFERENCE[law]))
        fmu_path = os.path.join(args.out, f"law{law}.fmu")
        build_fmu(Calibration(model, np.array(REFERENCE[law], dtype=float), of=0.0), fmu_path)
        native = opensees_sdof(opensees_export(model, params, 1000).commands, motion, h, n_steps)
        u_ref, F_ref = np.max(np.abs(native["u"])), np.max(np.abs(native["F"]))
        label = ", ".join(f"{k} {v:g}" for k, v in params.items())
        print(f"\nlaw {law} ({label}): OpenSees {NATIVE[law]} against the FMU")
        print(f"  {'':10} {'peak u [mm]':>18} {'peak F [kN]':>19} {'OF(F)':>9} {'FMU steps/step':>15} {'wall [s]':>9}")
        print(f"  {'OpenSees':10} {u_ref:10.3f} {'':7} {F_ref:10.2f} {'':8} {'':>9} {'':>15} "
              f"{native['wall_s']:9.2f}")
        rows = {"opensees": {"peak_u_mm": float(u_ref), "peak_F_kN": float(F_ref), "wall_s": native["wall_s"],
                             "rescued_steps": native["rescued_steps"]}}
        for scheme in ("explicit", "iterative"):
            run = cosimulate(fmu_path, scheme, t, ag, h)
            pu, pF = np.max(np.abs(run["u"])), np.max(np.abs(run["F"]))
            of = float(objective(native["F"], run["F"], t))
            du, dF = pu / u_ref - 1.0, pF / F_ref - 1.0
            print(f"  {scheme:10} {pu:10.3f} ({du:+.1e}) {pF:10.2f} ({dF:+.1e}) {of:9.2e} "
                  f"{run['fmu_steps']:15.2f} {run['wall_s']:9.2f}")
            rows[scheme] = {"peak_u_mm": float(pu), "peak_F_kN": float(pF), "peak_u_rel": float(du),
                            "peak_F_rel": float(dF), "of": of, "fmu_steps_per_step": run["fmu_steps"],
                            "wall_s": run["wall_s"]}
        summary["laws"][str(law)] = rows
    with open(os.path.join(args.out, "summary.json"), "w") as f:
        json.dump(summary, f, indent=2)
    print(f"\nFMUs and summary.json in {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
