"""``fvd-bridge demo``: the paper's whole procedure on the embedded virtual series.

Five virtual 300 kN devices (fvd_bridge.rig.demo_series) are tested with the
paper's protocol (10 cycles of 40 mm at 0.5 m/s); the records are written as
lab-like CSVs, read back, and all nine laws are calibrated on every device
with 20 runs each (default optimizer), then summarised as in Table A.7 and
Fig. 14.  ``--quick`` keeps the 20 runs with a smaller optimizer population
(DE 8 per parameter, 60 generations, then the polish).

The laws' kernels are compiled (or loaded from numba's cache) first, in the
pool's workers side by side (``laws.catalog.kernel_tasks``): each worker
compiles some and loads the others, where each would otherwise compile every
one at the same time as the other.
"""

from __future__ import annotations

import os
import sys
import time

from .. import timing
from ..campaign.engine import warm_kernels
from ..campaign.executors import Processes
from ..campaign.outputs import write_outputs
from ..text.campaign import format_report
from ..campaign.runner import CampaignSettings, book_fit_times, run_campaign
from ..fit import DEFAULT_OPTIMIZER, OPTIMIZERS
from ..io.staging import check_output, removed_on_failure
from ..laws import PAPER_LAWS
from ..records import read_record
from ..rig import DEMO_NOISE, Noise, demo_series, paper, write_series

QUICK = {"pop": 8, "gens": 60}


def add_parser(sub):
    p = sub.add_parser("demo", help="calibrate the nine laws on the embedded 5-device virtual series",
                       description="The paper's whole procedure on five embedded virtual 300 kN devices: "
                                   "simulate the paper's test, write lab-like CSVs, read them back, calibrate "
                                   "the nine laws (20 runs each), print Table A.7, beta and the Pareto set, "
                                   "and write every output and figure into --out.")
    p.add_argument("--out", default="demo_out", help="output directory (default demo_out)")
    p.add_argument("--quick", action="store_true", help="small optimizer settings (DE population 8 per parameter, 60 generations)")
    p.add_argument("--runs", type=int, help="runs per device and law (default 20; after the first 2, only "
                                            "where those disagree)")
    p.add_argument("--all-runs", action="store_true", help="make every run, as the paper's Table A.7 does")
    p.add_argument("--optimizer", default=DEFAULT_OPTIMIZER, choices=OPTIMIZERS)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--jobs", type=int, default=0, help="processes (default: one per core)")
    p.add_argument("--no-figures", action="store_true")
    p.add_argument("--profile", action="store_true", help="print where the time went (time per stage)")
    p.set_defaults(func=run)


def run(args) -> int:
    """The demo, all or nothing: a new --out is removed when a step fails (the records are written first)."""
    check_output(args.out, "dir", "--out")  # before any work: a bad path is one line, exit 2
    with removed_on_failure(args.out):
        return _run(args)


def _run(args) -> int:
    start = time.perf_counter()
    rec_dir = os.path.join(args.out, "records")
    devices = demo_series(seed=args.seed)
    paths = write_series(rec_dir, devices, paper(), Noise(**DEMO_NOISE), seed=args.seed)[:-1]
    records = [read_record(p) for p in paths]
    quick = args.quick
    cs = CampaignSettings(specs=tuple(law.key for law in PAPER_LAWS),
                          runs=args.runs or 20, optimizer=args.optimizer,
                          seed=args.seed, pop=QUICK["pop"] if quick else None,
                          gens=QUICK["gens"] if quick else None, jobs=args.jobs, all_runs=args.all_runs)
    mode = ("QUICK settings (--quick: small optimizer population and generations; `fvd-bridge demo` "
            "without --quick runs the full settings)" if quick
            else f"full settings ({cs.runs} runs asked{', all made' if cs.all_runs else ''}, default optimizer "
                 f"settings)")
    print(f"demo: {len(records)} virtual devices, paper protocol (10 cycles, 40 mm, 0.5 m/s), records in "
          f"{rec_dir}/; {len(cs.specs)} laws x {len(records)} devices x {cs.runs} runs, optimizer {cs.optimizer}, {mode}",
          file=sys.stderr)
    with Processes(cs.jobs) as executor:  # one pool for the kernels, the fits and the figures
        warm_kernels(executor, cs)
        with timing.stage("fits"):
            results = run_campaign(records, cs, executor=executor)
        book_fit_times(results)
        with timing.stage("outputs, figures"):
            summary = write_outputs(args.out, records, results, cs, figures=not args.no_figures, executor=executor)
    print(format_report(summary))
    print(f"\ndemo ran with {mode} in {time.perf_counter() - start:.0f} s; outputs in {args.out}/ "
          f"(true device parameters in {rec_dir}/truth.yaml)")
    return 0
