"""Speed of the damper FMU: communication steps per second of a differential
law with sub-stepping (law 7, TR-BDF2 with Newton on each stage, and law 9,
exact rate-independent steps; golden reference parameters; h_max < h so
that each fmi3DoStep integrates ceil(h / h_max) sub-steps), driven

- from Python, FMPy's low-level API (setFloat64 d, fmi3DoStep, getFloat64 F
  per step: what a Python master pays per step and damper), and
- from C, a small driver that dlopens the FMU's binary and calls the same
  three functions in a loop (compiled here with gcc against FMPy's FMI 3
  headers): the FMU's own cost;

both on the golden input (20 mm at 1 Hz + 5 mm at 5 Hz; the FMU derives v
from d), which they must agree on (the same forces, bit for bit); then the
wall time of the co-simulation examples (examples/fmu_cosim.py and
examples/opensees_fmu_cosim.py, the whole El Centro record unless
--duration; skipped when ../shared is absent).

    python benchmarks/bench_fmu.py [--h 0.01] [--h-max 0.001] [--steps 20000] [--duration S] [--no-examples]
"""

from __future__ import annotations

import argparse
import json
import math
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
RECORD = REPO / ".." / "shared" / "records" / "elcentro_1940_NS_2688pts_g_dt0.02.dat"
LAWS = (7, 9)
#: the golden input: (amplitude [mm], frequency [Hz])
WAVES = ((20.0, 1.0), (5.0, 5.0))

DRIVER = r"""
/* Drives one damper FMU: d(t + h) = sum A sin(2 pi f (t + h)) set before each fmi3DoStep(t, h), F read after. */
#include <dlfcn.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "fmi3FunctionTypes.h"

static void logger(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message) {
    fprintf(stderr, "FMU: %s\n", message);
}

#define LOAD(name) name##TYPE *name = (name##TYPE *)dlsym(lib, #name); \
    if (!name) { fprintf(stderr, "missing %s\n", #name); return 2; }

int main(int argc, char **argv) {
    if (argc != 9) { fprintf(stderr, "usage: driver LIB TOKEN RESOURCES STEPS H VR_D VR_F OUT\n"); return 2; }
    void *lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) { fprintf(stderr, "%s\n", dlerror()); return 2; }
    LOAD(fmi3InstantiateCoSimulation) LOAD(fmi3EnterInitializationMode) LOAD(fmi3ExitInitializationMode)
    LOAD(fmi3SetFloat64) LOAD(fmi3GetFloat64) LOAD(fmi3DoStep) LOAD(fmi3Terminate) LOAD(fmi3FreeInstance)
    long steps = atol(argv[4]);
    double h = atof(argv[5]);
    fmi3ValueReference vr_d = (fmi3ValueReference)atol(argv[6]), vr_F = (fmi3ValueReference)atol(argv[7]);
    fmi3Instance s = fmi3InstantiateCoSimulation("driver", argv[2], argv[3], fmi3False, fmi3False, fmi3False,
                                                 fmi3False, NULL, 0, NULL, logger, NULL);
    if (!s) { fprintf(stderr, "instantiation failed\n"); return 1; }
    double d = 0.0, F = 0.0, *force = malloc(steps * sizeof(double));
    if (fmi3EnterInitializationMode(s, fmi3False, 0.0, 0.0, fmi3False, 0.0) > fmi3Warning) return 1;
    fmi3SetFloat64(s, &vr_d, 1, &d, 1);
    if (fmi3ExitInitializationMode(s) > fmi3Warning) return 1;
    const double pi = 3.14159265358979323846;
    fmi3Boolean event, terminate, early;
    fmi3Float64 last;
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (long k = 0; k < steps; k++) {
        double t = k * h, te = (k + 1) * h;
        d = @MOTION@;
        fmi3SetFloat64(s, &vr_d, 1, &d, 1);
        if (fmi3DoStep(s, t, h, fmi3True, &event, &terminate, &early, &last) > fmi3Warning) return 1;
        fmi3GetFloat64(s, &vr_F, 1, &F, 1);
        force[k] = F;
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    printf("%.9f\n", (t1.tv_sec - t0.tv_sec) + 1e-9 * (t1.tv_nsec - t0.tv_nsec));
    FILE *out = fopen(argv[8], "wb");
    fwrite(force, sizeof(double), steps, out);
    fclose(out);
    fmi3Terminate(s);
    fmi3FreeInstance(s);
    return 0;
}
"""


