"""Golden force histories of the laws and of models (law + effects),
for checking other implementations.

The OpenSees and FMU exporters (and the tests) compare their force against
``tests/golden/law<SPEC>.csv``: a fixed displacement history, one reference
parameter set per law (and per effect), and the force of this package,
written with 11 significant digits.  Regenerate with
``python -m fvd_bridge.golden [--out DIR]`` after a deliberate change.

Input: d(t) = e(t) (A1 sin(2 pi f1 t) + A2 sin(2 pi f2 t)) [mm], A1 = 20 mm at
f1 = 1 Hz plus A2 = 5 mm at f2 = 5 Hz (so the loops carry minor loops), faded
in by e(t) = smoothstep(t / 0.25 s); v = dd/dt [mm/s] and a = d2d/dt2
[mm/s^2] exactly; 0 <= t <= 2 s, dt = 0.001 s.  The file's d, v (and a, for
models) are the input as written.  Law files have columns t,d,v,F; model
files t,d,v,a,F (inertia needs a).
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from .catalog import parse_model
from .effects.catalog import BUILTIN, EFFECTS
from .laws import LAWS
from .records import Record

DT = 0.001  # [s]
DURATION = 2.0  # [s]
FADE = 0.25  # [s]
WAVES = ((20.0, 1.0), (5.0, 5.0))  # (amplitude [mm], frequency [Hz])
GOLDEN_DIR = Path(__file__).resolve().parents[1] / "tests" / "golden"

# one realistic parameter set per law and per effect (each declared with it:
# ``Law.reference``, ``Effect.reference``), for a 300 kN class damper (kN, mm, s)
REFERENCE = {number: law.reference for number, law in LAWS.items()}
#: effect parameters of the model goldens, by effect name (values in the effect's units)
EFFECT_REFERENCE = {e.name: e.reference for e in BUILTIN}
#: the model goldens: each effect on law 2 and on law 9, and combinations (one arrangement of a spring at a
#: time: the seal behind the spring and beside the oil column)
MODEL_SPECS = tuple(f"{law}+{e}" for law in (2, 9) for e in EFFECT_REFERENCE) + (
    "2+series_stiffness+friction", "2+oil_column+friction+parallel_stiffness", "9+oil_column+friction",
    "9+gap+friction", "2+gap+series_stiffness+asymmetry",
    "2+" + "+".join(e for e in EFFECT_REFERENCE if not EFFECTS[e].arrangement_of))


def reference_input() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(t [s], d [mm], v [mm/s], a [mm/s^2]) of the golden input, before rounding to the file."""
    t = np.arange(round(DURATION / DT) + 1) * DT
    s = np.clip(t / FADE, 0.0, 1.0)
    e, de = s * s * (3.0 - 2.0 * s), 6.0 * s * (1.0 - s) / FADE
    dde = np.where(t < FADE, (6.0 - 12.0 * s) / FADE ** 2, 0.0)
    w = sum(a * np.sin(2 * math.pi * f * t) for a, f in WAVES)
    dw = sum(a * 2 * math.pi * f * np.cos(2 * math.pi * f * t) for a, f in WAVES)
    ddw = sum(-a * (2 * math.pi * f) ** 2 * np.sin(2 * math.pi * f * t) for a, f in WAVES)
    return t, e * w, de * w + e * dw, dde * w + 2.0 * de * dw + e * ddw


def reference_params(model) -> np.ndarray:
    """The reference parameter vector of a model (law's REFERENCE, effects' EFFECT_REFERENCE)."""
    return np.array(list(REFERENCE[model.law.number]) + [x for e in model.effects for x in EFFECT_REFERENCE[e.name]])


LAW_COLUMNS = "t,d,v,F"
MODEL_COLUMNS = "t,d,v,a,F"
FORMATS = {"t": "{:.3f}", "d": "{:.9g}", "v": "{:.9g}", "a": "{:.9g}", "F": "{:.11g}"}


def _as_written(x: np.ndarray, fmt: str) -> np.ndarray:
    return np.array([float(fmt.format(value)) for value in x])


