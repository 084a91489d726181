"""Where a run's time goes: named stages timed in wall seconds (``--profile``).

``with stage("read records"):`` adds the block's wall time to that stage
(stages nest: an inner stage's time is also its outer stage's);
``add(name, seconds)`` books time measured elsewhere (a fit's ``wall_s`` in
a worker process); ``report()`` is the table the verbs print with
``--profile``, in the order the stages first ran.
"""

from __future__ import annotations

import time
from contextlib import contextmanager

_STAGES: dict[str, list] = {}  # name -> [seconds, count]


def reset() -> None:
    """Forget every stage (a verb's run starts with this)."""
    _STAGES.clear()


def add(name: str, seconds: float, count: int = 1) -> None:
    """Book ``seconds`` [s] (``count`` times run) to stage ``name``."""
    entry = _STAGES.setdefault(name, [0.0, 0])
    entry[0] += float(seconds)
    entry[1] += int(count)


@contextmanager
def stage(name: str):
    """Time the block as stage ``name``."""
    _STAGES.setdefault(name, [0.0, 0])  # listed where it starts, before the stages inside it
    t0 = time.perf_counter()
    try:
        yield
    finally:
        add(name, time.perf_counter() - t0)


def stages() -> dict:
    """{name: (seconds, count)} in the order the stages first ran."""
    return {name: (s, n) for name, (s, n) in _STAGES.items()}


def report(total: float | None = None) -> str:
    """The stages as a table: wall seconds, share of ``total`` [s] (the
    run's wall time; default the largest stage), times run."""
    if not _STAGES:
        return "profile: no stage ran"
    total = total or max(s for s, _ in _STAGES.values())
    width = max(len(name) for name in _STAGES)
    lines = ["profile (wall time; indented stages are part of the one above; fits in worker processes are "
             "summed over the workers)", f"  {'stage':<{width}}  {'seconds':>9}  {'share':>6}  {'runs':>5}"]
    for name, (seconds, count) in _STAGES.items():
        lines.append(f"  {name:<{width}}  {seconds:9.3f}  {seconds / total:6.1%}  {count:5d}")
    lines.append(f"  {'total':<{width}}  {total:9.3f}")
    return "\n".join(lines)
