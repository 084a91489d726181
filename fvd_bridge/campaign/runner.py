"""Run every (device, model, run) fit of a campaign through an executor, with a progress bar."""

from __future__ import annotations

from contextlib import nullcontext
from dataclasses import asdict, dataclass, field

import numpy as np

from .. import timing
from ..catalog import catalog as load_catalog
from ..fit import DEFAULT_OPTIMIZER, settings_for
from ..fit.intervals import bootstrap_replicas, from_estimates, newton_refits
from ..fit.layout import Layout
from ..fit.local import L1_TOLERANCE, SAME_BASIN, WIDER
from ..fit.objective import NEAR_FLOOR
from ..fit.space import Space
from ..progress import bar as progress_bar
from ..records.device import as_device
from .executors import Processes
from .news import Listener
from .tasks import make_tasks, run_task, wider_task


@dataclass(frozen=True)
class CampaignSettings:
    """What a campaign runs: model specs, runs per (device, model), optimizer and its settings."""

    specs: tuple
    runs: int = 20
    bounds: str = "auto"
    optimizer: str = DEFAULT_OPTIMIZER
    seed: int = 0
    pop: int | None = None
    gens: int | None = None
    stall: int | None = None
    jobs: int = 0  # 0: one process per core
    plugins: tuple = field(default_factory=tuple)  # plugin file paths
    bound_overrides: tuple = field(default_factory=tuple)  # (spec or None, name, lower, upper)
    per_test: tuple = field(default_factory=tuple)  # (spec or None, name): parameters fitted per test
    start: tuple | None = None  # (spec, names, values) of a calibration file to start from
    start_values: tuple = field(default_factory=tuple)  # (spec or None, name, value): start values of some parameters
    intervals: int = 0  # bootstrap replicates of each calibration's parameter intervals (0: none)
    all_runs: bool = False  # make every run, also after the first ones agreed (``first_runs``)
    force_zero: str = "none"  # 'per-test': each test's force zero fitted beside the model (fit.zero; not exported)

    @property
    def catalog(self):
        """Laws and effects with this campaign's plugins (loaded once per process)."""
        return load_catalog(self.plugins)

    def model(self, spec: str):
        """The Model of one of the campaign's specs."""
        return self.catalog.model(spec)

    def overrides_for(self, spec: str) -> dict:
        """{name: (lower, upper)} of the --bound options that apply to ``spec``."""
        return {name: (lo, hi) for s, name, lo, hi in self.bound_overrides if s in (None, spec)}

    def per_test_for(self, spec: str) -> tuple:
        """The --per-test parameters that apply to ``spec``."""
        names = self.model(spec).names
        return tuple(dict.fromkeys(n for s, n in self.per_test if s in (None, spec) and n in names))

    def start_for(self, spec: str) -> tuple | None:
        """(names, values) of the --start calibration when ``spec``'s model
        extends it (same law, its effects among the model's), else None."""
        if self.start is None:
            return None
        given, model = self.model(self.start[0]), self.model(spec)
        if given.law is not model.law or not set(given.effect_names) <= set(model.effect_names):
            return None
        return self.start[1], self.start[2]

    @property
    def fits_zero(self) -> bool:
        """Whether each test's force zero is fitted beside the models (``force_zero`` 'per-test')."""
        return self.force_zero == "per-test"

    def start_values_for(self, spec: str) -> dict:
        """{name: value} of the --start-value options that apply to ``spec``."""
        names = self.model(spec).names
        return {name: v for s, name, v in self.start_values if s in (None, spec) and name in names}

    def as_dict(self) -> dict:
        s = settings_for(self.optimizer, self.pop, self.gens, self.stall)
        return {"specs": list(self.specs), "runs": self.runs, "bounds": self.bounds,
                "optimizer": self.optimizer, "seed": self.seed, "optimizer_settings": asdict(s),
                "plugins": list(self.plugins),
                "bound_overrides": [list(o) for o in self.bound_overrides],
                "per_test": [list(o) for o in self.per_test], "intervals": self.intervals,
                "all_runs": self.all_runs, "start_values": [list(o) for o in self.start_values],
                **({"force_zero": self.force_zero} if self.fits_zero else {}),  # (files of before: unchanged)
                "start": None if self.start is None else {"model": self.start[0],
                                                          "values": dict(zip(self.start[1], self.start[2]))}}


#: runs made first of each model; the others only where these disagree
FIRST_RUNS = 2


def first_runs(cs) -> int:
    """How many runs of each (device, model) are made before the agreement check."""
    return cs.runs if cs.all_runs or cs.runs <= FIRST_RUNS else FIRST_RUNS


