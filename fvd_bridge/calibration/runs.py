"""The seeded runs of a calibration and their intervals, for one (device,
model) or every one of a campaign: ``fit_runs`` and ``fit_intervals``.

Each (device, model)'s runs are ``FittedRuns``: the fits in the order made
(the runs asked, then the wider search's rounds).  Work goes out as Tasks
(``calibration.tasks``) through an executor (``run(fn, items)`` yielding
(item, result) in any order; None: this process, in order), so one
calibration and a campaign's hundreds run the same plan.
"""

from __future__ import annotations

from collections.abc import Sequence
from contextlib import nullcontext
from dataclasses import dataclass

import numpy as np

from ..fit.intervals import bootstrap_replicas, from_estimates, newton_refits
from ..fit.layout import Layout
from ..fit.local import L1_TOLERANCE, SAME_BASIN, WIDER
from ..fit.objective import NEAR_FLOOR
from ..fit.space import Space
from ..progress import bar as progress_bar
from ..records.device import as_device
from .news import Listener
from .tasks import is_wider, make_tasks, run_task, wider_task

#: runs made first of each model; the others only where these disagree
FIRST_RUNS = 2
#: replicas per refit task, at most: a calibration's replicates spread over the processes
REPLICAS_PER_TASK = 4


class InProcess:
    """Run every item here, in order (the executor of one calibration)."""

    def run(self, fn, items):
        for item in items:
            yield item, fn(*item)


class FittedRuns(Sequence):
    """The fits of one model on one device (FitResults), in the order made:
    the runs asked (``asked``), then the wider search's rounds."""

    def __init__(self, fits):
        self.fits = list(fits)

    def __getitem__(self, k):
        return self.fits[k]

    def __len__(self) -> int:
        return len(self.fits)

    def __repr__(self) -> str:
        return f"<FittedRuns {len(self.asked)} runs + {self.wider_runs} wider, best OF {self.best.of:.4g}>"

    @property
    def asked(self) -> list:
        """The runs asked for, in run order (their statistics are the run statistics)."""
        return [r for r in self.fits if not is_wider(r)]

    @property
    def wider_runs(self) -> int:
        """How many wider search rounds were made."""
        return len(self.fits) - len(self.asked)

    @property
    def best(self):
        """The fit with the lowest OF (the calibration)."""
        return min(self.fits, key=lambda r: r.of)

    @property
    def floor(self) -> float | None:
        """The record's noise floor OF the runs were judged by (None: not computed)."""
        return self.fits[0].floor

    def stats(self) -> dict:
        """{of_mean, of_sigma, p_mean, p_sigma}: over the runs asked."""
        P, OF = np.array([r.values for r in self.asked]), np.array([r.of for r in self.asked])
        return {"of_mean": float(OF.mean()), "of_sigma": float(OF.std()),
                "p_mean": P.mean(axis=0), "p_sigma": P.std(axis=0)}


def first_runs(request) -> int:
    """How many runs of each (device, model) are made before the agreement check."""
    return request.runs if request.all_runs or request.runs <= FIRST_RUNS else FIRST_RUNS


def repeat_each_other(runs) -> bool:
    """Runs that ended on one optimum: every OF within the local search's
    L1_TOLERANCE share of the best (how close its end is to eq. 18's
    optimum) and every parameter within SAME_BASIN of the best run's
    (unit-cube distance: the local search's own test of one basin)."""
    best = min(runs, key=lambda r: r.of)
    space = Space.of(best.bounds, best.log or None)
    at = space.position(np.asarray(best.values))
    return all(r.of <= best.of * (1.0 + L1_TOLERANCE)
               and np.max(np.abs(space.position(np.asarray(r.values)) - at), initial=0.0) <= SAME_BASIN
               for r in runs)


def far_above_floor(runs) -> bool:
    """Whether the best of ``runs`` ends beyond NEAR_FLOOR times the record's
    noise floor (the first run's ``floor``; False where it is not known)."""
    floor = runs[0].floor
    return floor is not None and floor > 0.0 and min(r.of for r in runs) > NEAR_FLOOR * floor


