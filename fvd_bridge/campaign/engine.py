"""A campaign's fits and intervals: every (device, model) of its settings
through the one calibration path (``calibration.runs``), timed by stage.
``fvd-bridge calibrate`` and ``fvd-bridge campaign`` run here;
``fb.calibrate`` runs the same path for one (``calibration.engine``), so
they give the same numbers by construction."""

from __future__ import annotations

from .. import timing
from ..laws.catalog import compile_kernel, kernel_tasks
from .executors import Processes
from .runner import CampaignSettings, book_fit_times, run_campaign, run_intervals


def warm_kernels(executor, cs: CampaignSettings) -> None:
    """In a local process pool: compile (or load) the laws' kernels of
    ``cs``'s models side by side in its workers (``laws.catalog.kernel_tasks``),
    not each worker all of them; any other executor: nothing."""
    if isinstance(executor, Processes):
        with timing.stage("kernels (compiled or loaded, side by side in the workers)"):
            for _ in executor.run(compile_kernel, kernel_tasks(sorted({cs.model(s).law.key for s in cs.specs}))):
                pass


def run_calibrations(records, cs: CampaignSettings, executor=None, progress: bool = True,
                     fits_executor=None) -> tuple[dict, dict]:
    """(runs, intervals) of every (device, model) of ``cs``: the runs
    (``run_campaign``: {(device, spec): FittedRuns}) and the best run's
    intervals (``run_intervals``: {(device, spec): Intervals}).
    ``fits_executor``: runs the fits instead of ``executor`` and shows its
    own progress (a campaign's ``Resumable``: fits read back from its store).
    A local process pool first compiles (or loads) the laws' kernels side
    by side in its workers (``laws.catalog.kernel_tasks``), not each worker all of them."""
    warm_kernels(executor, cs)
    with timing.stage("fits"):
        results = run_campaign(records, cs, progress and fits_executor is None, fits_executor or executor)
    book_fit_times(results)
    with timing.stage("intervals"):
        intervals = run_intervals(records, results, cs, executor, progress)
    return results, intervals