def repeat_each_other(runs) -> bool:
    """Runs that ended on one optimum: every OF within the local search's
    L1_TOLERANCE share of the best (how close its end is to eq. 18's
    optimum) and every parameter within SAME_BASIN of the best run's
    (unit-cube distance: the local search's own test of one basin)."""
    best = min(runs, key=lambda r: r.of)
    space = Space.of(best.bounds, best.log or None)
    at = space.position(np.asarray(best.params))
    return all(r.of <= best.of * (1.0 + L1_TOLERANCE)
               and np.max(np.abs(space.position(np.asarray(r.params)) - at), initial=0.0) <= SAME_BASIN
               for r in runs)


def run_campaign(records, cs: CampaignSettings, progress: bool = True, executor=None) -> dict:
    """Fit every spec to every record through ``executor`` (default: a local
    process pool of ``cs.jobs`` workers): first ``first_runs(cs)`` runs of
    each, then the rest of ``cs.runs`` of the models whose first runs do not
    ``repeat_each_other`` on every device (all of them with ``cs.all_runs``).
    Where the first runs end far above the record's noise floor (NEAR_FLOOR
    times it), the search looks wider first (``_search_wider``), and a wider
    round that finds better makes the rest of the runs too.
    The runs made are the first of the same seeded sequence a full campaign
    makes, so their statistics are those of its first runs (2 runs that
    agree bound the share of runs that would not only loosely: the
    robustness statistics over runs need ``all_runs``).

    Returns {(device name, spec): [FitResult per run made]} in run order.
    """
    executor = executor or Processes(cs.jobs)
    tasks = make_tasks(records, cs)
    k = first_runs(cs)
    results: dict = {(rec.name, spec): [None] * cs.runs for rec in records for spec in cs.specs}
    bar = progress_bar(len(tasks), progress, unit="fit")
    news = getattr(executor, "news", None) if progress else None  # a process pool's (campaign.news)
    try:
        with Listener(news, bar.set_postfix_str) if news is not None else nullcontext():
            _run_waves(executor, tasks, records, cs, results, bar, k)
    finally:
        bar.close()
    return results


def _run_waves(executor, tasks, records, cs, results, bar, k) -> None:
    """The first ``k`` runs of each (device, model); the wider search of the
    models they leave far above the noise floor (``_search_wider``); then
    the rest of the models whose first runs do not repeat each other or
    whose wider search found better (``run_campaign``); each wider round
    last in its runs."""
    _run(executor, [t for t in tasks if t.run < k], records, cs, results, bar)
    extra = _search_wider(executor, tasks, records, cs, results, bar, k)
    gained = {key[1] for key, runs in extra.items()
              if min(r.of for r in runs) < _best_of(results, key, k) * (1.0 - L1_TOLERANCE)}
    settled = {spec for spec in cs.specs if k < cs.runs and spec not in gained
               and all(repeat_each_other(results[(rec.name, spec)][:k]) for rec in records)}
    for spec in settled:
        bar.total -= len(records) * (cs.runs - k)
        for rec in records:
            del results[(rec.name, spec)][k:]
    if settled:
        named = ", ".join(s for s in cs.specs if s in settled)
        bar.set_description(f"the first {k} runs of {named} agree: not repeated")
    _run(executor, [t for t in tasks if t.run >= k and t.spec not in settled], records, cs, results, bar)
    for key, runs in extra.items():
        results[key] += runs


def _best_of(results, key, k) -> float:
    """The best OF of the first ``k`` runs of ``key``."""
    return min(r.of for r in results[key][:k])


def far_above_floor(runs) -> bool:
    """Whether the best of ``runs`` ends beyond NEAR_FLOOR times the record's
    noise floor (the first run's ``floor``; False where it is not known)."""
    floor = runs[0].floor
    return floor is not None and floor > 0.0 and min(r.of for r in runs) > NEAR_FLOOR * floor