def fit_runs(records, requests, *, executor=None, progress: bool = False) -> dict:
    """Fit every request's model (FitRequests) to every record (Records or
    Devices) through ``executor`` (None: in this process): first
    ``first_runs`` runs of each, then the rest of the runs of the models
    whose first runs do not ``repeat_each_other`` on every device (all of
    them with ``all_runs``).  Where the first runs of the local search end
    far above the record's noise floor (NEAR_FLOOR times it), the search
    looks wider first (``_search_wider``), and a wider round that finds
    better makes the rest of the runs too.  The runs made are the first of
    the same seeded sequence all runs would be, so their statistics are
    those of its first runs (2 runs that agree bound the share of runs
    that would not only loosely: the robustness statistics over runs need
    ``all_runs``).

    Returns {(device name, spec): FittedRuns}.
    """
    executor = executor or InProcess()
    plan = _Plan(records, requests, executor, progress)
    plan.run()
    return {key: FittedRuns(fits) for key, fits in plan.results.items()}


class _Plan:
    """The waves of ``fit_runs``: the first runs, the wider rounds, the rest."""

    def __init__(self, records, requests, executor, progress):
        self.records, self.requests, self.executor = list(records), {q.spec: q for q in requests}, executor
        self.tasks = make_tasks(self.records, requests)
        self.results = {(rec.name, q.spec): [None] * q.runs for rec in self.records for q in requests}
        self.progress = progress

    def run(self) -> None:
        self.bar = progress_bar(len(self.tasks), self.progress, unit="fit")
        news = getattr(self.executor, "news", None) if self.progress else None  # a process pool's
        try:
            with Listener(news, self.bar.set_postfix_str) if news is not None else nullcontext():
                self._waves()
        finally:
            self.bar.close()

    def _waves(self) -> None:
        first = {spec: first_runs(q) for spec, q in self.requests.items()}
        self._run([t for t in self.tasks if t.run < first[t.spec]])
        extra = self._search_wider(first)
        gained = {key[1] for key, runs in extra.items()
                  if min(r.of for r in runs) < min(r.of for r in self.results[key][:first[key[1]]]) * (1 - L1_TOLERANCE)}
        settled = {spec for spec, q in self.requests.items() if first[spec] < q.runs and spec not in gained
                   and all(repeat_each_other(self.results[(rec.name, spec)][:first[spec]]) for rec in self.records)}
        for spec in settled:
            self.bar.total -= len(self.records) * (self.requests[spec].runs - first[spec])
            for rec in self.records:
                del self.results[(rec.name, spec)][first[spec]:]
        if settled:
            k = first[next(iter(settled))]
            self.bar.set_description(f"the first {k} runs of {', '.join(s for s in self.requests if s in settled)} "
                                     f"agree: not repeated")
        self._run([t for t in self.tasks if t.run >= first[t.spec] and t.spec not in settled])
        for key, runs in extra.items():
            self.results[key] += runs

    def _search_wider(self, first) -> dict:
        """{(device, spec): [FitResult]}: the wider search rounds
        (``fit.local.WIDER``: more points and starts, the last with the DE
        check) of the models whose first runs end far above the noise floor
        on a device.  Round 1 always, round 2 where round 1 lowered the OF
        and it is still far above: two runs that agree in one basin prove
        nothing when the OF is far above what the record's noise allows.
        Every device of such a model gets the round (the run statistics
        need as many runs on each).  Only for the local search (the paper's
        GA and DE are run as asked)."""
        made = {(t.device, t.spec): t for t in self.tasks if t.run == 0}
        extra = {key: [] for key in made}
        results, records = self.results, self.records
        todo = [spec for spec, q in self.requests.items() if q.local
                and any(far_above_floor(results[(rec.name, spec)][:first[spec]]) for rec in records)]
        for round_ in range(1, len(WIDER) + 1):
            if not todo:
                break
            wave = [wider_task(made[(rec.name, spec)], round_, self.requests[spec].runs + round_ - 1)
                    for spec in todo for rec in records]
            before = {key: min(r.of for r in results[key][:first[key[1]]] + extra[key]) for key in made}
            self.bar.total += len(wave)
            self.bar.set_description(f"wider search {round_}/{len(WIDER)} of {', '.join(todo)}: "
                                     f"far above the noise floor")
            for (task, _, _), res in self.executor.run(run_task, self._items(wave)):
                extra[(task.device, task.spec)].append(res)
                self.bar.update()
            todo = [spec for spec in todo
                    if any(extra[(rec.name, spec)][-1].of < before[(rec.name, spec)] * (1.0 - L1_TOLERANCE)
                           for rec in records)
                    and any(far_above_floor(results[(rec.name, spec)][:first[spec]] + extra[(rec.name, spec)])
                            for rec in records)]
        return {key: runs for key, runs in extra.items() if runs}

    def _items(self, tasks):
        return ((t, self.records[t.device_index], self.requests[t.spec]) for t in tasks)

    def _run(self, tasks) -> None:
        """Run ``tasks`` through the executor, each result into its place."""
        if not tasks:
            return
        for (task, _, _), res in self.executor.run(run_task, self._items(tasks)):
            runs = self.results[(task.device, task.spec)]
            runs[task.run] = res
            best = min(x.of for x in runs if x is not None)
            self.bar.set_description(f"law {task.spec} | {task.device} | run {task.run + 1}/{len(runs)} | "
                                     f"best OF {best:.4f}")
            self.bar.update()


