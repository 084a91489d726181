"""The one calibration engine: ``fvd-bridge calibrate``, ``fvd-bridge
campaign`` and ``fb.calibrate`` all run their fits and intervals here
(and the first and last the Calibration), so they give the same numbers
by construction."""

from __future__ import annotations

from .. import timing
from ..calibration import Calibration
from .executors import Serial
from .outputs import calibration, summarize
from .runner import CampaignSettings, book_fit_times, run_campaign, run_intervals


def run_calibrations(records, cs: CampaignSettings, executor=None, progress: bool = True,
                     fits_executor=None) -> tuple[dict, dict]:
    """(runs, intervals) of every (device, model) of ``cs``: the runs
    (``run_campaign``: {(device, spec): [FitResult]}) and the best run's
    intervals (``run_intervals``: {(device, spec): Intervals}).
    ``fits_executor``: runs the fits instead of ``executor`` and shows its
    own progress (a campaign's ``Resumable``: fits read back from its store)."""
    with timing.stage("fits"):
        results = run_campaign(records, cs, progress and fits_executor is None, fits_executor or executor)
    book_fit_times(results)
    with timing.stage("intervals"):
        intervals = run_intervals(records, results, cs, executor, progress)
    return results, intervals


def calibrate_one(record, cs: CampaignSettings, executor=None, progress: bool = False) -> Calibration:
    """The Calibration of ``cs``'s one model on one Record or Device, as
    ``fvd-bridge calibrate`` writes it (default: in this process)."""
    results, intervals = run_calibrations([record], cs, executor or Serial(), progress)
    spec = cs.specs[0]
    summary = summarize([record], results, cs)
    return calibration(record, 0, spec, summary["models"][spec], cs, intervals.get((record.name, spec)))