def _search_wider(executor, tasks, records, cs, results, bar, k) -> dict:
    """{(device, spec): [FitResult]}: the wider search rounds (``fit.local.WIDER``:
    more points and starts, the last with the DE check) of the models whose
    first ``k`` runs end far above the noise floor on a device.  Round 1
    always, round 2 where round 1 lowered the OF and it is still far above:
    two runs that agree in one basin prove nothing when the OF is far above
    what the record's noise allows.  Every device of such a model gets the
    round (the run statistics need as many runs on each).  Only for the
    local search (the paper's GA and DE are run as asked)."""
    if not cs.optimizer.startswith("local"):
        return {}
    first = {(t.device, t.spec): t for t in tasks if t.run == 0}
    extra = {key: [] for key in first}
    todo = [spec for spec in cs.specs if any(far_above_floor(results[(rec.name, spec)][:k]) for rec in records)]
    for round_ in range(1, len(WIDER) + 1):
        if not todo:
            break
        wave = [wider_task(first[(rec.name, spec)], round_, cs.runs + round_ - 1) for spec in todo for rec in records]
        before = {key: min(r.of for r in results[key][:k] + extra[key]) for key in first}
        bar.total += len(wave)
        bar.set_description(f"wider search {round_}/{len(WIDER)} of {', '.join(todo)}: far above the noise floor")
        for (task, _, _), res in executor.run(run_task, ((t, records[t.device_index], cs) for t in wave)):
            extra[(task.device, task.spec)].append(res)
            bar.update()
        todo = [spec for spec in todo
                if any(extra[(rec.name, spec)][-1].of < before[(rec.name, spec)] * (1.0 - L1_TOLERANCE)
                       for rec in records)
                and any(far_above_floor(results[(rec.name, spec)][:k] + extra[(rec.name, spec)]) for rec in records)]
    return {key: runs for key, runs in extra.items() if runs}


def _run(executor, tasks, records, cs, results, bar) -> None:
    """Run ``tasks`` through ``executor``, each result into its place in ``results``."""
    if not tasks:
        return
    for (task, _, _), res in executor.run(run_task, ((t, records[t.device_index], cs) for t in tasks)):
        runs = results[(task.device, task.spec)]
        runs[task.run] = res
        best = min(x.of for x in runs if x is not None)
        bar.set_description(f"law {task.spec} | {task.device} | run {task.run + 1}/{cs.runs} | "
                            f"best OF {best:.4f}")
        bar.update()


def book_fit_times(results: dict) -> None:
    """Each model's fits' own wall times (in whichever process ran them) as
    ``--profile`` stages."""
    for (_, spec), runs in results.items():
        timing.add(f"  law {spec} (summed over workers)", sum(r.wall_s for r in runs if r is not None), len(runs))


#: replicas per refit task, at most: a calibration's replicates spread over the processes
REPLICAS_PER_TASK = 4


def refit_task(key: tuple, first: int, cs, per_test, replicas, params, noise, bounds):
    """The Newton refits (fit.intervals.newton_refits) of replicas ``first``,
    ``first`` + 1, ... of one (device, model) calibration: (estimates, OFs)."""
    model = cs.model(key[1])
    layout = Layout(model, tuple(as_device(replicas[0]).test_names), tuple(per_test), cs.fits_zero)
    return newton_refits(model, layout, replicas, params, noise, bounds)


def run_intervals(records, results: dict, cs: CampaignSettings, executor=None, progress: bool = True) -> dict:
    """{(device, spec): Intervals} of every calibration (the best run of each),
    through ``executor`` (default: a local process pool); empty when
    ``cs.intervals`` is 0.  The replicas are drawn here, in one random
    stream per calibration; their refits go out REPLICAS_PER_TASK at a
    time, so one calibration's replicates share the processes and the
    progress counts replicates.  The numbers are those of
    ``fit.intervals.intervals`` in one process."""
    if not cs.intervals:
        return {}
    executor = executor or Processes(cs.jobs)
    drawn, items = {}, []
    for rec in records:
        for spec in cs.specs:
            key, best = (rec.name, spec), min(results[(rec.name, spec)], key=lambda r: r.of)
            per_test = cs.per_test_for(spec)
            layout, replicas, noise = bootstrap_replicas(cs.model(spec), rec, best.params, per_test, cs.intervals,
                                                         seed=[cs.seed, 7], force_zero=cs.fits_zero)
            width = best.params.size + 2 * len(best.zero or {})  # the tests' force zero after the parameters
            drawn[key] = (layout, best, np.zeros((len(replicas), width)), np.zeros(len(replicas)))
            items += [(key, b, cs, per_test, replicas[b:b + REPLICAS_PER_TASK], best.params, noise, best.bounds)
                      for b in range(0, len(replicas), REPLICAS_PER_TASK)]
    bar = progress_bar(len(drawn) * cs.intervals, progress, unit="replicate",
                       desc=f"intervals ({cs.intervals} replicates of {len(drawn)} calibration(s))")
    try:
        for item, (estimates, ofs) in executor.run(refit_task, items):
            _, _, all_estimates, all_ofs = drawn[item[0]]
            first = item[1]
            all_estimates[first:first + len(ofs)], all_ofs[first:first + len(ofs)] = estimates, ofs
            bar.update(len(ofs))
    finally:
        bar.close()
    return {key: from_estimates(cs.model(key[1]), layout, best.params, estimates, float(np.mean(ofs)), best.bounds,
                                best.of, best.zero, floor=results[key][0].floor)
            for key, (layout, best, estimates, ofs) in drawn.items()}