@dataclass(frozen=True)
class RefitBatch:
    """Replicas ``first``, ``first`` + 1, ... of one (device, model)
    calibration ``key``: the replica records, the best run's parameters,
    the noise they were drawn with and the search bounds."""

    key: tuple
    first: int
    request: object  # FitRequest
    replicas: list
    params: np.ndarray
    noise: object
    bounds: np.ndarray


def refit_task(batch: RefitBatch):
    """The Newton refits (fit.intervals.newton_refits) of one RefitBatch: (estimates, OFs)."""
    q = batch.request
    layout = Layout(q.model, tuple(as_device(batch.replicas[0]).test_names), q.per_test, q.fits_zero)
    return newton_refits(q.model, layout, batch.replicas, batch.params, batch.noise, batch.bounds)


def fit_intervals(records, results: dict, requests, *, executor=None, progress: bool = False) -> dict:
    """{(device, spec): Intervals} of every calibration (the best run of
    each, ``results`` of ``fit_runs``) of the requests that ask for
    intervals, through ``executor`` (None: in this process).  The replicas
    are drawn here, in one random stream per calibration; their refits go
    out REPLICAS_PER_TASK at a time, so one calibration's replicates share
    the processes and the progress counts replicates.  The numbers are those
    of ``fit.intervals.intervals`` in one process."""
    executor = executor or InProcess()
    drawn, items = {}, []
    for rec in records:
        for q in (q for q in requests if q.intervals):
            key, best = (rec.name, q.spec), min(results[(rec.name, q.spec)], key=lambda r: r.of)
            layout, replicas, noise = bootstrap_replicas(q.model, rec, best.values, q.per_test, q.intervals,
                                                         seed=[q.seed, 7], force_zero=q.fits_zero)
            width = best.values.size + 2 * len(best.zero or {})  # the tests' force zero after the parameters
            drawn[key] = (q, layout, best, np.zeros((len(replicas), width)), np.zeros(len(replicas)))
            items += [(RefitBatch(key, b, q, replicas[b:b + REPLICAS_PER_TASK], best.values, noise, best.bounds),)
                      for b in range(0, len(replicas), REPLICAS_PER_TASK)]
    if not drawn:
        return {}
    replicates = sum(len(d[3]) for d in drawn.values())
    bar = progress_bar(replicates, progress, unit="replicate",
                       desc=f"intervals ({replicates // len(drawn)} replicates of {len(drawn)} calibration(s))")
    try:
        for (batch,), (estimates, ofs) in executor.run(refit_task, items):
            all_estimates, all_ofs = drawn[batch.key][3:]
            first = batch.first
            all_estimates[first:first + len(ofs)], all_ofs[first:first + len(ofs)] = estimates, ofs
            bar.update(len(ofs))
    finally:
        bar.close()
    return {key: from_estimates(q.model, layout, best.values, estimates, float(np.mean(ofs)), best.bounds,
                                best.of, best.zero, floor=results[key][0].floor)
            for key, (q, layout, best, estimates, ofs) in drawn.items()}
