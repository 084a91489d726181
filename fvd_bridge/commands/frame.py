"""``fvd-bridge frame``: calibrated dampers in a steel frame under a real earthquake record."""

from __future__ import annotations

import argparse
import glob
import os
import sys
import tempfile

from .. import timing
from ..calibration import Calibration
from ..catalog import catalog
from ..errors import InputError
from ..records import read_record
from ..records.motions import read_motion
from ..export.opensees_check import quiet_opensees
from ..io.staging import check_output
from .common import add_plugin_option, add_test_option

BUILDINGS = ("3-story", "9-story")
#: --duration keeping less than this share of the record's energy (Arias intensity) is warned about
KEEP_WARN = 0.9


def add_parser(sub):
    p = sub.add_parser(
        "frame", help="compare calibrated dampers (laws, series) in a 3- or 9-story frame under an earthquake",
        description="Put each calibrated damper (PARAMS.yaml files, or calibrate output folders: every "
                    "params/*/*.yaml) in every story of a SAC LA benchmark steel frame (OpenSees, through the "
                    "OpenSees export), run a ground-motion record, and compare peak and residual drift, floor "
                    "acceleration, damper force, stroke and energy with the bare frame; over the devices of "
                    "a series, the spread per model; ends with the simplest model as good as the best-fitting "
                    "(ranked on the same data only: models fitted to different tests are ranked on a common "
                    "test record, --rank-on or one all were fitted on, or not at all).")
    p.add_argument("params", nargs="*", metavar="PARAMS", help="calibration files or calibrate output folders")
    p.add_argument("--periods", action="store_true",
                   help="print the bare frame's first three periods and frequencies beside the benchmark's "
                        "and stop (no PARAMS or --record needed)")
    p.add_argument("--json", action="store_true", help="with --periods: one JSON line {\"periods\": [...], ...}")
    p.add_argument("--record", metavar="FILE",
                   help="ground motion: 2-column text t,a (g unless --units), USGS .smc, GeoNet .V2A, PEER .AT2; "
                        "or el-centro-1940, the 1940 El Centro NS record shipped with the package")
    p.add_argument("--component", help="V2A component (index or part of its name, e.g. N28W)")
    p.add_argument("--units", help="acceleration unit of a text record (default g; e.g. m/s^2, gal)")
    p.add_argument("--scale-pga", type=float, metavar="G", help="scale the record to this peak ground acceleration [g]")
    p.add_argument("--duration", type=float, metavar="S",
                   help="use only the first S seconds of the record (warned when it keeps less than "
                        f"{KEEP_WARN:.0%}% of the record's energy)")
    p.add_argument("--dampers-per-story", type=int, default=1, metavar="N",
                   help="dampers side by side in each story (default 1); forces are reported per damper")
    p.add_argument("--scale-force", type=float, default=1.0, metavar="S",
                   help="each damper is the calibrated device with its force times S (a larger device of the "
                        "series; default 1); its force limit scales with it")
    p.add_argument("--target-damping", type=float, metavar="XI",
                   help="size the dampers: each damper the calibrated device with its force times the one factor "
                        "(every story) that gives the first mode this supplemental damping ratio, e.g. 0.20 "
                        "(energy method, FEMA 274); prints each story's damper and the damping the frame "
                        "achieves (free-vibration decay)")
    p.add_argument("--design-drift", type=float, metavar="RATIO",
                   help="roof drift ratio the dampers are sized at and their damping estimated at, e.g. 0.01 "
                        "(default: the bare frame's peak under the record)")
    p.add_argument("--property-bounds", metavar="OUT|LMIN,LMAX",
                   help="also run each damper as its upper- and lower-bound device (ASCE 7's maximum and minimum "
                        "damper properties) and report the envelope of drift and damper force with the bound "
                        "that governs each: a campaign's or calibrate's output folder (or its bounds.json: each "
                        "model's factors on the force at the design velocity, the device first brought to the "
                        "series' nominal force) or two factors, e.g. 0.85,1.2")
    p.add_argument("--bounds", dest="property_bounds", action=OldBoundsOption, help=argparse.SUPPRESS)
    p.add_argument("--building", default="3-story", choices=BUILDINGS, help="frame (default 3-story)")
    p.add_argument("--laws", help="only these models, e.g. 2,9 or 2+friction (default all given)")
    p.add_argument("--rank-on", metavar="FILE",
                   help="a damper test record (t,d,F; its unit sidecar, else kN, mm, s) to rank the models on: "
                        "each model's OF on it (default: their own OFs when all were fitted to the same tests, "
                        "else a test all were fitted on; without one they are not ranked)")
    p.add_argument("--stroke-limit", type=float, metavar="MM",
                   help="damper stroke limit [mm] (default: the calibration record's peak displacement)")
    p.add_argument("--force-limit", type=float, metavar="KN",
                   help="damper force limit [kN] (default: the calibration record's peak force)")
    p.add_argument("--out", default=os.path.join("results", "frame"), metavar="DIR",
                   help="output folder (default results/frame)")
    p.add_argument("--no-figures", action="store_true", help="write no figures")
    p.add_argument("--quiet", action="store_true", help="no progress lines")
    p.add_argument("--profile", action="store_true", help="print where the time went (time per analysis)")
    add_test_option(p)
    add_plugin_option(p)
    p.set_defaults(func=run)


