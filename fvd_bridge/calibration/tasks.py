"""One unit of the runs: a (device, model, run) fit with its own seed.

A Task is plain data with a stable id, so that any executor (this process,
a local process pool, a Dask cluster, a resumable store) can ship it, run
it with ``run_task`` and key its result; the seed depends only on the
request's seed and the task's position (device, model among a campaign's,
run), never on the order or the process it runs in.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from ..fit import fit_model
from ..fit.floor import device_floor, device_force_floor
from ..fit.layout import Layout
from ..fit.local import wider
from ..fit.nested import nested_start
from ..fit.objective import NEAR_FLOOR
from ..records.device import as_device
from .news import reporter


@dataclass(frozen=True)
class Task:
    """Fit model ``spec`` (``spec_index`` in the campaign) to device ``device``
    (index ``device_index``), run number ``run``, with ``seed``; ``wider``:
    round k (1, 2, ...) of the wider search made after the runs where they
    end far above the record's noise floor (``fit.local.wider``; 0: a run)."""

    device_index: int
    device: str
    spec_index: int
    spec: str
    run: int
    seed: tuple
    wider: int = 0

    @property
    def id(self) -> str:
        """Stable, filename-safe id: 'device/law<spec>/run<k>' ('.../wider<k>' for a wider round)."""
        which = f"wider{self.wider}" if self.wider else f"run{self.run:04d}"
        return f"{self.device}/law{self.spec}/{which}"


def make_tasks(records, requests) -> list[Task]:
    """Every (device, model, run) of ``requests`` (FitRequests) on ``records``, in table order."""
    return [Task(i, rec.name, q.position, q.spec, r, (q.seed, i, q.position, r))
            for i, rec in enumerate(records) for q in requests for r in range(q.runs)]


#: a wider round's seed is (campaign seed, device, model, WIDER_SEED + round): never a run's
WIDER_SEED = 1_000_000


def is_wider(fit) -> bool:
    """Whether ``fit`` (a FitResult of ``run_task``) is a wider search round's, not a run's (its seed)."""
    seed = list(fit.seed) if isinstance(fit.seed, (list, tuple)) else [fit.seed]
    return len(seed) == 4 and seed[-1] >= WIDER_SEED


def wider_task(task: Task, round_: int, run: int) -> Task:
    """The wider search round ``round_`` of ``task``'s (device, model), the ``run``-th fit made of it."""
    return Task(task.device_index, task.device, task.spec_index, task.spec, run,
                (task.seed[0], task.device_index, task.spec_index, WIDER_SEED + round_), round_)


def run_task(task: Task, record, request):
    """Fit one task (a FitResult) on ``record`` (a Record or a Device) as
    ``request`` (a FitRequest) asks; its model is loaded once per process;
    a calibration the model extends is its start, else the start values
    (the data's start for the other parameters)."""
    model = request.model
    settings = request.settings
    if task.wider:
        settings = wider(settings, task.wider)
    per_test = request.per_test
    given = request.extends
    start = (nested_start(model, record, given.names, given.values, per_test) if given is not None
             else dict(request.start_values) or None)
    fit = fit_model(model, record, bounds=request.bounds, optimizer=request.optimizer, seed=list(task.seed),
                    settings=settings, overrides=request.overrides, per_test=per_test, start=start,
                    on_generation=reporter(task.id), force_zero=request.fits_zero)
    device = as_device(record)
    if task.run == 0 and not task.wider and fit.of > NEAR_FLOOR * device_force_floor(device):
        # the floor the runs are judged by (calibration.runs); within NEAR_FLOOR of the force
        # noise's floor alone (a lower bound) a fit is near it, and its propagation is not paid for
        layout = Layout(model, tuple(device.test_names), per_test)
        fit = replace(fit, floor=device_floor(model, layout, fit.values, device))
    if not task.wider:
        return fit
    return replace(fit, stop=f"wider search {task.wider} ({settings.samples} points, {settings.starts} starts"
                             f"{', DE check' if settings.always_check else ''}): {fit.stop}")
