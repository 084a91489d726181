"""FMI 3.0 co-simulation FMU of a calibrated damper: build and validate.

``build_fmu(calibration, path)`` writes one FMU that holds the C sources of
the package's ``fmu/`` folder (``FMU_SOURCES``; one model for every law and built-in effect
of the registry, chosen by structural parameters; laws.c and effects.c mirror
the Python step forms function for function, model.c is the FMI plumbing)
and the interface generated from the registry (``fmu_interface``:
``config.h`` and ``modelDescription.xml``, with the calibrated parameters as
start values, the model's own parameters tunable and every other one fixed),
compiled for this platform by FMPy's CMake project
(``fmpy.build.build_platform_binary``; needs cmake and a C compiler).
``validate(fmu, calibration, record)`` checks it with FMPy and returns the
OF (paper eq. 18) of its force against the Python model's.

Co-simulation convention (the FMU's inputs): FMI's by default, the master
sets the pin's displacement d [mm] at the communication point t before
``fmi3DoStep(t, h)``; the FMU redoes its last step with it (its state stays
exact), extrapolates d to t + h (second order, from the last three points)
and steps there: its outputs F [kN], z, E [kN mm] are the values at t + h,
without a one-step lag.  With the structural parameter inputs_at_step_end
the master sets d(t + h) itself and the step is exact (fvd_bridge's
co-simulation).  Each step is integrated in ceil(h / h_max) equal
sub-steps.  The velocity and acceleration are derived from the samples of
d (second-order backward differences, from rest), or taken from the inputs
v [mm/s], a [mm/s^2] once the master sets them (or with the structural
parameters use_velocity_input, use_acceleration_input).
Variables: ``fmu_interface.variables()``; law parameters are named
``law<N>.<name>`` (law2.C), effect parameters as in the calibration file
(friction.Ff), effects switched by ``<effect>.enabled``.
"""

from __future__ import annotations

import contextlib
import io
import math
import os
import shutil
import subprocess
import sys
import tempfile
import uuid
import xml.etree.ElementTree as ET
import zipfile
from datetime import datetime, timezone
from pathlib import Path

import fmpy
import numpy as np
from fmpy import read_model_description, simulate_fmu
from fmpy.build import build_platform_binary
from fmpy.validation import validate_fmu

from .._version import __version__
from ..calibration.parts import RecordSource
from ..calibration.tested import fitted_on_text
from ..effects.catalog import EFFECTS
from ..errors import InputError, positive
from ..fit.objective import objective
from . import fmu_interface
from .fmu_interface import MODEL_IDENTIFIER
from .fmu_toolchain import build_log_problem, toolchain_problem

#: the hand-kept C sources and build description: package data (fvd_bridge/fmu/, shipped in the
#: wheel), found beside this module alike in a checkout, an editable install and an installed wheel
#: (a folder on disk, not importlib.resources: the C compiler reads the files; pip installs unzipped)
FMU_SOURCES = Path(__file__).resolve().parents[1] / "fmu"
SOURCE_FILES = ("model.h", "damper.h", "model.c", "laws.c", "effects.c", "fmi3Functions.c")
#: written into the FMU by build_fmu, generated from the registry (fmu_interface) and the calibration
GENERATED_FILES = ("sources/config.h", "sources/calibration.h", "modelDescription.xml")
#: largest sub-step [s] when neither h_max nor the calibration record's dt is given
DEFAULT_H_MAX = 1e-3
#: OF (eq. 18) an FMU must reach against the Python model on a record, d as its only input
OF_BOUND = 0.002
#: the inputs ``validate`` and ``simulate`` can drive: 'd' alone, or with v (and a) from the record
INPUTS = ("d", "dv", "dva")
#: FMPy's CMake project links no library: without libm, pow() stays unresolved
CMAKE_OPTIONS = {"CMAKE_C_STANDARD_LIBRARIES:STRING": "-lm", "CMAKE_C_VISIBILITY_PRESET:STRING": "hidden"}


