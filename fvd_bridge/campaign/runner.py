"""Run every (device, model, run) fit, spread over processes, with a progress bar."""

from __future__ import annotations

import functools
import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field

from tqdm import tqdm

from ..fit import fit_model, settings_for


@dataclass(frozen=True)
class CampaignSettings:
    """What a campaign runs: model specs, runs per (device, model), optimizer and its settings."""

    specs: tuple
    runs: int = 20
    bounds: str = "auto"
    optimizer: str = "de"
    seed: int = 0
    pop: int | None = None
    gens: int | None = None
    stall: int | None = None
    jobs: int = 0  # 0: one process per core
    plugins: tuple = field(default_factory=tuple)
    bound_overrides: tuple = field(default_factory=tuple)  # (spec or None, name, lower, upper)

    def overrides_for(self, spec: str) -> dict:
        """{name: (lower, upper)} of the --bound options that apply to ``spec``."""
        return {name: (lo, hi) for s, name, lo, hi in self.bound_overrides if s in (None, spec)}

    def model(self, spec: str):
        """The Model of ``spec``, with this campaign's plugin effects (loaded once per process)."""
        from ..model import parse_model

        return parse_model(spec, _plugins(self.plugins))

    def as_dict(self) -> dict:
        s = settings_for(self.optimizer, self.pop, self.gens, self.stall)
        return {"specs": list(self.specs), "runs": self.runs, "bounds": self.bounds,
                "optimizer": self.optimizer, "seed": self.seed, "optimizer_settings": vars(s),
                "plugins": list(self.plugins),
                "bound_overrides": [list(o) for o in self.bound_overrides]}


def _task_seed(seed: int, device: int, spec_index: int, run: int) -> list[int]:
    """Seed of one run: independent of the order and process it runs in."""
    return [seed, device, spec_index, run]


@functools.lru_cache(maxsize=None)
def _plugins(paths: tuple) -> dict | None:
    if not paths:
        return None
    from ..effects.plugins import load_plugins

    return load_plugins(paths)


def _fit_one(record, spec, seed, cs: CampaignSettings):
    model = cs.model(spec)
    settings = settings_for(cs.optimizer, cs.pop, cs.gens, cs.stall)
    overrides = {n: b for n, b in cs.overrides_for(spec).items() if n in model.names}
    return fit_model(model, record, bounds=cs.bounds, optimizer=cs.optimizer, seed=seed, settings=settings,
                     overrides=overrides)


def _init_worker():
    import numba

    numba.set_num_threads(1)  # the processes already use every core


def run_campaign(records, cs: CampaignSettings, progress: bool = True) -> dict:
    """Fit every spec to every record ``cs.runs`` times.

    Returns {(device name, spec): [FitResult per run]} in run order.
    """
    tasks = [(i, rec, j, spec, r) for i, rec in enumerate(records)
             for j, spec in enumerate(cs.specs) for r in range(cs.runs)]
    results: dict = {(rec.name, spec): [None] * cs.runs for rec in records for spec in cs.specs}
    jobs = cs.jobs or os.cpu_count() or 1
    bar = tqdm(total=len(tasks), disable=not progress, unit="fit", dynamic_ncols=True)

    def done(rec_name, spec, r, res):
        results[(rec_name, spec)][r] = res
        best = min(x.of for x in results[(rec_name, spec)] if x is not None)
        bar.set_description(f"law {spec} | {rec_name} | run {r + 1}/{cs.runs} | best OF {best:.4f}")
        bar.update()

    try:
        if jobs == 1 or len(tasks) == 1:
            for i, rec, j, spec, r in tasks:
                done(rec.name, spec, r, _fit_one(rec, spec, _task_seed(cs.seed, i, j, r), cs))
        else:
            # not 'fork': a child forked after numba's thread pool started can hang or die
            method = "forkserver" if "forkserver" in multiprocessing.get_all_start_methods() else "spawn"
            with ProcessPoolExecutor(max_workers=jobs, initializer=_init_worker,
                                     mp_context=multiprocessing.get_context(method)) as pool:
                futures = {pool.submit(_fit_one, rec, spec, _task_seed(cs.seed, i, j, r), cs): (rec.name, spec, r)
                           for i, rec, j, spec, r in tasks}
                for fut in as_completed(futures):
                    done(*futures[fut], fut.result())
    finally:
        bar.close()
    return results
