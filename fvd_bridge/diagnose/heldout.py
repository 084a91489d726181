"""Held-out cycles: does an effect also help on cycles it was not fitted to?

The record's cycles are dealt into two folds, alternately (cycle 1, 3, 5,
... and cycle 2, 4, 6, ...; a cycle is two half-cycles between reversals of
d), so each fold spans every amplitude and velocity level of the test: a
fold cut in time would hold the low levels alone and the high ones alone,
and neither could separate, say, friction from the damping exponent.  Base
model and candidate are each fitted on one fold (least squares from their
full-record optimum, the OF of that fold's samples; the model still runs
over the whole record, so a differential law's state is right) and scored
on the other fold, then the folds swap.  The candidate passes when, in both folds, it lowers the
held-out OF by at least ``SHARE`` of the relative drop it brings on the
whole record: a real effect carries over to cycles it was not fitted to,
an effect that only fits one part of the record (a transient, one odd
cycle) does not.

Given several tests of one device (a Device), the folds are the tests:
each is left out in turn, base and candidate are fitted on the others and
scored on it (leave-one-test-out): an effect must carry over to a test it
was not fitted to.
"""

from __future__ import annotations

import numpy as np

from ..fit import evaluate_params, polish_model
from ..records.device import Device
from .where import half_cycles

#: share of the whole-record drop the held-out drop must reach in each fold
SHARE = 0.5


def folds(record) -> list[np.ndarray]:
    """Two boolean masks (n_t,): the samples of the odd and of the even
    cycles (pairs of half-cycles; with fewer than four half-cycles, the first
    and the second half of the record)."""
    starts = half_cycles(record.d)
    if starts.size < 4:
        first = np.arange(record.n) < record.n // 2
        return [first, ~first]
    cycle = np.searchsorted(starts, np.arange(record.n), side="right") - 1  # half-cycle of each sample
    first = (cycle // 2) % 2 == 0
    return [first, ~first]


class BaseFolds:
    """The folds of a record (cycles dealt alternately) or of a device (its
    tests, left out in turn), and the base model fitted on each once, shared
    by every candidate: ``fold`` is a list of (fit on, its mask, score on,
    its mask)."""

    def __init__(self, model, params, record):
        if isinstance(record, Device) and len(record.tests) > 1:
            self.fold = [(record.without(k), None, test, None) for k, test in enumerate(record.tests)]
        else:
            one = record.tests[0] if isinstance(record, Device) else record
            self.fold = [(one, mask, one, ~mask) for mask in folds(one)]
        self.fits = [polish_model(model, on, params, mask)[0] for on, mask, _, _ in self.fold]
        self.scores = [evaluate_params(model, at, p, mask) for p, (_, _, at, mask) in zip(self.fits, self.fold)]


def held_out(base: BaseFolds, model, params, improvement: float) -> dict:
    """{'base': [held-out OF of the base per fold], 'with': [the candidate's],
    'gain': [relative drop per fold], 'passes': each drop >= SHARE x
    ``improvement``, the relative drop on the whole record}."""
    scores = []
    for on, mask, at, at_mask in base.fold:
        fitted, _ = polish_model(model, on, params, mask)
        scores.append(evaluate_params(model, at, fitted, at_mask))
    gain = [(b - c) / b if b > 0 else 0.0 for b, c in zip(base.scores, scores)]
    return {"base": list(base.scores), "with": scores, "gain": gain, "passes": all(g > 0.0 and g >= SHARE * improvement for g in gain)}
