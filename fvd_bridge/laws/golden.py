"""Golden force histories of the nine laws, for checking other implementations.

The OpenSees and FMU exporters (and the tests) compare their force against
``tests/golden/lawN.csv``: a fixed displacement history, one reference
parameter set per law, and the force of this package's kernel, written with
11 significant digits.  Regenerate with ``python -m fvd_bridge.laws.golden``
after a deliberate change of a kernel.

Input: d(t) = e(t) (A1 sin(2 pi f1 t) + A2 sin(2 pi f2 t)) [mm], A1 = 20 mm at
f1 = 1 Hz plus A2 = 5 mm at f2 = 5 Hz (so the loops carry minor loops), faded
in by e(t) = smoothstep(t / 0.25 s); v = dd/dt [mm/s] exactly; 0 <= t <= 2 s,
dt = 0.001 s.  The file's d and v are the kernel's input as written.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from .catalog import LAWS

DT = 0.001  # [s]
DURATION = 2.0  # [s]
FADE = 0.25  # [s]
WAVES = ((20.0, 1.0), (5.0, 5.0))  # (amplitude [mm], frequency [Hz])
GOLDEN_DIR = Path(__file__).resolve().parents[2] / "tests" / "golden"

# one realistic parameter set per law, for a 300 kN class damper (kN, mm, s);
# law 7 has beta = 1: the Maxwell model of OpenSees' ViscousDamper
REFERENCE = {
    1: (0.6,),
    2: (45.0, 0.3),
    3: (45.0, 0.3, 5.0),
    4: (45.0, 0.3, 5.0, 0.1),
    5: (45.0, 0.3, 2.0, 1.2),
    6: (0.25, 60.0, 0.01, 0.08),
    7: (45.0, 0.3, 100.0, 1.0),
    8: (0.25, 30.0, 0.5, 330.0),
    9: (0.2, 0.15, 27.0),
}


def reference_input() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(t [s], d [mm], v [mm/s]) of the golden input, before rounding to the file."""
    t = np.arange(round(DURATION / DT) + 1) * DT
    s = np.clip(t / FADE, 0.0, 1.0)
    e, de = s * s * (3.0 - 2.0 * s), 6.0 * s * (1.0 - s) / FADE
    w = sum(a * np.sin(2 * math.pi * f * t) for a, f in WAVES)
    dw = sum(a * 2 * math.pi * f * np.cos(2 * math.pi * f * t) for a, f in WAVES)
    return t, e * w, de * w + e * dw


COLUMNS = "t,d,v,F"
FORMATS = ("{:.3f}", "{:.9g}", "{:.9g}", "{:.11g}")  # of t, d, v, F


def _as_written(x: np.ndarray, fmt: str) -> np.ndarray:
    return np.array([float(fmt.format(value)) for value in x])


def _rows(*columns) -> list[str]:
    return [",".join(fmt.format(value) for fmt, value in zip(FORMATS, row)) for row in zip(*columns)]


def _header(number: int) -> list[str]:
    law = LAWS[number]
    pars = " ".join(f"{p.name}={x:g}" for p, x in zip(law.parameters, REFERENCE[number]))
    return [f"# fvd_bridge golden output, law {number}: {law.name}; {law.equation}",
            f"# parameters: {pars}",
            f"# input: d = smoothstep(t/{FADE:g}) ({WAVES[0][0]:g} sin(2 pi {WAVES[0][1]:g} t) + "
            f"{WAVES[1][0]:g} sin(2 pi {WAVES[1][1]:g} t)), v = dd/dt, dt = {DT:g} s; "
            f"the force of the package's kernel for d, v as written",
            "# units: t [s], d [mm], v [mm/s], F [kN]; regenerate: python -m fvd_bridge.laws.golden",
            COLUMNS]


def read_golden(path) -> tuple[dict, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(parameters {name: value}, t, d, v, F) of a golden file."""
    lines = Path(path).read_text().splitlines()
    pars_line = next(line for line in lines if line.startswith("# parameters:"))
    pars = {k: float(x) for k, x in (item.split("=") for item in pars_line.split(":", 1)[1].split())}
    t, d, v, F = np.loadtxt(lines[lines.index(COLUMNS) + 1:], delimiter=",").T
    return pars, t, d, v, F


def write_golden(directory=GOLDEN_DIR) -> list[Path]:
    """Write lawN.csv for the nine laws into ``directory``; returns the paths."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    t, d, v = (_as_written(x, fmt) for x, fmt in zip(reference_input(), FORMATS))
    paths = []
    for number, law in LAWS.items():
        F = law.force(d, v, DT, np.array([REFERENCE[number]]))[0]
        path = directory / f"law{number}.csv"
        path.write_text("\n".join(_header(number) + _rows(t, d, v, F)) + "\n")
        paths.append(path)
    return paths


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m fvd_bridge.laws.golden",
                                     description=__doc__.split("\n")[0])
    parser.add_argument("--out", default=str(GOLDEN_DIR), help="folder for lawN.csv (default: tests/golden)")
    args = parser.parse_args(argv)
    for path in write_golden(args.out):
        print(f"wrote {path} ({path.stat().st_size / 1024:.0f} kB)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
