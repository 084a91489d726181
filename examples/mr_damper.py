"""Calibrate all nine laws on a real damper test and look at the loops.

The record is a magnetorheological damper at 0 V (passive) on a shaking
table, 100 Hz, from ../shared/devices (labcontrol-data/mr-damper, MIT):
variable x_F holds position [mm], velocity [mm/s] and force [N].

    python examples/mr_damper.py [--out DIR] [--runs N] [--quick]

Writes the calibrated parameter files, Table A.7 and the figures (loops per
law in DIR/figures/loops_*.png) and prints the summary.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from fvd_bridge.campaign.outputs import write_outputs
from fvd_bridge.text.campaign import format_report
from fvd_bridge.campaign.runner import CampaignSettings, run_campaign
from fvd_bridge.records import ReadOptions, read_record

RECORD = Path(__file__).resolve().parents[1] / ".." / "shared" / "devices" / "labcontrol_mrdamper_4.1_0V.mat"
MAPPING = ReadOptions(mat_var="x_F", columns={"d": "0", "F": "2"}, units={"F": "N"}, dt=0.01)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="mr_damper_out")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--quick", action="store_true", help="small optimizer settings (for tests)")
    args = ap.parse_args(argv)
    if not RECORD.is_file():
        print(f"{RECORD} is absent: this example needs the shared MR-damper records", file=sys.stderr)
        return 0
    record = read_record(str(RECORD.resolve()), MAPPING, name="mr_damper_0V")
    cs = CampaignSettings(specs=tuple(str(k) for k in range(1, 10)), runs=args.runs,
                          pop=8 if args.quick else None, gens=60 if args.quick else None)
    results = run_campaign([record], cs)
    summary = write_outputs(args.out, [record], results, cs)
    print(format_report(summary))
    best = min(summary["models"], key=lambda s: summary["models"][s]["of_overall"])
    print(f"\nbest law on this MR damper: law {best} (OF {summary['models'][best]['of_overall']:.4f}); "
          f"loops in {args.out}/figures/")
    return 0


if __name__ == "__main__":
    sys.exit(main())
