"""One unit of a campaign: a (device, model, run) fit with its own seed.

A Task is plain data with a stable id, so that any executor (a local process
pool, a Dask cluster, a resumable store) can ship it, run it with
``run_task`` and key its result; the seed depends only on the campaign seed
and the task's position, never on the order or the process it runs in.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..fit import fit_model, settings_for
from ..fit.nested import nested_start
from .news import reporter


@dataclass(frozen=True)
class Task:
    """Fit model ``spec`` (``spec_index`` in the campaign) to device ``device``
    (index ``device_index``), run number ``run``, with ``seed``."""

    device_index: int
    device: str
    spec_index: int
    spec: str
    run: int
    seed: tuple

    @property
    def id(self) -> str:
        """Stable, filename-safe id: 'device/law<spec>/run<k>'."""
        return f"{self.device}/law{self.spec}/run{self.run:04d}"


def make_tasks(records, cs) -> list[Task]:
    """Every (device, model, run) of the campaign, in table order."""
    return [Task(i, rec.name, j, spec, r, (cs.seed, i, j, r))
            for i, rec in enumerate(records) for j, spec in enumerate(cs.specs) for r in range(cs.runs)]


def run_task(task: Task, record, cs):
    """Fit one task (a FitResult) on ``record`` (a Record or a Device); the
    model comes from the campaign's catalog, loaded once per process; a
    --start calibration the model extends is its start, else the
    --start-value values (the data's start for the other parameters)."""
    model = cs.catalog.model(task.spec)
    settings = settings_for(cs.optimizer, cs.pop, cs.gens, cs.stall)
    overrides = {n: b for n, b in cs.overrides_for(task.spec).items() if n in model.names}
    per_test = cs.per_test_for(task.spec)
    given = cs.start_for(task.spec)
    start = (nested_start(model, record, given[0], given[1], per_test) if given is not None
             else cs.start_values_for(task.spec) or None)
    return fit_model(model, record, bounds=cs.bounds, optimizer=cs.optimizer, seed=list(task.seed),
                     settings=settings, overrides=overrides, per_test=per_test, start=start,
                     on_generation=reporter(task.id), force_zero=cs.fits_zero)