def motion_c() -> str:
    """The golden input at te as a C expression."""
    return " + ".join(f"{a!r} * sin(2.0 * pi * {f!r} * te)" for a, f in WAVES)


def motion(te: float) -> float:
    """The same in Python (same libm sin, same order of operations)."""
    d = 0.0
    for k, (a, f) in enumerate(WAVES):
        term = a * math.sin(2.0 * math.pi * f * te)
        d = term if k == 0 else d + term
    return d


def python_loop(fmu_path: str, steps: int, h: float) -> tuple[float, np.ndarray]:
    """(wall [s], F per step) of a low-level FMPy loop."""
    from fmpy import extract, read_model_description
    from fmpy.fmi3 import FMU3Slave

    md = read_model_description(fmu_path)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    with tempfile.TemporaryDirectory(prefix="bench_fmu-") as tmp:
        fmu = FMU3Slave(guid=md.guid, unzipDirectory=extract(fmu_path, tmp),
                        modelIdentifier=md.coSimulation.modelIdentifier, instanceName="bench")
        fmu.instantiate()
        fmu.enterInitializationMode(startTime=0.0)
        fmu.setFloat64([vr["d"]], [0.0])
        fmu.exitInitializationMode()
        d_vr, F_vr = [vr["d"]], [vr["F"]]
        F = np.empty(steps)
        t0 = time.perf_counter()
        for k in range(steps):
            fmu.setFloat64(d_vr, [motion((k + 1) * h)])
            fmu.doStep(k * h, h)
            F[k] = fmu.getFloat64(F_vr)[0]
        wall = time.perf_counter() - t0
        fmu.terminate()
        fmu.freeInstance()
    return wall, F


def c_loop(fmu_path: str, steps: int, h: float, work: Path) -> tuple[float, np.ndarray]:
    """(wall [s] of the stepping loop, F per step) of the C driver."""
    import fmpy
    from fmpy import extract, read_model_description

    driver = work / "driver"
    if not driver.exists():
        (work / "driver.c").write_text(DRIVER.replace("@MOTION@", motion_c()))
        include = Path(fmpy.__file__).parent / "c-code"
        subprocess.run(["gcc", "-O2", "-o", str(driver), str(work / "driver.c"), f"-I{include}", "-ldl", "-lm"],
                       check=True)
    md = read_model_description(fmu_path)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    unzipdir = Path(extract(fmu_path, str(work / Path(fmu_path).stem)))
    lib = unzipdir / "binaries" / "x86_64-linux" / f"{md.coSimulation.modelIdentifier}.so"
    out = work / "force.bin"
    res = subprocess.run([str(driver), str(lib), md.guid, (unzipdir / "resources").as_uri() + "/", str(steps),
                          repr(h), str(vr["d"]), str(vr["F"]), str(out)], capture_output=True, text=True)
    if res.returncode != 0:
        raise RuntimeError(f"C driver failed: {res.stderr.strip()}")
    return float(res.stdout.split()[0]), np.fromfile(out, dtype=float)


