"""Executors: how a campaign's tasks are run.

An executor has ``run(fn, items) -> iterator of (item, result)`` in completion
order, calling ``fn(*item)`` for each item; the campaign (runner.py) knows
nothing else about it.  ``Serial`` runs in this process, ``Processes`` on a
local process pool, ``Dask`` on a dask.distributed cluster (a LocalCluster
or a scheduler's address); ``resume.Resumable`` wraps any of them.
"""

from __future__ import annotations

import logging
import multiprocessing
import multiprocessing.util
import os
import signal

import numpy as np
from concurrent.futures import ProcessPoolExecutor, as_completed

from ..errors import InputError, speak, words
from ..calibration.news import install as install_news
from ..calibration.runs import InProcess

#: run every item here, in order (one calibration's executor, under the campaign's name)
Serial = InProcess


def _stop_worker(signum, frame):
    """SIGTERM in a worker (``stop``): exit now, as a pool worker's process
    ends (multiprocessing's exit handlers, which release the semaphores it
    made, numba's process lock among them, then os._exit), wherever it is
    (a task, numba's compiler callback): no traceback, nothing leaked."""
    multiprocessing.util._exit_function()
    os._exit(0)


def _init_worker(words: str = "api", news=None):
    """A worker's start: SIGTERM ends it; its messages speak the caller's
    ``words`` (errors.speak); its fits report to ``news`` (calibration.news)."""
    # first: SIGTERM ends the worker, also during this start-up (stop)
    signal.signal(signal.SIGTERM, _stop_worker)
    import numba  # lazily: only a worker sets numba's threads; importing executors stays numba-free

    numba.set_num_threads(1)  # the processes already use every core
    speak(words)
    install_news(news)


class Processes:
    """A local process pool of ``jobs`` workers (0: one per core), each numba
    kernel on one thread; 'forkserver' (or 'spawn'), never 'fork': a child
    forked after numba's thread pool started can hang or die.  Inside ``with
    Processes(jobs) as ex:`` one pool serves every ``run`` (a campaign's
    fits, then its figures: the workers start once, about 1 s); outside it
    each run starts and ends its own."""

    def __init__(self, jobs: int = 0):
        self.jobs = jobs or os.cpu_count() or 1
        self._shared = False
        self._pool = None
        self._context = multiprocessing.get_context(
            "forkserver" if "forkserver" in multiprocessing.get_all_start_methods() else "spawn")
        self._news = None

    @property
    def news(self):
        """The queue the workers' fits report their progress to
        (calibration.news): made when a listener asks for it, before the pool
        starts; workers started without it report nothing."""
        if self._news is None:
            self._news = self._context.Queue()
        return self._news

    def __enter__(self):
        self._shared = True
        return self

    def __exit__(self, exc_type, *_):
        pool, self._pool, self._shared = self._pool, None, False
        if pool is not None:
            pool.shutdown(wait=True) if exc_type is None else stop(pool)
        return False

    def _start(self) -> ProcessPoolExecutor:
        return ProcessPoolExecutor(max_workers=self.jobs, initializer=_init_worker, initargs=(words(), self._news),
                                   mp_context=self._context)

    def run(self, fn, items):
        items = list(items)
        if self.jobs == 1 or len(items) <= 1:
            yield from Serial().run(fn, items)
            return
        pool = self._pool or self._start()
        if self._shared:
            self._pool = pool
        try:
            futures = {pool.submit(fn, *item): item for item in items}
            for fut in as_completed(futures):
                yield futures[fut], fut.result()
        except BaseException:  # SIGTERM, Ctrl-C, a failed task, the caller stopping: no worker outlives the run
            self._pool = None
            stop(pool)
            raise
        if not self._shared:
            pool.shutdown(wait=True)


#: seconds a terminated worker gets to exit before it is killed (a signal waits
#: for the compiled kernel it interrupts to return; Slurm waits 30 s before SIGKILL)
STOP_GRACE = 20.0