def build_fmu(calibration, path, h_max: float | None = None) -> str:
    """Write the calibrated damper as an FMI 3.0 co-simulation FMU at ``path``
    (written atomically: nothing is left there on failure); returns the path.

    ``h_max`` [s]: the largest integration sub-step (default: the
    calibration record's dt, else DEFAULT_H_MAX).  A model with a plugin
    effect cannot be exported, nor one built without cmake and a C compiler
    (InputError naming what to install), nor a calibration with parameters
    fitted per test (choose the test first: ``Calibration.for_test``)."""
    calibration = calibration.for_test()  # refused with per-test parameters: one test's values are not the device's
    values = start_values(calibration, _h_max(calibration, h_max))
    problem = toolchain_problem()  # before anything is written
    if problem:
        raise InputError(problem)
    path = os.path.abspath(os.fspath(path))
    os.makedirs(os.path.dirname(path), exist_ok=True)
    token = "{" + str(uuid.uuid4()) + "}"  # once: into the XML and the C define
    with tempfile.TemporaryDirectory(prefix="fvd_fmu-") as work:
        unzipdir = Path(work) / "fmu"
        sources = unzipdir / "sources"
        sources.mkdir(parents=True)
        for name in SOURCE_FILES + ("buildDescription.xml",):
            shutil.copy(_source(name), sources / name)
        root = model_description(calibration, values, token)
        ET.ElementTree(root).write(unzipdir / "modelDescription.xml", encoding="UTF-8", xml_declaration=True)
        (sources / "config.h").write_text(fmu_interface.config_header())
        (sources / "calibration.h").write_text(calibration_header(root))
        _compile(unzipdir, Path(work) / "build")
        partial = f"{path}.partial-{os.getpid()}"
        try:
            with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as zf:
                for file in sorted(p for p in unzipdir.rglob("*") if p.is_file()):
                    zf.write(file, file.relative_to(unzipdir).as_posix())
            os.replace(partial, path)
        finally:
            if os.path.exists(partial):
                os.remove(partial)
    return path


def start_values(calibration, h_max: float) -> dict:
    """{FMU variable name: start value} of a calibration: the law's number,
    the effects' switches, the law's parameters as 'law<N>.<name>', the
    effects' as in the model ('friction.Ff'), h_max [s]."""
    model = calibration.model
    why = model.fmu_refusal()
    if why:
        raise InputError(f"model '{model.spec}': {why}; the FMU holds the built-in effects "
                         f"({', '.join(EFFECTS)}) and the laws with a C step form")
    number = model.law.number
    values = {"law": number, "h_max": h_max}
    values.update({f"{name}.enabled": model.has(name) for name in EFFECTS})
    off = dict(zip(model.names, model.off_values()))
    for name, x in calibration.named().items():
        key = _variable(number, name)
        if not (math.isfinite(x) or x == off[name]):  # an infinite 'off' value: a rigid series spring
            raise InputError(f"model '{model.spec}': parameter '{name}' = {x}: not a finite number")
        values[key] = float(x)
    return values


def tunable_parameters(calibration) -> list:
    """The FMU variables of the calibrated model's own parameters (its law's
    'law<N>.<name>' and its effects' 'friction.Ff'): tunable in its FMU."""
    number = calibration.model.law.number
    return [_variable(number, name) for name in calibration.model.names]