class OldBoundsOption(argparse.Action):
    """``--bounds``, frame's old name of ``--property-bounds`` (``--bounds`` alone is calibrate's search
    box): still read, with a one-line note on stderr."""

    def __call__(self, parser, namespace, values, option_string=None):
        print("note: frame --bounds is now --property-bounds (--bounds is calibrate's search box); "
              "the old name still works", file=sys.stderr)
        setattr(namespace, self.dest, values)


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


def building_of(args):
    from ..frames import buildings

    return buildings.three_story() if args.building == "3-story" else buildings.nine_story()


def print_periods(args) -> int:
    """The bare frame's first three eigen periods beside the benchmark's."""
    import json

    import numpy as np

    from ..frames.model import frame_periods

    b = building_of(args)
    quiet_opensees()  # an eigen analysis: nothing to keep of OpenSees' messages
    T = frame_periods(b, len(b.reference_periods))
    ref = np.asarray(b.reference_periods)
    if args.json:
        print(json.dumps({"building": b.name, "periods": T.tolist(), "frequencies": (1.0 / T).tolist(),
                          "benchmark_periods": ref.tolist(), "benchmark_frequencies": (1.0 / ref).tolist(),
                          "source": b.source}))
        return 0
    print(f"{b.name}: bare frame's periods against the benchmark's ({b.source})")
    print(f"{'mode':>4}  {'period [s]':>10}  {'benchmark':>9}  {'frequency [Hz]':>14}  {'benchmark':>9}  {'f off':>6}")
    for k, (mine, theirs) in enumerate(zip(T, ref), start=1):
        print(f"{k:>4}  {mine:>10.4f}  {theirs:>9.4f}  {1 / mine:>14.4f}  {1 / theirs:>9.4f}  "
              f"{100 * (theirs / mine - 1):>+5.1f}%")
    return 0


def load_inputs(args):
    """Calibrations, building and ground motion, all checked before any analysis."""
    if not args.params:
        raise InputError("frame: give calibration files or calibrate output folders (PARAMS), or --periods")
    if not args.record:
        raise InputError("frame: --record FILE is required (a ground motion), except with --periods")
    for name in ("scale_pga", "duration", "stroke_limit", "force_limit", "scale_force", "target_damping",
                 "design_drift"):
        value = getattr(args, name)
        if value is not None and not value > 0:
            raise InputError(f"--{name.replace('_', '-')} {value}: must be > 0")
    if args.target_damping is not None and args.scale_force != 1.0:
        raise InputError(f"--target-damping {args.target_damping:g} sizes the dampers: leave out --scale-force "
                         f"{args.scale_force:g}")
    if args.target_damping is not None and args.target_damping >= 1.0:
        raise InputError(f"--target-damping {args.target_damping:g}: a damping ratio below 1 (0.20 is 20%)")
    if args.dampers_per_story < 1:
        raise InputError(f"--dampers-per-story {args.dampers_per_story}: must be at least 1")
    cals = [Calibration.load(f, plugins=args.plugin) for f in calibration_files(args.params)]
    if args.laws:
        wanted = {catalog(args.plugin).model(s.strip()).spec for s in args.laws.split(",")}
        cals = [c for c in cals if c.spec in wanted]
        if not cals:
            raise InputError(f"--laws {args.laws}: none of the calibration files holds these models")
    cals = [cal.for_test(args.test if cal.per_test else None) for cal in cals]  # per test: --test's
    if args.property_bounds is not None:
        from ..frames.property_bounds import read_bounds

        args.property_bounds_read = read_bounds(args.property_bounds)
        for cal in cals:
            args.property_bounds_read.factors(cal.spec)  # every model has factors: refused before any analysis
    motion = read_motion(args.record, component=args.component, units=args.units)
    if args.duration:
        whole = motion
        motion = motion.window(args.duration)
        kept = motion.arias() / whole.arias() if whole.arias() > 0 else 1.0
        motion.source["energy_kept"] = kept
        if kept < KEEP_WARN:
            t5, t95 = whole.strong_motion()
            print(f"warning: --duration {args.duration:g} keeps {kept:.1%} of the record's energy (Arias "
                  f"intensity); its strong motion (5-95%) lies at {t5:.1f}-{t95:.1f} s of {whole.duration:.1f} s",
                  file=sys.stderr)
    if args.scale_pga:
        motion = motion.scaled_to_pga(args.scale_pga)
    return cals, building_of(args), motion, (read_record(args.rank_on) if args.rank_on else None)


