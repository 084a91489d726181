"""One cache of the compiled numerical kernels, and a word when it is cold.

The laws' and effects' kernels are compiled by numba on first use and
cached on disk (``cache=True``).  Without a setting numba caches beside the
package's sources, so `make demo`, the tests and a direct `fvd-bridge` call
could each compile again.  ``configure`` points every entry point at one
folder, ``NUMBA_CACHE_DIR`` if the user set it, else the user's cache
folder (``$XDG_CACHE_HOME/fvd_bridge/numba``, ``~/.cache/...``), before any
kernel is compiled; ``cold`` says whether nothing is cached there yet, so
the command line can say why its first run is slow.

Each kernel compiles once per environment: ``kernel_array`` gives a kernel
the one array type it is compiled for (a read-only array would compile it
again), and numba's index updates are locked across processes
(``_lock_index_updates``), so that one process's entry survives another's.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np

#: a kernel every calibration compiles: its cache index marks a warm cache
MARKER = "algebraic.*.nbi"


def cache_dir() -> Path:
    """The folder of the compiled kernels."""
    if os.environ.get("NUMBA_CACHE_DIR"):
        return Path(os.environ["NUMBA_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "fvd_bridge" / "numba"


def configure() -> None:
    """Point numba at ``cache_dir()``, unless NUMBA_CACHE_DIR is set or the
    folder cannot be made (then numba's own default stays); then make its
    index updates one step across processes (``_lock_index_updates``)."""
    _point_numba_at_cache_dir()
    _lock_index_updates()


def _point_numba_at_cache_dir() -> None:
    if os.environ.get("NUMBA_CACHE_DIR"):
        return
    path = cache_dir()
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError:
        return
    os.environ["NUMBA_CACHE_DIR"] = str(path)
    if "numba" in sys.modules:  # imported before us: its config has read the environment already
        from numba.core import config

        config.CACHE_DIR = str(path)


def _lock_index_updates() -> None:
    """Make numba's update of a kernel's cache index one step across processes.

    numba saves a compiled kernel by reading the kernel's index file, adding
    the new entry with the next free data file name and writing the index
    back.  Two processes that save two specializations of one kernel at once
    (a pool's workers compiling its block widths, two test workers) can each
    write back an index without the other's entry, both under the same data
    file name: the entry lost compiles again in the next process, and an
    index can name a data file that holds the other specialization.  Here
    that read-add-write holds an exclusive lock (``flock``) on a file beside
    the index; nothing changes where ``fcntl`` is missing (Windows)."""
    try:
        import fcntl
    except ImportError:
        return
    from numba.core.caching import IndexDataCacheFile

    save = IndexDataCacheFile.save
    if getattr(save, "locked", False):
        return

    def locked_save(self, key, data):
        with open(os.path.join(self._cache_path, "index.lock"), "a") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file closes
            return save(self, key, data)

    locked_save.locked = True
    IndexDataCacheFile.save = locked_save


def kernel_array(x) -> np.ndarray:
    """``x`` as a kernel's argument: float64, C-contiguous and writable (a
    copy only if it is not).  numba compiles a kernel once per argument
    type, and a read-only array (a broadcast view, a row of one) is a type
    of its own: passed one, a kernel compiled and cached for writable arrays
    compiles again."""
    if type(x) is np.ndarray and x.dtype == np.float64 and x.flags.c_contiguous and x.flags.writeable:
        return x  # already one (most calls: np.require's checks cost more than the kernel's setup)
    return np.require(x, dtype=np.float64, requirements="CW")


def cold() -> bool:
    """True when no kernel is cached yet: the first run compiles them."""
    path = cache_dir()
    return not (path.is_dir() and any(path.rglob(MARKER)))


NOTICE = "compiling the numerical kernels (after an install or an update, once: about a minute; cached in {})"


def announce(say):
    """Call ``say(NOTICE)`` once: now if the cache is cold (the kernels may
    compile in worker processes), else at the first kernel numba actually
    compiles (a cache made stale by an update; numba's ``numba:compile``
    event fires on a cache miss only).  Returns the listener, if any."""
    from numba.core import event

    text = NOTICE.format(cache_dir())
    if cold():
        say(text)
        return None

    class _Once(event.Listener):
        said = False

        def on_start(self, ev):
            if not self.said:
                self.said = True
                say(text)

        def on_end(self, ev):
            pass

    listener = _Once()
    event.register("numba:compile", listener)
    return listener
