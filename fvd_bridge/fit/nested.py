"""Nested starts and widening bounds: a fit that cannot end worse than the
model it extends, nor be starved by an automatic bound.

A model with effects nests the model without its last effect: that model's
optimum, with the effect at its 'off' values, reproduces it exactly.  The fit
puts that point into its first population and keeps it should the search
end above it.  A law parameter that ends on an automatic bound has its bound
widened (the span doubled on that side, on the log scale for log-searched
parameters, never past the parameter's physical ``limit``) and the fit
goes on from its optimum (Nelder-Mead: the optimum moves on along the
bound it was pressed against), at most ``WIDEN_ROUNDS`` times, while each
widening lowers the OF by ``WIDEN_GAIN`` at least (a stiffness whose
optimum is rigid would otherwise run to infinity).  Effects' bounds
are their plausibility caps and do not widen.
"""

from __future__ import annotations

import numpy as np

from ..records.device import as_device
from .layout import SEP, Layout

#: at most this many widen-and-refit rounds per fit
WIDEN_ROUNDS = 5
#: Nelder-Mead evaluations of each round after a widening
WIDEN_EVALS = 1000
#: a widening is kept only if it lowers the OF by this share; else the optimum
#: lies at that end (a rigid spring, a vanishing term) and the fit before it stands
WIDEN_GAIN = 1e-3


def nested_start(model, record, parent_names, parent_params, per_test=()) -> np.ndarray:
    """The parameters of a fit of ``model`` to ``record`` (a Record or a
    Device, with ``per_test`` parameters per test) that reproduce a parent
    model's fit (``parent_names``, ``parent_params``): values copied by name
    (a per-test column without its own takes the shared value), each added
    effect at its 'off' values clipped into its bounds (an infinite stiffness
    is the upper bound)."""
    device = as_device(record)
    values = dict(zip(parent_names, map(float, parent_params)))
    for e in model.effects:
        for name, none, (lo, hi) in zip(e.names, e.none, e.bounds(device.scales())):
            values.setdefault(name, float(np.clip(none, lo, hi)))
    return Layout(model, tuple(device.test_names), tuple(per_test)).expand(values)


def data_start(model, record, per_test=()) -> np.ndarray | None:
    """The law's data-driven starts (``Law.start`` on all tests' samples
    together: one or more candidate sets), each with every effect off, as
    ``nested_start`` lays it out: (k, n_cols); None when the law has none."""
    if model.law.start is None:
        return None
    device = as_device(record)
    d, v, F = (np.concatenate([getattr(t, k) for t in device.tests]) for k in "dvF")
    return np.array([nested_start(model, device, model.law.names, p, per_test) for p in model.law.start(d, v, F)])


def wider_bounds(model, fit, fixed=()) -> dict:
    """{law parameter: (lower, upper)} widened where ``fit`` (a FitResult)
    ended on an automatic bound; parameters in ``fixed`` (the user's --bound)
    and those at their physical limit stay.  Empty when nothing widens."""
    limits = {p.name: p.limit for p in model.law.parameters}
    rigid = {p.name for p in model.law.parameters if p.rigid_upper}
    out = {}
    for name, side in fit.on_bound():
        base = name.split(SEP)[0]
        if base not in limits or base in fixed or base in out or (side == "upper" and base in rigid):
            continue
        j = fit.names.index(name)
        lo, hi = (float(x) for x in fit.bounds[j])
        lim_lo, lim_hi = limits[base]
        if fit.log[j] and lo > 0:
            new = (lo * lo / hi, hi) if side == "lower" else (lo, hi * hi / lo)
        else:
            new = (lo - (hi - lo), hi) if side == "lower" else (lo, hi + (hi - lo))
            if side == "lower" and lo > 0 and new[0] < 0:
                new = (0.0, hi) if lim_lo <= 0 else (max(lim_lo, lo / 10.0), hi)
        new = (max(new[0], lim_lo), min(new[1], lim_hi))
        if new != (lo, hi):
            out[base] = new
    return out
