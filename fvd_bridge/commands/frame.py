"""``fvd-bridge frame``: calibrated dampers in a steel frame under a real earthquake record."""

from __future__ import annotations

import glob
import os
import sys

from ..calibration import Calibration
from ..catalog import catalog
from ..errors import InputError
from ..records.motions import read_motion
from .common import quiet_opensees

BUILDINGS = ("3-story", "9-story")


def add_parser(sub):
    p = sub.add_parser(
        "frame", help="compare calibrated dampers (laws, series) in a 3- or 9-story frame under an earthquake",
        description="Put each calibrated damper (PARAMS.yaml files, or calibrate output folders: every "
                    "params/*/*.yaml) in every story of a SAC LA benchmark steel frame (OpenSees, through the "
                    "OpenSees export), run a ground-motion record, and compare peak and residual drift, floor "
                    "acceleration, damper force, stroke and energy with the bare frame; over the devices of "
                    "a series, the spread per model; ends with the simplest model as good as the best-fitting.")
    p.add_argument("params", nargs="+", metavar="PARAMS", help="calibration files or calibrate output folders")
    p.add_argument("--record", required=True, metavar="FILE",
                   help="ground motion: 2-column text t,a (g unless --units), USGS .smc, GeoNet .V2A, PEER .AT2")
    p.add_argument("--component", help="V2A component (index or part of its name, e.g. N28W)")
    p.add_argument("--units", help="acceleration unit of a text record (default g; e.g. m/s^2, gal)")
    p.add_argument("--scale-pga", type=float, metavar="G", help="scale the record to this peak ground acceleration [g]")
    p.add_argument("--duration", type=float, metavar="S", help="use only the first S seconds of the record")
    p.add_argument("--building", default="3-story", choices=BUILDINGS, help="frame (default 3-story)")
    p.add_argument("--laws", help="only these models, e.g. 2,9 or 2+friction (default all given)")
    p.add_argument("--stroke-limit", type=float, metavar="MM",
                   help="damper stroke limit [mm] (default: the calibration record's peak displacement)")
    p.add_argument("--force-limit", type=float, metavar="KN",
                   help="damper force limit [kN] (default: the calibration record's peak force)")
    p.add_argument("--out", default=os.path.join("results", "frame"), metavar="DIR",
                   help="output folder (default results/frame)")
    p.add_argument("--no-figures", action="store_true", help="write no figures")
    p.add_argument("--quiet", action="store_true", help="no progress lines")
    p.set_defaults(func=run)


def calibration_files(paths) -> list[str]:
    """PARAMS arguments -> calibration files (a folder: its params/*/*.yaml or */*.yaml)."""
    files = []
    for path in paths:
        if os.path.isdir(path):
            found = sorted(glob.glob(os.path.join(path, "params", "*", "*.yaml"))) or \
                sorted(glob.glob(os.path.join(path, "*", "*.yaml"))) or sorted(glob.glob(os.path.join(path, "*.yaml")))
            if not found:
                raise InputError(f"{path}: no calibration files (expected params/<device>/law<SPEC>.yaml)")
            files += found
        elif os.path.isfile(path):
            files.append(path)
        else:
            raise InputError(f"{path}: no such file or folder")
    return files


def load_inputs(args):
    """Calibrations, building and ground motion, all checked before any analysis."""
    from ..frames import buildings

    for name in ("scale_pga", "duration", "stroke_limit", "force_limit"):
        value = getattr(args, name)
        if value is not None and not value > 0:
            raise InputError(f"--{name.replace('_', '-')} {value}: must be > 0")
    cals = [Calibration.load(f) for f in calibration_files(args.params)]
    if args.laws:
        wanted = {catalog().model(s.strip()).spec for s in args.laws.split(",")}
        cals = [c for c in cals if c.spec in wanted]
        if not cals:
            raise InputError(f"--laws {args.laws}: none of the calibration files holds these models")
    motion = read_motion(args.record, component=args.component, units=args.units)
    if args.duration:
        motion = motion.window(args.duration)
    if args.scale_pga:
        motion = motion.scaled_to_pga(args.scale_pga)
    building = buildings.three_story() if args.building == "3-story" else buildings.nine_story()
    return cals, building, motion


def run(args) -> int:
    from ..frames.compare import run_cases
    from ..frames.outputs import format_frame_table, write_frame_outputs

    cals, building, motion = load_inputs(args)
    quiet_opensees()

    def progress(msg):
        if not args.quiet:
            print(msg, file=sys.stderr, flush=True)

    progress(f"frame: {building.name}, {motion.name} ({motion.duration:.1f} s, PGA {motion.pga_g:.3g} g); "
             f"{len(cals)} damper model(s) + the bare frame")
    cases = run_cases(building, motion, cals, args.stroke_limit, args.force_limit, progress=progress)
    summary = write_frame_outputs(args.out, building, motion, cases, figures=not args.no_figures)
    print(format_frame_table(cases, summary["series"], summary["verdict"]))
    print(f"\nwrote {args.out}/ (frame_table.csv, frame_series.csv, frame_summary.json, histories/"
          f"{', figures/' if not args.no_figures else ''})")
    return 0
