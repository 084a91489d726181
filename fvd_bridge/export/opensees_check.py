"""Driving exported OpenSees materials and checking them against the model.

Each driver starts a fresh OpenSees model (``ops.wipe()``: it clears any
model of this process) in 1-D, defines the commands and imposes the
displacement history d [mm] (and velocity v [mm/s]) on the damper material.
"""

from __future__ import annotations

import os

from dataclasses import dataclass

import numpy as np

from ..fit.objective import objective
from ..catalog import parse_model
from ..model import Model
from ..records.record import Record
from ..units import factor
from .opensees import apply, listed, opensees_export

def _ops():
    import openseespy.opensees as ops  # lazily: OpenSees loads a native library on import

    return ops


def quiet_opensees(log: str | None = None) -> None:
    """Send OpenSees' console output (banners, per-step convergence warnings)
    to the file ``log`` (default nowhere) for the rest of this process: the
    analyses report their own solver trouble (FrameResult.solver, the export
    check's OF)."""
    _ops().logFile(log or os.devnull, "-noEcho")


def _fresh(ops, commands) -> None:
    ops.wipe()
    ops.model("basic", "-ndm", 1, "-ndf", 1)
    apply(commands, ops)


def _set_global_step(ops, dt: float) -> None:
    """One transient step of dt [s] on a free unloaded mass: OpenSees keeps
    dt as its global step (ops_Dt), which ViscousDamper integrates over."""
    ops.node(999999, 0.0)
    ops.mass(999999, 1.0)
    ops.constraints("Plain")
    ops.numberer("Plain")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", 1e-12, 10)
    ops.algorithm("Linear")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    ops.analyze(1, float(dt))


def drive_material(commands, tag: int, t, d, v) -> np.ndarray:
    """Force [kN] of material ``tag`` for the strain d [mm] and rate v [mm/s]
    at times t [s] (uniform step): testUniaxialMaterial + setStrain(d, v),
    each step committed.  The global step is set to t[1] - t[0] first
    (``_set_global_step``): materials such as ViscousDamper and
    BilinearOilDamper integrate over it (ops_Dt), the others ignore it."""
    ops, commands = _ops(), listed(commands)
    _fresh(ops, commands)
    _set_global_step(ops, t[1] - t[0])
    ops.testUniaxialMaterial(int(tag))
    F = np.empty(len(d))
    for i, (di, vi) in enumerate(zip(d, v)):
        ops.setStrain(float(di), float(vi))
        F[i] = ops.getStress()
    ops.wipe()
    return F


def drive_element(commands, tag: int, t, d, integrator: tuple = ("Newmark", 0.5, 0.25),
                  connection: int = 0) -> np.ndarray:
    """Force [kN] of a zeroLength element of material ``tag`` whose free end
    follows d [mm] at times t [s] (uniform step) in a transient analysis
    (Penalty constraints): the damper as it runs in a structure, its velocity
    from the integrator (average acceleration by default; ("TRBDF2",) measured
    the same for ViscousDamper and 20% worse for Viscous).  ``connection``:
    a damper of two materials in series (``Export.connection``): the law
    (``tag``) from the fixed node to an internal node without mass, the
    connection (tag + connection) from there to the driven end."""
    ops, commands = _ops(), listed(commands)
    _fresh(ops, commands)
    dt = float(t[1] - t[0])
    ops.node(1, 0.0)
    ops.node(2, 0.0)
    ops.fix(1, 1)
    if connection:
        ops.node(3, 0.0)
        ops.element("zeroLength", 2, 1, 3, "-mat", int(tag), "-dir", 1)
        ops.element("zeroLength", 1, 3, 2, "-mat", int(tag) + int(connection), "-dir", 1)
    else:
        ops.element("zeroLength", 1, 1, 2, "-mat", int(tag), "-dir", 1)
    ops.timeSeries("Path", 1, "-dt", dt, "-values", *map(float, d))
    ops.pattern("Plain", 1, 1)
    ops.sp(2, 1, 1.0)
    ops.constraints("Penalty", 1e12, 1e12)
    ops.numberer("Plain")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", 1e-10, 20)
    ops.algorithm("Newton")
    ops.integrator(*integrator)
    ops.analysis("Transient")
    F = np.empty(len(d))
    F[0] = ops.eleForce(1, 2)
    for i in range(1, len(d)):
        if ops.analyze(1, dt) != 0:
            raise RuntimeError(f"OpenSees analysis failed at t = {t[i]:g} s")
        F[i] = ops.eleForce(1, 2)
    ops.wipe()
    return F


@dataclass(frozen=True)
class CheckResult:
    """OpenSees force against the model on one history: ``of`` (eq. 18, the
    model force as reference), the export's ``bound`` on this history
    (``Export.bound``) and ``exact`` flag, both forces [kN]."""

    of: float
    bound: float
    exact: bool
    F_opensees: np.ndarray
    F_model: np.ndarray

    @property
    def ok(self) -> bool:
        return self.of <= self.bound


def check(model, params: dict, t, d, v=None, a=None, *, element: bool = False, substeps: int = 1,
          export=None) -> CheckResult:
    """Export ``model`` with ``params`` ({name: value}) (or take ``export``, its Export), drive it with d [mm]
    at times t [s] (uniform; v [mm/s], a [mm/s^2]: np.gradient when not
    given), and compare with ``model.force`` (``substeps`` per sample) on the
    same history; ``element``: through a zeroLength element (``drive_element``; a damper
    of two materials in series always is, through an internal node)."""
    model = model if isinstance(model, Model) else parse_model(model)
    t, d = np.asarray(t, dtype=float), np.asarray(d, dtype=float)
    v = np.gradient(d, t) if v is None else np.asarray(v, dtype=float)
    a = np.gradient(v, t) if a is None else np.asarray(a, dtype=float)
    record = Record(t, d, np.zeros_like(t), v, a, name="check")
    F_model = model.force(record, np.array([[params[n] for n in model.names]]), substeps)[0]
    tested = {"d": float(np.max(np.abs(d))), "F": float(np.max(np.abs(F_model)))}  # this history as the tested one
    export = export or opensees_export(model, params, tag=1, tested=tested)
    # in the export's own units (kN, mm, s unless it was written in others), its force back in kN
    kt, kd = factor("t", export.units["t"]), factor("d", export.units["d"])
    if export.connection:  # two materials in series: in elements, TRBDF2 (average acceleration rings at contact)
        F_ops = drive_element(export, export.tag, t / kt, d / kd, ("TRBDF2",), export.connection)
    elif element:
        F_ops = drive_element(export, export.tag, t / kt, d / kd)
    else:
        F_ops = drive_material(export, export.tag, t / kt, d / kd, v * kt / kd)
    F_ops = export.to_kN(F_ops)
    return CheckResult(float(objective(F_model, F_ops, t)), export.bound(d, F_model), export.exact,
                       F_ops, F_model)


def check_on_record(cal, record, export=None, test: str | None = None) -> CheckResult:
    """A calibration's OpenSees export (``export``; default: kN, mm, s, tag 1)
    against its model on a record's motion, with the parameters of ``test``
    (per-test parameters; None: the shared ones).

    Both are driven by one consistent motion: the displacement integrated
    from the record's velocity (trapezoidal rule, from 0 where OpenSees
    materials start), so that displacement noise, which the derived velocity
    has smoothed away, reaches neither."""
    params = cal.named(test)
    export = export or opensees_export(cal.model, params, tag=1, tested=cal.tested)
    t, v = record.t, record.v
    d = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))])
    return check(cal.model, params, t, d, v, record.a, export=export)
