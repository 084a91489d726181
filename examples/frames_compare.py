"""How much does the choice of damper law, and the scatter of a production
series, change a building's response to a real earthquake?

A production series of virtual 300 kN fluid-viscous dampers (orifice
C sign(v)|v|^0.3 with a compressible oil column, seal friction and
manufacturing scatter) is tested on the virtual rig with the paper's
protocol; laws 1 (linear dashpot), 2 (power-law dashpot), 7 with beta = 1
(Maxwell: dashpot behind a spring, OpenSees ViscousDamper) and 9 (LuGre +
viscous) are calibrated on every device; every calibrated damper goes into
each story of the SAC LA 3-story steel frame, which is shaken by El Centro
1940 NS (../shared/records), and compared with the bare frame.

    python examples/frames_compare.py [--out DIR] [--devices N] [--duration S] [--quick]

Prints the comparison table, the series spread and the verdict; writes the
frame outputs (tables, damper deformation histories a lab can replay,
figures) into DIR/frame/.  Needs ../shared/records (exits 0 with a note
when it is absent).
"""

from __future__ import annotations

import argparse
import os
import sys
from dataclasses import replace
from pathlib import Path

RECORD = Path(__file__).resolve().parents[1] / ".." / "shared" / "records" / "elcentro_1940_NS_2688pts_g_dt0.02.dat"
LAWS = ("1", "2", "7", "9")


def maxwell_calibration(rec, model, seed, quick: bool):
    """Law 7 with beta held at 1 (a linear spring behind the power-law dashpot)."""
    from fvd_bridge.calibration import Calibration
    from fvd_bridge.fit import DEFAULT_OPTIMIZER, fit_model, objective, settings_for

    settings = settings_for(DEFAULT_OPTIMIZER, 8 if quick else None, 60 if quick else None)
    fit = fit_model(model, rec, seed=seed, settings=settings, overrides={"beta": (1.0, 1.0 + 1e-12)})
    fit.values[3] = 1.0
    fit = replace(fit, of=float(objective(rec.F, model.force(rec, fit.values[None, :])[0], rec.t)))
    return Calibration.from_fit(model, fit, rec, {"note": "law 7 with beta held at 1 (Maxwell)"})


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="frames_out")
    ap.add_argument("--devices", type=int, default=3, help="devices in the production series (default 3)")
    ap.add_argument("--duration", type=float, help="use the first S seconds of the record (default all)")
    ap.add_argument("--quick", action="store_true", help="small optimizer settings (a quick look)")
    args = ap.parse_args(argv)
    if not RECORD.is_file():
        print(f"frames_compare: {RECORD} is absent; nothing to do")
        return 0

    from fvd_bridge import calibrate, parse_model, read_record
    from fvd_bridge.frames.buildings import three_story
    from fvd_bridge.frames.compare import run_cases
    from fvd_bridge.records.motions import read_motion
    from fvd_bridge.frames.outputs import write_frame_outputs
    from fvd_bridge.text.frames import format_frame_table
    from fvd_bridge.rig import VirtualDamper, Noise, paper, production_series, write_series

    nominal = VirtualDamper(C=45.4, alpha=0.3, Ks=150.0, friction=3.0)
    devices = production_series(args.devices, nominal, {"C": 0.05, "alpha": 0.03, "Ks": 0.1}, seed=7,
                                prefix="fvd")
    paths = write_series(os.path.join(args.out, "records"), devices, paper(cycles=3 if args.quick else 10),
                         Noise(force=1.0, displacement=0.005), seed=7)[:-1]
    calibrations = []
    for path in paths:
        rec = read_record(path)
        for spec in LAWS:
            model = parse_model(spec)
            if spec == "7":  # the Maxwell model (beta = 1) that OpenSees' ViscousDamper solves
                cal = maxwell_calibration(rec, model, seed=[7, len(calibrations)], quick=args.quick)
            else:
                cal = calibrate(rec, model, runs=1, seed=7, pop=8 if args.quick else None,
                                gens=60 if args.quick else None)
            calibrations.append(cal)
            print(f"{rec.name}: law {spec} OF {cal.of:.4f}", file=sys.stderr)
    motion = read_motion(RECORD)
    if args.duration:
        motion = motion.window(args.duration)
    building = three_story()
    cases = run_cases(building, motion, calibrations, progress=lambda m: print(m, file=sys.stderr))
    summary = write_frame_outputs(os.path.join(args.out, "frame"), building, motion, cases)
    print(format_frame_table(cases, summary["series"], summary["verdict"]))
    print(f"\nwrote {args.out}/frame/ ({len(cases)} analyses)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
