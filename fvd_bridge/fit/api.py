"""fit_model: one model, one record, one seeded optimizer run."""

from __future__ import annotations

import time

import numpy as np

from ..errors import InputError
from .de import DESettings, run_de
from .ga import GASettings, run_ga
from .objective import objective
from .result import FitResult
from .space import Space

OPTIMIZERS = ("de", "ga", "ga+polish")
DEFAULT_OPTIMIZER = "de"


def settings_for(optimizer: str, pop: int | None = None, gens: int | None = None, stall: int | None = None):
    """Optimizer settings with CLI/YAML overrides (None keeps the default)."""
    if optimizer not in OPTIMIZERS:
        raise InputError(f"--optimizer '{optimizer}': expected one of {', '.join(OPTIMIZERS)}")
    if optimizer.startswith("ga"):
        base = GASettings()
        return GASettings(pop=pop or base.pop, gens=gens or base.gens, stall=stall or base.stall)
    base = DESettings()
    return DESettings(popsize=pop or base.popsize, gens=gens or base.gens)


def apply_overrides(model, bounds: np.ndarray, overrides: dict) -> np.ndarray:
    """Replace the bounds of named parameters; unknown names and empty ranges are input errors."""
    b = bounds.copy()
    for name, (lo, hi) in overrides.items():
        if name not in model.names:
            raise InputError(f"--bound {name}: model {model.spec} has no parameter '{name}' "
                             f"(has: {', '.join(model.names)})")
        if not lo < hi:
            raise InputError(f"--bound {name}={lo:g},{hi:g}: the lower bound must be below the upper")
        b[model.names.index(name)] = (lo, hi)
    return b


def fit_model(model, record, bounds: str | np.ndarray = "auto", optimizer: str = DEFAULT_OPTIMIZER,
              seed=0, settings=None, substeps: int = 1, on_generation=None,
              overrides: dict | None = None) -> FitResult:
    """Fit ``model`` (fvd_bridge.model.Model) to ``record`` by minimising eq. 18.

    ``bounds``: 'auto', 'paper' or an (n_par, 2) array; ``overrides`` maps
    parameter names to (lower, upper) replacing those bounds.  The same seed gives
    the same result (``seed``: an int or a list of ints, as numpy's default_rng takes).  ``on_generation(gen, best_of)`` reports progress.
    """
    if isinstance(bounds, str):
        mode, b = bounds, model.bounds(bounds, record.scales())
    else:
        mode, b = "custom", np.asarray(bounds, dtype=float)
    b = apply_overrides(model, b, overrides or {})
    space = Space.of(b, model.log_scale(mode) if mode == "auto" else None)
    settings = settings or settings_for(optimizer)
    rng = np.random.default_rng(seed)

    def evaluate(X):
        F = model.force(record, space.to_params(X), substeps)
        of = objective(record.F, F, record.t)
        return np.where(np.isfinite(of), of, np.inf)

    start = time.perf_counter()
    if optimizer == "de":
        x, of, history, evals = run_de(evaluate, space.n, rng, settings, on_generation)
    else:
        x, of, history, evals = run_ga(evaluate, space.n, rng, settings, on_generation)
        if optimizer == "ga+polish":
            from .de import polish

            count = [evals]
            x, of = polish(evaluate, x, of, 4000, count)
            evals = count[0]
            history.append(of)
    return FitResult(spec=model.spec, names=model.names, units=model.units,
                     params=space.to_params(x), of=float(of), bounds=b, bounds_mode=mode,
                     optimizer=optimizer, seed=seed, evaluations=int(evals), history=history,
                     wall_s=time.perf_counter() - start, record=record.name,
                     log=[bool(x) for x in space.log], off=model.off_values())