def _rows(columns: str, *values) -> list[str]:
    fmts = [FORMATS[c] for c in columns.split(",")]
    return [",".join(fmt.format(value) for fmt, value in zip(fmts, row)) for row in zip(*values)]


def _input_line(with_a: bool) -> str:
    return (f"# input: d = smoothstep(t/{FADE:g}) ({WAVES[0][0]:g} sin(2 pi {WAVES[0][1]:g} t) + "
            f"{WAVES[1][0]:g} sin(2 pi {WAVES[1][1]:g} t)), v = dd/dt{', a = dv/dt' if with_a else ''}, "
            f"dt = {DT:g} s; the force of the package's kernel for d, v{', a' if with_a else ''} as written")


def _law_header(number: int) -> list[str]:
    law = LAWS[number]
    pars = " ".join(f"{p.name}={x:g}" for p, x in zip(law.parameters, REFERENCE[number]))
    return [f"# fvd_bridge golden output, law {number}: {law.name}; {law.equation}",
            f"# parameters: {pars}", _input_line(False),
            "# units: t [s], d [mm], v [mm/s], F [kN]; regenerate: python -m fvd_bridge.golden",
            LAW_COLUMNS]


def _model_header(model, params) -> list[str]:
    pars = " ".join(f"{n}={x:g}" for n, x in zip(model.names, params))
    effects = "; ".join(f"{e.name}: {e.equation}" for e in model.effects)
    return [f"# fvd_bridge golden output, model {model.spec}: law {model.law.number} ({model.law.equation}) "
            f"with {effects}",
            f"# parameters: {pars}", _input_line(True),
            "# units: t [s], d [mm], v [mm/s], a [mm/s^2], F [kN]; regenerate: python -m fvd_bridge.golden",
            MODEL_COLUMNS]


def read_golden(path) -> tuple[dict, dict]:
    """(parameters {name: value}, columns {t, d, v[, a], F: array}) of a golden file."""
    lines = Path(path).read_text().splitlines()
    pars_line = next(line for line in lines if line.startswith("# parameters:"))
    pars = {k: float(x) for k, x in (item.split("=") for item in pars_line.split(":", 1)[1].split())}
    head = next(k for k, line in enumerate(lines) if line in (LAW_COLUMNS, MODEL_COLUMNS))
    data = np.loadtxt(lines[head + 1:], delimiter=",").T
    return pars, dict(zip(lines[head].split(","), data))


def golden_record(columns: dict):
    """The golden input as a Record (F = 0; a = 0 in a law file, which has none)."""
    t = columns["t"]
    return Record(t, columns["d"], np.zeros_like(t), columns["v"], columns.get("a", np.zeros_like(t)),
                  name="golden")


def write_golden(directory=GOLDEN_DIR) -> list[Path]:
    """Write law<SPEC>.csv for every law and the MODEL_SPECS into ``directory``."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    t, d, v, a = (_as_written(x, FORMATS[c]) for x, c in zip(reference_input(), "tdva"))
    paths = []
    for number, law in LAWS.items():
        F = law.force(d, v, DT, np.array([REFERENCE[number]]))[0]
        path = directory / f"law{number}.csv"
        path.write_text("\n".join(_law_header(number) + _rows(LAW_COLUMNS, t, d, v, F)) + "\n")
        paths.append(path)
    record = golden_record({"t": t, "d": d, "v": v, "a": a})
    for spec in MODEL_SPECS:
        model = parse_model(spec)
        params = reference_params(model)
        F = model.force(record, params[None, :])[0]
        path = directory / f"law{spec}.csv"
        path.write_text("\n".join(_model_header(model, params) + _rows(MODEL_COLUMNS, t, d, v, a, F)) + "\n")
        paths.append(path)
    return paths


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m fvd_bridge.golden", description=__doc__.split("\n")[0])
    parser.add_argument("--out", default=str(GOLDEN_DIR), help="folder for law<SPEC>.csv (default: tests/golden)")
    args = parser.parse_args(argv)
    for path in write_golden(args.out):
        print(f"wrote {path} ({path.stat().st_size / 1024:.0f} kB)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
