"""The damper FMU in a co-simulation: one instance driven through FMPy's
low-level FMI 3.0 API, the master's end-of-step convention
(``inputs_at_step_end``) and its state saved and restored for a rollback
(``cosim``)."""

from __future__ import annotations

import tempfile

from fmpy import extract, read_model_description
from fmpy.fmi3 import FMU3Slave, fmi3LogMessageCallback


class DamperFMU:
    """One instance of the damper FMU, driven with FMPy's low-level FMI 3 API
    (``fmpy.fmi3.FMU3Slave``): d [mm] and, with ``use_velocity``, v [mm/s]
    set before each fmi3DoStep(t, h) are the values at t + h; F [kN] is read
    after it.  ``unzipdir``: an already extracted FMU (several instances share
    one); otherwise the FMU is extracted to a temporary folder, removed by
    ``close``.  ``scale``: the force and work it hands out are the FMU's
    times this (dampers side by side, a larger device of the series)."""

    def __init__(self, path, name: str = "damper", use_velocity: bool = True, unzipdir=None,
                 scale: float = 1.0):
        md = read_model_description(str(path))
        vr = {v.name: v.valueReference for v in md.modelVariables}
        self._tmp = None
        if unzipdir is None:
            self._tmp = tempfile.TemporaryDirectory(prefix="fvd_cosim-")
            unzipdir = extract(str(path), self._tmp.name)
        self.name, self.use_velocity, self.messages, self.scale = name, use_velocity, [], float(scale)
        self._inputs = [vr["d"], vr["v"]] if use_velocity else [vr["d"]]
        self._force, self._outputs = [vr["F"]], [vr["F"], vr["z"], vr["E"]]
        self.fmu = FMU3Slave(guid=md.guid, unzipDirectory=unzipdir,
                             modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        self._log = fmi3LogMessageCallback(self._message)  # kept: the FMU calls it back
        self.fmu.instantiate(logMessage=self._log)
        # structural parameters: d(t + h) before each step (exact, structure first); v as given or derived
        self.fmu.setBoolean([vr["inputs_at_step_end"], vr["use_velocity_input"]], [True, use_velocity])
        self.steps = 0

    def _message(self, env, status, category, message):
        self.messages.append(message.decode(errors="replace"))

    def initialize(self, t0: float = 0.0, d0: float = 0.0, v0: float = 0.0) -> None:
        """Initialization at t0 [s] with the pin at d0 [mm], v0 [mm/s]."""
        self.fmu.enterInitializationMode(startTime=t0)
        self.fmu.setFloat64(self._inputs, [d0, v0][:len(self._inputs)])
        self.fmu.exitInitializationMode()

    def step(self, t: float, h: float, d: float, v: float = 0.0, rollback: bool = False) -> float:
        """One communication step [t, t + h] with d(t + h) [mm], v(t + h)
        [mm/s]; returns F(t + h) [kN].  ``rollback``: the master may set an
        earlier state afterwards (noSetFMUStatePriorToCurrentPoint false)."""
        self.fmu.setFloat64(self._inputs, [d, v][:len(self._inputs)])
        try:
            self.fmu.doStep(t, h, noSetFMUStatePriorToCurrentPoint=not rollback)
        except Exception as e:  # FMPy's FMICallException: the FMU's own words are in its log
            said = "; ".join(self.messages[-3:]) or str(e)
            raise RuntimeError(f"{self.name}: fmi3DoStep(t = {t:g} s, h = {h:g} s) failed: {said}") from e
        self.steps += 1
        return self.scale * self.fmu.getFloat64(self._force)[0]

    def outputs(self) -> tuple[float, float, float]:
        """(F [kN], z, E [kN mm]) at the current communication point."""
        F, z, E = self.fmu.getFloat64(self._outputs)
        return self.scale * F, z, self.scale * E

    def save(self):
        """The FMU state (fmi3GetFMUState); give it back with ``free``."""
        return self.fmu.getFMUState()

    def restore(self, state) -> None:
        self.fmu.setFMUState(state)

    def free(self, state) -> None:
        self.fmu.freeFMUState(state)

    def close(self) -> None:
        """fmi3Terminate, fmi3FreeInstance, and the temporary folder."""
        try:
            self.fmu.terminate()
            self.fmu.freeInstance()
        finally:
            if self._tmp is not None:
                self._tmp.cleanup()


def damper_fmus(path, n: int, use_velocity: bool = True, workdir=None, scale: float = 1.0) -> list[DamperFMU]:
    """``n`` initialized instances of one FMU, extracted once into ``workdir``
    (a folder that must outlive them), their forces times ``scale``."""
    unzipdir = extract(str(path), str(workdir)) if workdir is not None else None
    fmus = [DamperFMU(path, f"damper{i + 1}", use_velocity, unzipdir, scale) for i in range(n)]
    for f in fmus:
        f.initialize()
    return fmus
