"""Progress of long work: a bar on a terminal, a whole line now and then in a log.

A tqdm bar redraws itself with carriage returns, which a log file keeps as
hundreds of updates on one line.  Where the output is not a terminal,
``bar`` gives a ``LogProgress`` instead: the same calls, written as whole
lines, one every LOG_EVERY_S seconds and the last.
"""

from __future__ import annotations

import sys
import time

from tqdm import tqdm

#: seconds between two lines of progress in a log
LOG_EVERY_S = 30.0


def bar(total: int, enabled: bool = True, unit: str = "fit", desc: str = "", initial: int = 0, stream=None):
    """A progress bar of ``total`` ``unit``s on ``stream`` (stderr): tqdm's
    on a terminal, ``LogProgress`` elsewhere, a silent one unless ``enabled``."""
    stream = stream or sys.stderr
    if not enabled:
        return tqdm(total=total, disable=True)
    if getattr(stream, "isatty", lambda: False)():
        return tqdm(total=total, initial=initial, unit=unit, desc=desc or None, dynamic_ncols=True, file=stream)
    return LogProgress(total, unit, desc, initial, stream)


class LogProgress:
    """tqdm's ``update``, ``set_description``, ``set_postfix_str``, ``close``
    and ``n``, written as whole lines: 'units 12/40 fits, 31 s | text'."""

    def __init__(self, total: int, unit: str, desc: str, initial: int, stream):
        self.total, self.unit, self.desc, self.n, self.stream = total, unit, desc, initial, stream
        self.text = self.postfix = self.said = ""
        self.t0 = self.last = time.monotonic()

    def set_description(self, text: str, refresh: bool = True) -> None:
        self.text = text
        self._now_and_then()

    def set_postfix_str(self, text: str, refresh: bool = True) -> None:
        """News from inside the work (calibration.news): a line now and then, also between updates."""
        self.postfix = text
        self._now_and_then()

    def update(self, k: int = 1) -> None:
        self.n += k
        self._now_and_then()

    def _now_and_then(self) -> None:
        if time.monotonic() - self.last >= LOG_EVERY_S:
            self._line()

    def close(self) -> None:
        self._line()

    def _line(self) -> None:
        """The state as a line, unless the last line said it already (a close right after an update)."""
        self.last = time.monotonic()
        head = f"{self.desc}: " if self.desc else ""
        tail = "".join(f" | {x}" for x in (self.text, self.postfix) if x)
        line = f"{head}{self.n}/{self.total} {self.unit}s, {self.last - self.t0:.0f} s{tail}"
        if line != self.said:
            print(line, file=self.stream, flush=True)
            self.said = line
