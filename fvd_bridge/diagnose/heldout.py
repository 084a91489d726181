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
was not fitted to.  A parameter fitted per test (``--per-test``) has no
value for the test left out: there it is fitted on that test alone, the
shared parameters held at what the other tests gave (``fit_own``).

A candidate whose held-out OF is above the base's on any fold (a test, or
a set of cycles, it predicts worse than the base does) is never
recommended, whatever it gains elsewhere (``worse``): a model that
predicts a test worse than its base is no better model of the device.
"""

from __future__ import annotations

import numpy as np

from ..fit import evaluate_params, polish_model
from ..fit.layout import Layout
from ..fit.local import FROM_START, run_local
from ..fit.objective import objective_weights
from ..fit.space import Space
from ..records.device import Device
from .agree import free, per_test_params
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


def fit_own(model, test, params, names, scales) -> np.ndarray:
    """``params`` (the model's vector) with the parameters ``names`` fitted
    on ``test`` alone (least squares on eq. 18 from their values, inside the
    automatic bounds of the device's ``scales``), the others held."""
    params = np.array(params, dtype=float)
    if not names:
        return params
    cols = [model.names.index(n) for n in names]
    b = np.array(model.bounds("auto", scales), dtype=float)[cols]
    b[:, 0], b[:, 1] = np.minimum(b[:, 0], params[cols]), np.maximum(b[:, 1], params[cols])
    space = Space.of(b, np.asarray(model.log_scale("auto"), bool)[cols])
    c = objective_weights(test.F, test.t)

    def full(X):
        P = np.repeat(params[None, :], len(np.atleast_2d(X)), axis=0)
        P[:, cols] = space.to_params(np.atleast_2d(X))
        return P

    def residuals(X):
        return c * (model.force(test, full(X)) - test.F)

    def evaluate(X):
        of = np.abs(residuals(X)).sum(axis=-1)
        return np.where(np.isfinite(of), of, np.inf)

    stepped = [i for i, n in enumerate(names) if n in model.stepped]
    found = run_local(evaluate, residuals, len(cols), np.random.default_rng(0), FROM_START, None,
                      space.to_unit(params[cols])[None, :], stepped)
    x, of = found.x, found.of
    return full(x)[0] if of < evaluate(space.to_unit(params[cols])[None, :])[0] else params


class BaseFolds:
    """The folds of a record (cycles dealt alternately) or of a device (its
    tests, left out in turn), and the base model fitted on each once, shared
    by every candidate: ``fold`` is a list of (fit on, its mask, score on,
    its mask), ``labels`` names what each fold scores (a test, or cycles).
    ``per_test``: parameters fitted per test (``fit_own`` on the test left out)."""

    def __init__(self, model, params, record, per_test=()):
        self.per_test = tuple(per_test)
        if isinstance(record, Device) and len(record.tests) > 1:
            self.device = record
            self.fold = [(record.without(k), None, test, None) for k, test in enumerate(record.tests)]
            self.labels = [f"test {name}" for name in record.test_names]
        else:
            one = record.tests[0] if isinstance(record, Device) else record
            self.device = None
            self.fold = [(one, mask, one, ~mask) for mask in folds(one)]
            self.labels = ["the odd cycles", "the even cycles"]
        self.fits, self.scores = self.score(model, params)

    def score(self, model, params) -> tuple[list, list]:
        """(fits, held-out OFs): ``model`` fitted on each fold from ``params``
        (the full record's or device's optimum) and scored on what it left out."""
        if self.device is None:
            fits = [polish_model(model, on, params, mask)[0] for on, mask, _, _ in self.fold]
            return fits, [evaluate_params(model, at, p, mask) for p, (_, _, at, mask) in zip(fits, self.fold)]
        names = free(model, self.per_test)
        split = per_test_params(model, self.device, params, names)
        scales = self.device.scales()
        fits, scores = [], []
        for k, (on, _, at, _) in enumerate(self.fold):
            keep = [j for j in range(len(self.device.tests)) if j != k]
            layout = Layout(model, tuple(on.test_names), names)
            start = np.concatenate([split[keep[0]]] + [[split[j][model.names.index(n)] for j in keep[1:]]
                                                       for n in layout.free])
            fitted, _ = polish_model(model, on, start, per_test=names)
            shared = per_test_params(model, on, fitted, names)[0]  # the per-test ones are refitted below
            own = fit_own(model, at, np.where(np.isin(model.names, names), split[k], shared), names, scales)
            fits.append(fitted)
            scores.append(evaluate_params(model, at, own))
        return fits, scores


def held_out(base: BaseFolds, model, params, improvement: float) -> dict:
    """{'base': [held-out OF of the base per fold], 'with': [the candidate's],
    'gain': [relative drop per fold], 'worse': [labels of the folds the
    candidate predicts worse than the base], 'passes': none worse and each
    drop >= SHARE x ``improvement``, the relative drop on the whole record}."""
    _, scores = base.score(model, params)
    gain = [(b - c) / b if b > 0 else 0.0 for b, c in zip(base.scores, scores)]
    worse = [label for label, b, c in zip(base.labels, base.scores, scores) if c > b]
    return {"base": list(base.scores), "with": scores, "gain": gain, "worse": worse,
            "passes": not worse and all(g > 0.0 and g >= SHARE * improvement for g in gain)}