def fmu_speed(args) -> None:
    from fvd_bridge.calibration import Calibration
    from fvd_bridge.export.fmu import build_fmu, substeps_of
    from fvd_bridge.golden import REFERENCE
    from fvd_bridge.catalog import parse_model

    n_sub = substeps_of(args.h, args.h_max)
    print(f"damper FMU, communication step h = {args.h:g} s, h_max = {args.h_max:g} s: {n_sub} sub-steps per "
          f"step; golden input (20 mm at 1 Hz + 5 mm at 5 Hz), d only\n")
    print(f"{'law':>4} {'Python steps/s':>15} {'[us/step]':>10} {'C steps/s':>12} {'[us/step]':>10} "
          f"{'sub-steps/s (C)':>16} {'same F':>7}")
    with tempfile.TemporaryDirectory(prefix="bench_fmu-") as tmp:
        work = Path(tmp)
        for law in LAWS:
            model = parse_model(str(law))
            path = str(work / f"law{law}.fmu")
            build_fmu(Calibration(model, np.array(REFERENCE[law], dtype=float), of=0.0), path, h_max=args.h_max)
            wall_py, F_py = python_loop(path, args.steps, args.h)
            c_steps = 10 * args.steps
            wall_c, F_c = c_loop(path, c_steps, args.h, work)
            same = bool(np.array_equal(F_py, F_c[:args.steps]))
            py_rate, c_rate = args.steps / wall_py, c_steps / wall_c
            print(f"{law:>4} {py_rate:15,.0f} {1e6 / py_rate:10.2f} {c_rate:12,.0f} {1e6 / c_rate:10.2f} "
                  f"{c_rate * n_sub:16,.0f} {'yes' if same else 'NO':>7}")


def examples(args) -> None:
    if not RECORD.is_file():
        print(f"\nco-simulation examples: {RECORD} is absent; skipped")
        return
    span = f"the first {args.duration:g} s of El Centro 1940 NS" if args.duration else "El Centro 1940 NS (53.7 s)"
    print(f"\nco-simulation examples on {span}, h = 5 ms (wall time, FMU builds included):")
    for script in ("fmu_cosim.py", "opensees_fmu_cosim.py"):
        with tempfile.TemporaryDirectory(prefix="bench_cosim-") as out:
            cmd = [sys.executable, str(REPO / "examples" / script), "--out", out]
            if args.duration:
                cmd += ["--duration", str(args.duration)]
            t0 = time.perf_counter()
            res = subprocess.run(cmd, capture_output=True, text=True)
            wall = time.perf_counter() - t0
            if res.returncode != 0:
                print(f"  {script}: failed ({res.stderr.strip().splitlines()[-1:]})")
                continue
            summary = json.loads((Path(out) / "summary.json").read_text())
        if script == "fmu_cosim.py":
            parts = "; ".join(
                f"law {law}: OpenSees {r['opensees']['wall_s']:.2f} s, explicit {r['explicit']['wall_s']:.2f} s, "
                f"iterative {r['iterative']['wall_s']:.2f} s "
                f"({r['iterative']['fmu_steps_per_step']:.1f} FMU steps/step)"
                for law, r in summary["laws"].items())
            print(f"  {script} (SDOF, {summary['steps']} steps): {wall:.1f} s in all; {parts}")
        else:
            it, ex = summary["iterative"], summary["explicit"]
            print(f"  {script} (3-story frame, law {summary['law']}, {it['steps']} steps): {wall:.1f} s in all; "
                  f"native run_frame {summary['native']['wall_s']:.1f} s, explicit {ex['wall_s']:.1f} s, "
                  f"iterative {it['wall_s']:.1f} s ({it['opensees_solves_per_step']:.2f} OpenSees solves, "
                  f"{it['fmu_steps_per_damper_step']:.1f} FMU steps per damper per step)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--h", type=float, default=0.01, help="communication step [s] (default 0.01)")
    ap.add_argument("--h-max", type=float, default=0.001, help="the FMU's largest sub-step [s] (default 0.001)")
    ap.add_argument("--steps", type=int, default=20000, help="Python steps (the C driver runs 10x as many)")
    ap.add_argument("--duration", type=float, help="examples: the first S seconds of the record (default all)")
    ap.add_argument("--no-examples", action="store_true")
    args = ap.parse_args()
    if shutil.which("cmake") is None or shutil.which("gcc") is None:
        print("bench_fmu: building the FMU and the driver needs cmake and gcc; skipped")
        return
    fmu_speed(args)
    if not args.no_examples:
        examples(args)


if __name__ == "__main__":
    main()
