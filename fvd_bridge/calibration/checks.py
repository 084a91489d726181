"""Post-fit warnings a user needs (as data: code, message, parameter).

Checked: a parameter on a bound, non-identifiable combinations (law 8: only
mu N), runs that disagree, a fit no better than law 1.

Runs disagree when the worst run's OF is more than RUN_RANGE = 5% above the
best: (max - min) / min of OF over runs > 0.05.  The relative range works
from 2 runs on (two runs at OF 0.1921 and 0.2023: 5.3%, flagged), where a
sigma-over-mean rule hides the same gap (2.6%).
"""

from __future__ import annotations

import numpy as np

from ..errors import bound_option, command, option
from ..fit.local import L1_TOLERANCE
from ..fit.objective import EXPLAINS_LITTLE, NEAR_FLOOR
from .tasks import is_wider

#: runs disagree when (max - min) / min of OF over runs exceeds this
RUN_RANGE = 0.05
#: a law is "no better than law 1" unless its mean OF is below this share of law 1's
NO_BETTER = 0.98


def fit_warnings(model, runs: list, law1_of: float | None = None) -> list[dict]:
    """Warnings for one (device, model) from its runs (FitResults)."""
    best = min(runs, key=lambda r: r.of)
    out = []
    for name, side in best.on_bound():
        out.append({"code": "on_bound", "parameter": name, "message": _bound_message(model, best, name, side)})
    for d in (d for d in model.law.derived if d.factors):  # law 8: only mu*N is identifiable
        values = np.array([model.derived(r.values)[d.name][0] for r in runs])
        first = d.factors[0]
        alone = np.array([r.values[model.names.index(first)] for r in runs])
        out.append({"code": "non_identifiable", "parameter": ",".join(d.factors),
                    "message": f"only {d.name} is identifiable ({d.name} = {values.mean():.4g} {d.unit}, spread "
                               f"{_spread(values):.1%} over runs; {first} alone spreads {_spread(alone):.1%}): "
                               f"report {d.name}, not {' and '.join(d.factors)}"})
    out += floor_warnings(runs, best)
    runs = [r for r in runs if not is_wider(r)] or runs  # the runs asked for; the wider search's are its own
    ofs = np.array([r.of for r in runs])
    spread = relative_range(ofs) if len(runs) > 1 else 0.0
    if spread > RUN_RANGE:
        remedy = "more generations" + (f" or {option('--optimizer', 'de')}" if best.optimizer != "de" else
                                       f", more runs ({option('--runs')}), or narrower bounds around the best run "
                                       f"({option('--bound')})")
        out.append({"code": "runs_disagree", "parameter": None,
                    "message": f"runs disagree: OF {ofs.min():.4g} to {ofs.max():.4g} over {len(runs)} runs, the worst "
                               f"{spread:.1%} above the best (more than {RUN_RANGE:.0%}; the optimizer "
                               f"({best.optimizer}) does not find one optimum: {remedy})"})
    if law1_of is not None and model.spec != "1" and ofs.mean() > NO_BETTER * law1_of:
        out.append({"code": "no_better_than_law1", "parameter": None,
                    "message": f"mean OF {ofs.mean():.4g} is no better than law 1's {law1_of:.4g}"})
    return out


def floor_warnings(runs: list, best) -> list[dict]:
    """The best run against what the record allows: far above its noise
    floor (the first run's ``floor``: NEAR_FLOOR times it), a force the model
    explains little of (an OF beyond EXPLAINS_LITTLE), and a wider search
    that found better than the runs (``calibration.runs``: the runs alone
    end in another basin on this record)."""
    out, floor = [], runs[0].floor
    if best.of > EXPLAINS_LITTLE:
        out.append({"code": "explains_little", "parameter": None,
                    "message": f"OF {best.of:.3g}: the model explains little of the measured force (beyond "
                               f"{EXPLAINS_LITTLE}; a force of zero scores 0.9 on a sine test): check the "
                               f"record's columns, units and sign, and the law"})
    elif floor and best.of > NEAR_FLOOR * floor:
        searched = ", after a wider search" if any(is_wider(r) for r in runs) else ""
        out.append({"code": "far_above_floor", "parameter": None,
                    "message": f"OF {best.of:.3g} is {best.of / floor:.0f}x what the record's noise allows "
                               f"({floor:.2g}){searched}: the model misses part of the record, and the "
                               f"intervals count the noise only ({command('diagnose')} shows what is missing)"})
    made = [r.of for r in runs if not is_wider(r)]
    found = [r.of for r in runs if is_wider(r)]
    if made and found and min(found) < min(made) * (1.0 - L1_TOLERANCE):
        out.append({"code": "wider_search_found_better", "parameter": None,
                    "message": f"the runs asked for ended at OF {min(made):.4g} at best; a wider search found "
                               f"{min(found):.4g} (the calibration): this record's objective has several basins"})
    return out


def _bound_message(model, best, name: str, side: str) -> str:
    """'alpha ended on its upper bound 1 (bounds auto); try --bound 9:alpha=0,2'."""
    lo, hi = best.params[name].bounds
    rigid = {p.name for p in model.law.parameters if p.rigid_upper}
    if side == "upper" and name.split("@")[0] in rigid:
        return (f"{name} ended on its upper bound {hi:.4g}, which stands for rigid (an elastic range of a "
                f"thousandth of the stroke): the record shows no compliance this element could take up")
    if name in (best.flat_ends or []):
        return (f"{name} ended on its {side} bound {lo if side == 'lower' else hi:.4g}; widening it did not lower "
                f"the OF: the optimum lies at that end (a rigid spring, a vanishing term)")
    if best.bounds_mode == "paper":
        return f"{name} ended on its {side} bound {lo if side == 'lower' else hi:.4g} (paper bounds; try {option('--bounds', 'auto')})"
    base, end = name.split("@")[0], lo if side == "lower" else hi
    lim = {p.name: p.limit for p in model.law.parameters}.get(base)
    if lim is not None and (base in best.widened or end in lim):  # widened by itself (fit.nested): no hint
        return (f"{name} ended on its {side} bound {end:.4g}; the automatic bounds widen "
                f"by themselves towards its physical range [{lim[0]:.4g}, {lim[1]:.4g}], and the optimum stays at "
                f"this end: the record does not need this term as the law writes it")
    wider = (lo - (hi - lo), hi) if side == "lower" else (lo, hi + (hi - lo))
    if side == "lower" and lo > 0.0 and wider[0] < 0.0:
        wider = (lo / 10.0, hi)
    return (f"{name} ended on its {side} bound {lo if side == 'lower' else hi:.4g} (bounds {best.bounds_mode} "
            f"[{lo:.4g}, {hi:.4g}]); widen it, e.g. {bound_option(name, *wider, model.spec)}")


def relative_range(x) -> float:
    """(max - min) / min of positive values (e.g. OF over runs): how far the worst
    is above the best, meaningful from 2 values on; NaN when min <= 0."""
    x = np.asarray(x, dtype=float)
    lo = float(np.min(x))
    return float((np.max(x) - lo) / lo) if lo > 0 else float("nan")


def _spread(x: np.ndarray) -> float:
    m = abs(x.mean())
    return float(x.std() / m) if m > 0 else float("nan")
