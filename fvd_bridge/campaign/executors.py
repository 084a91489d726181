"""Executors: how a campaign's tasks are run.

An executor has ``run(fn, items) -> iterator of (item, result)`` in completion
order, calling ``fn(*item)`` for each item; the campaign (runner.py) knows
nothing else about it.  ``Serial`` runs in this process, ``Processes`` on a
local process pool; a Dask or a resumable executor plugs in the same way.
"""

from __future__ import annotations

import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor, as_completed


class Serial:
    """Run every item here, in order."""

    def run(self, fn, items):
        for item in items:
            yield item, fn(*item)


def _init_worker():
    import numba

    numba.set_num_threads(1)  # the processes already use every core


class Processes:
    """A local process pool of ``jobs`` workers (0: one per core), each numba
    kernel on one thread; 'forkserver' (or 'spawn'), never 'fork': a child
    forked after numba's thread pool started can hang or die."""

    def __init__(self, jobs: int = 0):
        self.jobs = jobs or os.cpu_count() or 1

    def run(self, fn, items):
        items = list(items)
        if self.jobs == 1 or len(items) <= 1:
            yield from Serial().run(fn, items)
            return
        method = "forkserver" if "forkserver" in multiprocessing.get_all_start_methods() else "spawn"
        with ProcessPoolExecutor(max_workers=self.jobs, initializer=_init_worker,
                                 mp_context=multiprocessing.get_context(method)) as pool:
            futures = {pool.submit(fn, *item): item for item in items}
            for fut in as_completed(futures):
                yield futures[fut], fut.result()
