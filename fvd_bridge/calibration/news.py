"""Progress from inside the fits: a worker's optimizer reports its
generations to the campaign's process, which shows the latest on its bar.

A fit of a gap model on a long record runs a minute in a worker; its
progress bar counts finished fits only, so without news it stands still.
``Processes`` gives each worker the campaign's queue (``install``);
``reporter(label)`` is the fit's ``on_generation`` there, sending (label,
generation, best OF) at most every EVERY_S seconds; ``Listener`` drains
the queue in a thread of the campaign's process and shows each on the bar.
Nothing of it changes a result: the optimizers only call it.
"""

from __future__ import annotations

import queue as queue_module
import threading
import time

#: seconds between two reports of one fit
EVERY_S = 1.0

_QUEUE = None  # in a worker: the campaign's queue (``install``)


def install(queue) -> None:
    """In a worker process: send the fits' news to ``queue`` (None: nowhere).
    The worker may exit with news still unread (its feeder thread is not
    joined): a campaign without a listener must not hang on a full pipe."""
    global _QUEUE
    if queue is not None:
        queue.cancel_join_thread()
    _QUEUE = queue


def reporter(label: str):
    """An ``on_generation(generation, best_of)`` sending (label, generation,
    best OF) to the campaign at most every EVERY_S seconds; None outside a
    campaign's worker."""
    if _QUEUE is None:
        return None
    sent = [0.0]

    def report(generation, best_of):
        now = time.monotonic()
        if now - sent[0] >= EVERY_S:
            sent[0] = now
            try:
                _QUEUE.put_nowait((label, int(generation), float(best_of)))
            except (queue_module.Full, OSError, ValueError):  # a closed or full queue: the news is lost, not the fit
                pass

    return report


class Listener:
    """``with Listener(queue, show):`` a thread that calls ``show(text)`` with
    each report ('device_01/law9+gap/run0001: step 40, OF 0.0973')."""

    def __init__(self, queue, show):
        self.queue, self.show = queue, show
        self._thread = threading.Thread(target=self._listen, daemon=True)
        self._stop = threading.Event()

    def __enter__(self):
        self._thread.start()
        return self

    def __exit__(self, *exc):
        self._stop.set()
        self._thread.join(timeout=2.0)
        return False

    def _listen(self):
        while not self._stop.is_set():
            try:
                label, step, of = self.queue.get(timeout=0.2)
            except (queue_module.Empty, OSError, EOFError, ValueError):
                continue
            self.show(f"{label}: step {step}, OF {of:.4g}")