def model_description(calibration, values: dict, token: str) -> ET.Element:
    """The FMU's modelDescription.xml: the variables generated from the
    registry (``fmu_interface.model_description``) with the start values,
    the model's own parameters tunable and every other one fixed, the token,
    the description and an fvd_bridge annotation."""
    try:
        root = fmu_interface.model_description(tunable=tunable_parameters(calibration), start=values,
                                               description=_description(calibration))
    except KeyError as exc:
        raise InputError(f"model '{calibration.spec}': no FMU variable for {exc.args[0]}") from None
    root.set("instantiationToken", token)
    root.set("generationTool", f"fvd_bridge {__version__}")
    root.set("generationDateAndTime", datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"))
    annotations = _annotation(calibration)
    ET.indent(annotations, space="  ", level=1)
    root[-1].tail, annotations.tail = "\n\n  ", "\n\n"
    root.append(annotations)
    return root


def calibration_header(root: ET.Element) -> str:
    """sources/calibration.h: the token and every start value of the model
    description, by value reference, the variables' names (messages) and
    which parameters are tunable."""
    float64, boolean, names, tunable = [], [], [], ["[0] = false"]
    law = None
    for v in root.find("ModelVariables"):
        vr, start = int(v.get("valueReference")), v.get("start")
        names.append(f'[{vr}] = "{v.get("name")}"')
        if v.get("variability") == "tunable":
            tunable.append(f"[{vr}] = true")
        if start is None:
            continue
        if v.tag == "Float64":
            float64.append(f"[{vr}] = {_c_value(float(start))}")
        elif v.tag == "Boolean":
            boolean.append(f"[{vr}] = {start}")
        elif v.get("name") == "law":
            law = int(start)
    lines = ["/* Written by fvd_bridge.export.fmu.build_fmu: the instantiation token, the start values of",
             " * modelDescription.xml by value reference, the variables' names and the tunable parameters.",
             " * Do not edit. */",
             f'#define INSTANTIATION_TOKEN "{root.get("instantiationToken")}"',
             f"#define START_LAW {law}",
             _c_list("START_FLOAT64", float64), _c_list("START_BOOLEAN", boolean),
             _c_list("VARIABLE_NAMES", names), _c_list("TUNABLE_PARAMETERS", tunable)]
    return "\n".join(lines) + "\n"


def fmu_forces(fmu_path, calibration, record, inputs=("d",)) -> tuple[np.ndarray, dict]:
    """The Python model's force on the record (``calibration.force`` at the
    FMU's sub-steps per sample) and the FMU's {inputs: force} [kN], the FMU
    driven by FMPy's ``simulate_fmu`` with the record's d ('d'), d and v
    ('dv') or d, v and a ('dva'), FMI's way (each sample set at its
    communication point), or with '@end' ('dva@end') each sample sent before
    the step that ends there (inputs_at_step_end: exact).  The file is
    checked by ``fmpy.validate_fmu`` once: a file it finds problems in is an
    InputError."""
    fmu_path = os.fspath(fmu_path)
    problems = validate_fmu(fmu_path)
    if problems:
        more = f" (and {len(problems) - 1} more)" if len(problems) > 1 else ""
        raise InputError(f"{fmu_path}: not a valid FMU: {problems[0].strip()}{more}")
    md = read_model_description(fmu_path)
    h_max = float(next(v.start for v in md.modelVariables if v.name == "h_max"))
    F_model = calibration.force(record, substeps_of(record.dt, h_max))
    return F_model, {i: simulate(fmu_path, record, i.split("@")[0], ("F",), at_step_end=i.endswith("@end"))["F"]
                     for i in inputs}


def validate(fmu_path, calibration, record, inputs: str = "d") -> float:
    """OF (paper eq. 18) of the FMU's force against the Python model's on the
    record (``fmu_forces``; 'dva@end' is the C mirror, which must stay
    within OF_BOUND)."""
    F_model, F_fmu = fmu_forces(fmu_path, calibration, record, (inputs,))  # 'dva@end': at each step's end
    return float(objective(F_model, F_fmu[inputs], record.t))


def simulate(fmu_path, record, inputs: str = "d", outputs=("F", "z", "E"), at_step_end: bool = False) -> dict:
    """Outputs {name: (n_t,)} of the FMU driven by the record with FMPy's
    ``simulate_fmu`` (one communication step per sample): ``inputs`` 'd',
    'dv' or 'dva', each sample set at its own time, FMI's convention (or,
    ``at_step_end``, sent before the step that ends there, with
    inputs_at_step_end)."""
    if inputs not in INPUTS:
        raise InputError(f"inputs '{inputs}': expected one of {', '.join(INPUTS)}")
    t = np.asarray(record.t, dtype=float)
    names = tuple(inputs)
    signal = end_of_step_input(record, names) if at_step_end else sampled_input(record, names)
    with contextlib.redirect_stdout(io.StringIO()):  # FMPy prints 'missing input for variable v' for each unused input
        result = simulate_fmu(os.fspath(fmu_path), start_time=t[0], stop_time=t[-1], step_size=record.dt,
                              output_interval=record.dt,  # else FMPy may double the communication step
                              input=signal, output=list(outputs), start_values={"inputs_at_step_end": at_step_end})
    if result.size != t.size or not np.allclose(result["time"], t, rtol=0.0, atol=1e-9 * max(1.0, abs(t[-1]))):
        raise RuntimeError(f"{fmu_path}: FMPy returned {result.size} samples for the record's {t.size}")
    return {name: np.asarray(result[name], dtype=float) for name in outputs}


def sampled_input(record, names=("d",)) -> np.ndarray:
    """FMPy input signal of the record's samples at their times (FMI's
    convention: the inputs at each communication point)."""
    signal = np.zeros(record.n, dtype=[("time", float)] + [(n, float) for n in names])
    signal["time"] = record.t
    for n in names:
        signal[n] = np.asarray(getattr(record, n), dtype=float)
    return signal


def end_of_step_input(record, names=("d", "v", "a")) -> np.ndarray:
    """FMPy input signal that sets, before each step [t_k, t_k+1], the record's
    sample k+1 (the FMU's end-of-step convention): the record shifted one
    sample earlier, plus an event at t_0 so that initialization still sees
    sample 0 (FMPy applies the left value at t_0 during initialization and
    the right one before the first step; a row before t_0 makes the event
    visible to its interpolation)."""
    t = np.asarray(record.t, dtype=float)
    time = np.concatenate([[t[0] - record.dt, t[0]], t[:-1]])
    signal = np.zeros(time.size, dtype=[("time", float)] + [(n, float) for n in names])
    signal["time"] = time
    for n in names:
        x = np.asarray(getattr(record, n), dtype=float)
        signal[n] = np.concatenate([[x[0]], x])
    return signal


def substeps_of(h: float, h_max: float) -> int:
    """Sub-steps of a step h [s]: ceil(h / h_max), a step within 1e-9 above a
    multiple of h_max counting as that multiple (model.c's substeps_of)."""
    return max(1, math.ceil(h / h_max * (1.0 - 1e-9)))


# --------------------------------------------------------------------------- helpers

def _source(name: str) -> Path:
    path = FMU_SOURCES / name
    if not path.is_file():
        raise InputError(f"{path}: the FMU's C sources are missing from this installation of fvd_bridge "
                         f"(package data of its wheel: reinstall fvd_bridge)")
    return path


def _variable(number: int, name: str) -> str:
    """The FMU variable of a model parameter: an effect's as named ('friction.Ff'), a law's 'law<N>.<name>'."""
    return name if "." in name else fmu_interface.law_parameter_name(number, name)


def _h_max(calibration, h_max) -> float:
    if h_max is None:
        h_max = calibration.record.dt or DEFAULT_H_MAX
    return positive("h_max [s]", h_max)


def _device(calibration) -> str:
    name = calibration.device or calibration.record.name
    if name:
        return str(name)
    return Path(calibration.path).parent.name if calibration.path else "damper"


def _record_file(calibration) -> str | None:
    """The calibration record's file name (its basename: no local path goes into the FMU)."""
    file = calibration.record.file
    return os.path.basename(str(file)) if file else None


def _description(calibration) -> str:
    """The FMU's description: the device, named by its law (Law.name) and effects, the model, the calibration."""
    model, law = calibration.model, calibration.model.law
    kind = law.name + (" with " + ", ".join(e.name.replace("_", " ") for e in model.effects) if model.effects else "")
    effects = "".join(f"; {e.name}: {e.equation}" for e in model.effects)
    file = _record_file(calibration) if len(calibration.tests) <= 1 else None  # several tests: several files
    fitted_on = fitted_on_text(calibration)
    source = (f" on {fitted_on}" + (f" ({file})" if file else "")) if fitted_on else ""
    return (f"{_device(calibration)}: {kind} (fvd_bridge model {model.spec}: law {law.number}, {law.equation}"
            f"{effects}), calibrated by fvd_bridge to OF {calibration.of:.4g}{source}; "
            f"{calibration.tested_text()}. "
            "Set d [mm] (and v, a when you have them) at each communication point before fmi3DoStep, as FMI "
            "masters do (inputs_at_step_end: at the step's end); units kN, mm, s.")


def _annotation(calibration) -> ET.Element:
    """<Annotations><Annotation type="fvd_bridge.calibration">: model, law, effects, OF, record, parameters."""
    model, law = calibration.model, calibration.model.law
    annotations = ET.Element("Annotations")
    ann = ET.SubElement(annotations, "Annotation", type="fvd_bridge.calibration")
    cal = ET.SubElement(ann, "Calibration", model=model.spec, device=_device(calibration),
                        of=repr(float(calibration.of)), fvd_bridge_version=__version__)
    if calibration.path:
        cal.set("file", os.path.basename(calibration.path))
    if calibration.tests:
        cal.set("tests", ", ".join(t.name for t in calibration.tests))  # one of a device's: the test taken
    ET.SubElement(cal, "Law", number=str(law.number), name=law.name, equation=law.equation, source=law.source)
    for e in model.effects:
        ET.SubElement(cal, "Effect", name=e.name, equation=e.equation)
    for name, unit, x in zip(model.names, model.units, calibration.values):
        ET.SubElement(cal, "Parameter", name=name, unit=unit, value=repr(float(x)))
    rec = calibration.record
    if rec != RecordSource():
        r = ET.SubElement(cal, "Record", {k: str(getattr(rec, k)) for k in ("name", "format", "samples", "dt")
                                           if getattr(rec, k) not in (None, "")})
        if _record_file(calibration):
            r.set("file", _record_file(calibration))
        for key, value in rec.peaks.as_dict().items():
            if value is not None:
                ET.SubElement(r, "Peak", quantity=key, value=repr(float(value)))
    return annotations


def _c_value(x: float) -> str:
    return "INFINITY" if x == math.inf else repr(x)


def _c_list(name: str, items: list) -> str:
    return f"#define {name} {{ \\\n    " + ", \\\n    ".join(items) + " }"


def _compile(unzipdir: Path, build_dir: Path) -> None:
    """The platform binary by FMPy's CMake project, quietly (its log shown on
    failure; a missing C library header: one line, InputError)."""
    build_dir.mkdir()
    log = build_dir.parent / "build.log"
    try:
        with _output_to(log):
            build_platform_binary(unzipdir.resolve(), build_dir, cmake_options=dict(CMAKE_OPTIONS))
    except subprocess.CalledProcessError as exc:
        text = log.read_text(errors="replace")
        problem = build_log_problem(text)
        if problem:
            raise InputError(problem) from None
        tail = "\n".join(text.splitlines()[-20:])
        raise RuntimeError(f"compiling the FMU failed ({exc}):\n{tail}") from None
    binary = unzipdir / "binaries" / _platform_tuple() / (MODEL_IDENTIFIER + _library_suffix())
    if not binary.is_file():
        raise RuntimeError(f"compiling the FMU produced no {binary.relative_to(unzipdir)}")


def _platform_tuple() -> str:
    return fmpy.platform_tuple


def _library_suffix() -> str:
    return fmpy.sharedLibraryExtension


@contextlib.contextmanager
def _output_to(path: Path):
    """Send this process's stdout and stderr (file descriptors 1, 2: cmake's
    and the compiler's output) to ``path`` inside the block."""
    for stream in (sys.stdout, sys.stderr):
        stream.flush()
    saved = [os.dup(1), os.dup(2)]
    try:
        with open(path, "wb") as fh:
            os.dup2(fh.fileno(), 1)
            os.dup2(fh.fileno(), 2)
            yield
    finally:
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(Exception):
                stream.flush()
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in saved:
            os.close(fd)