def stop(pool: ProcessPoolExecutor) -> None:
    """End a process pool now: queued tasks cancelled, the end-of-work
    sentinels sent, each worker ended (SIGTERM: ``_stop_worker``; SIGKILL
    after STOP_GRACE s), the pool's queues released."""
    workers = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for proc in workers:
        proc.terminate()
    for proc in workers:
        proc.join(STOP_GRACE)
        if proc.is_alive():
            proc.kill()
            proc.join()
    pool.shutdown(wait=True)  # its manager thread sees the workers gone and releases the queues


def _one_thread(fn, *args):
    """Call ``fn(*args)`` with numba kernels on one thread (a Dask worker thread
    is one of many on the machine, like a Processes worker)."""
    import numba  # lazily: on the Dask worker, like _init_worker

    numba.set_num_threads(1)
    return fn(*args)


#: argument types sent with each task, not scattered once (scatter refuses an empty tuple)
PLAIN = (tuple, list, str, int, float, np.ndarray, type(None))


class Dask:
    """Run on a dask.distributed cluster: the scheduler at ``scheduler``
    ('tcp://host:8786'), or a LocalCluster of ``workers`` (0: one per core)
    single-threaded workers, process workers unless ``processes`` is False.

    Every worker needs fvd_bridge (same version) and any plugin file at the
    same path.  Each distinct record (and settings object) is sent to the cluster once; numba
    kernels run on one thread per task.  Results arrive in completion order.
    """

    def __init__(self, scheduler: str | None = None, workers: int = 0, processes: bool = True):
        self.scheduler, self.processes = scheduler, processes
        self.workers = workers or os.cpu_count() or 1

    def client(self):
        """A connected distributed.Client (and the LocalCluster it owns, if any)."""
        from distributed import Client, LocalCluster  # lazily: dask only (about 0.6 s to import)

        if self.scheduler:
            try:
                return Client(self.scheduler, timeout="30s")
            except (OSError, TimeoutError) as exc:
                raise InputError(f"--scheduler {self.scheduler}: cannot connect ({exc})") from None
        cluster = LocalCluster(n_workers=self.workers, threads_per_worker=1, processes=self.processes,
                               dashboard_address=None, silence_logs=logging.ERROR)
        return Client(cluster)

    def _client_holding_sigterm(self):
        """(client, deliver): the client, with SIGTERM held while its cluster
        starts (a cluster cut off in its start-up cannot be torn down: its
        exit-time teardown fails on workers still starting); ``deliver()``
        raises a held SIGTERM once the caller can tear the cluster down."""
        held = []
        try:
            previous = signal.signal(signal.SIGTERM, lambda signum, frame: held.append(signum))
        except ValueError:  # not the main thread: signals go elsewhere
            return self.client(), lambda: None
        try:
            client = self.client()
        finally:
            signal.signal(signal.SIGTERM, previous)
        return client, lambda: held and signal.raise_signal(signal.SIGTERM)

    def run(self, fn, items):
        from distributed import as_completed  # lazily: dask only

        items = list(items)
        if not items:
            return
        client, deliver = self._client_holding_sigterm()
        try:
            deliver()
            shared = {}  # id(object) -> future of the object sent once (records, settings)
            futures = {}
            for item in items:
                args = []
                for x in item[1:]:
                    if isinstance(x, PLAIN):  # small values go with the task
                        args.append(x)
                        continue
                    if id(x) not in shared:
                        shared[id(x)] = client.scatter(x, hash=False)
                    args.append(shared[id(x)])
                futures[client.submit(_one_thread, fn, item[0], *args, pure=False)] = item
            for fut in as_completed(futures):
                yield futures.pop(fut), fut.result()
        except BaseException:  # stopped (SIGTERM, Ctrl-C, a failed task): the one line is the CLI's
            for name in ("distributed", "tornado", "asyncio"):  # the cluster's teardown logs tracebacks of
                logging.getLogger(name).setLevel(logging.CRITICAL + 1)  # callbacks it cut short
            raise
        finally:
            cluster = getattr(client, "cluster", None)
            client.close()
            if cluster is not None and not self.scheduler:
                cluster.close()
