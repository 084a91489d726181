"""Post-fit warnings a user needs (as data: code, message, parameter).

Checked: a parameter on a bound, non-identifiable combinations (law 8: only
mu N), runs that disagree, a fit no better than law 1.
"""

from __future__ import annotations

import numpy as np

#: runs disagree when the spread of OF across runs exceeds this share of its mean
RUN_SPREAD = 0.05
#: a law is "no better than law 1" unless its mean OF is below this share of law 1's
NO_BETTER = 0.98


def fit_warnings(spec: str, runs: list, law1_of: float | None = None) -> list[dict]:
    """Warnings for one (device, model) from its runs (FitResults)."""
    best = min(runs, key=lambda r: r.of)
    out = []
    for name, side in best.on_bound():
        hint = " (try --bounds auto)" if best.bounds_mode == "paper" else " (widen it with --bound)"
        out.append({"code": "on_bound", "parameter": name,
                    "message": f"{name} ended on its {side} bound{hint}"})
    if spec.split("+")[0] == "8":
        products = np.array([r.params[2] * r.params[3] for r in runs])
        mus = np.array([r.params[2] for r in runs])
        out.append({"code": "non_identifiable", "parameter": "mu,N",
                    "message": f"only mu*N is identifiable (mu*N = {products.mean():.4g} kN, spread "
                               f"{_spread(products):.1%} over runs; mu alone spreads {_spread(mus):.1%}): "
                               f"report mu*N, not mu and N"})
    ofs = np.array([r.of for r in runs])
    if len(runs) > 1 and ofs.std() > RUN_SPREAD * ofs.mean():
        out.append({"code": "runs_disagree", "parameter": None,
                    "message": f"runs disagree: OF {ofs.mean():.4g} +- {ofs.std():.2g} over {len(runs)} runs "
                               f"(the optimizer does not find one optimum; more generations or --optimizer de)"})
    if law1_of is not None and spec != "1" and ofs.mean() > NO_BETTER * law1_of:
        out.append({"code": "no_better_than_law1", "parameter": None,
                    "message": f"mean OF {ofs.mean():.4g} is no better than law 1's {law1_of:.4g}"})
    return out


def _spread(x: np.ndarray) -> float:
    m = abs(x.mean())
    return float(x.std() / m) if m > 0 else float("nan")