def sizing_command(args, target: float = 0.20) -> str:
    """The command line that runs this analysis again with dampers sized for ``target``."""
    import shlex

    words = ["fvd-bridge", "frame", *args.params, "--record", args.record]
    for name in ("component", "units", "scale_pga", "duration", "rank_on", "laws", "design_drift",
                 "property_bounds", "test"):
        if getattr(args, name) is not None:
            words += [f"--{name.replace('_', '-')}", f"{getattr(args, name):g}" if isinstance(getattr(args, name), float)
                      else str(getattr(args, name))]
    if args.building != "3-story":
        words += ["--building", args.building]
    if args.dampers_per_story != 1:
        words += ["--dampers-per-story", str(args.dampers_per_story)]
    for plugin in args.plugin or ():
        words += ["--plugin", plugin]
    return shlex.join(words + ["--target-damping", f"{target:g}", "--out", args.out.rstrip("/") + "_sized"])


def run(args) -> int:
    from ..frames.compare import run_cases
    from ..frames.outputs import write_frame_outputs
    from ..text.frames import format_frame_table

    if args.periods:
        return print_periods(args)
    check_output(args.out, "dir", "--out")  # before any work: a bad path is one line, exit 2
    cals, building, motion, rank_on = load_inputs(args)
    log = tempfile.NamedTemporaryFile(prefix="fvd_bridge_opensees_", suffix=".log", delete=False)
    log.close()
    quiet_opensees(log.name)

    def progress(msg):
        if not args.quiet:
            print(msg, file=sys.stderr, flush=True)

    progress(f"frame: {building.name}, {motion.name} ({motion.duration:.1f} s, PGA {motion.pga_g:.3g} g); "
             f"{len(cals)} damper model(s) + the bare frame")
    dampers = f"{args.dampers_per_story} damper(s) per story" + (
        f", each the device x{args.scale_force:g} in force" if args.scale_force != 1.0 else "")
    progress(f"dampers: {dampers}; forces per damper")
    bounds = getattr(args, "property_bounds_read", None)
    if bounds is not None:
        progress(f"property bounds: {bounds.source}: each damper as nominal, upper- and lower-bound device")
    try:
        with timing.stage("frame analyses"):
            cases = run_cases(building, motion, cals, stroke_limit=args.stroke_limit, force_limit=args.force_limit, progress=progress,
                              per_story=args.dampers_per_story, scale=args.scale_force, rank_on=rank_on,
                              target_damping=args.target_damping, design_drift=args.design_drift,
                              bounds=bounds)
        settings = {"dampers_per_story": args.dampers_per_story, "scale_force": args.scale_force,
                    "energy_kept": motion.source.get("energy_kept", 1.0), "target_damping": args.target_damping,
                    "design_drift": args.design_drift, "sizing_command": sizing_command(args),
                    "bounds": args.property_bounds}
        with timing.stage("outputs, figures"):
            summary = write_frame_outputs(args.out, building, motion, cases, figures=not args.no_figures,
                                          settings=settings, log=log.name, bounds=bounds)
    finally:
        os.unlink(log.name)
    print(format_frame_table(cases, summary["series"], summary["verdict_lines"], summary["answer"]))
    print(f"\nwrote {args.out}/ (frame_table.csv, frame_series.csv, frame_summary.json, histories/"
          f"{', figures/' if not args.no_figures else ''})")
    return 0
