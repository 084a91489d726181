"""A resumable campaign: an executor around any other that skips the units a
UnitStore already holds and stores every new one the moment it ends.

    executor = Resumable(Processes(jobs), UnitStore(out))   # or around Dask(...)
    results = run_campaign(records, cs, progress=False, executor=executor)

Killed at any moment and started again, the same campaign redoes no finished
unit and loses none; a unit found corrupt is redone.  The progress bar counts
units: done (stored and new), left, rate and ETA of this session's units.
"""

from __future__ import annotations

import sys

from ..progress import bar as progress_bar


class Resumable:
    """Executor: ``run(fn, items)`` over ``inner``, items ``(task, record, settings)``.

    After ``run`` started: ``total``, ``resumed`` (units found stored) and
    ``todo`` (units handed to ``inner``) say what happened.
    """

    def __init__(self, inner, store, progress: bool = True, say=None):
        self.inner, self.store, self.progress = inner, store, progress
        self.say = say or (lambda text: print(text, file=sys.stderr))
        self.total = self.resumed = self.todo = 0

    def run(self, fn, items):
        items = list(items)
        stored, todo = [], []
        for item in items:
            result = self.store.load(item[0])
            if result is None:
                todo.append(item)
            else:
                stored.append((item, result))
        self.total, self.resumed, self.todo = len(items), len(stored), len(todo)
        for path, reason in self.store.corrupt:
            self.say(f"warning: {path}: corrupt unit ({reason}); redoing it")
        self.say(f"{self.total} units: {self.resumed} already done in {self.store.root}, {self.todo} to compute")
        yield from stored
        if not todo:
            return
        bar = progress_bar(self.total, self.progress, unit="unit", desc="units", initial=self.resumed)
        try:
            for item, result in self.inner.run(fn, todo):
                result = self.store.save(item[0], result)
                bar.set_postfix_str(f"left {self.total - bar.n - 1} | last {item[0].id} OF {result.of:.4g}",
                                    refresh=False)
                bar.update()
                yield item, result
        finally:
            bar.close()
