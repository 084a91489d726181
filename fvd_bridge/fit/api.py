"""fit_model: one model, one record, one seeded optimizer run."""

from __future__ import annotations

import time

import numpy as np

from ..errors import InputError
from .de import DESettings, polish, run_de
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
              overrides: dict | None = None, start: np.ndarray | None = None,
              mask: np.ndarray | None = None) -> FitResult:
    """Fit ``model`` (fvd_bridge.model.Model) to ``record`` by minimising eq. 18.

    ``bounds``: 'auto', 'paper' or an (n_par, 2) array; ``overrides`` maps
    parameter names to (lower, upper) replacing those bounds.  The same seed gives
    the same result (``seed``: an int or a list of ints, as numpy's default_rng takes).  ``on_generation(gen, best_of)`` reports progress.
    ``start``: parameters put into DE's first population (clipped into the
    bounds; the fit ends no worse than them).  ``mask``: fit the OF of those
    samples only (boolean (n_t,); the model still runs over the whole record).
    """
    mode, b, space, evaluate = _problem(model, record, bounds, overrides, mask, substeps)
    settings = settings or settings_for(optimizer)
    rng = np.random.default_rng(seed)
    t0 = time.perf_counter()
    if optimizer == "de":
        x0 = None if start is None else space.to_unit(np.clip(start, b[:, 0], b[:, 1]))
        x, of, history, evals = run_de(evaluate, space.n, rng, settings, on_generation, x0)
    else:
        x, of, history, evals = run_ga(evaluate, space.n, rng, settings, on_generation)
        if optimizer == "ga+polish":
            count = [evals]
            x, of = polish(evaluate, x, of, 4000, count)
            evals = count[0]
            history.append(of)
    return FitResult(spec=model.spec, names=model.names, units=model.units,
                     params=space.to_params(x), of=float(of), bounds=b, bounds_mode=mode,
                     optimizer=optimizer, seed=seed, evaluations=int(evals), history=history,
                     wall_s=time.perf_counter() - t0, record=record.name,
                     log=[bool(x) for x in space.log], off=model.off_values())


def _problem(model, record, bounds, overrides=None, mask=None, substeps: int = 1):
    """(bounds mode, bounds (n_par, 2), the unit-cube Space, evaluate(X) -> OF
    (eq. 18 of the ``mask``ed samples, inf where not finite)) of one fit."""
    if isinstance(bounds, str):
        mode, b = bounds, model.bounds(bounds, record.scales())
    else:
        mode, b = "custom", np.asarray(bounds, dtype=float)
    b = apply_overrides(model, b, overrides or {})
    space = Space.of(b, model.log_scale(mode) if mode == "auto" else None)

    def evaluate(X):
        of = objective(record.F, model.force(record, space.to_params(X), substeps), record.t, mask)
        return np.where(np.isfinite(of), of, np.inf)

    return mode, b, space, evaluate


def polish_model(model, record, start: np.ndarray, mask: np.ndarray | None = None, max_evals: int = 1000,
                 bounds: str = "auto") -> tuple[np.ndarray, float]:
    """Nelder-Mead from ``start`` (parameters) inside the model's bounds,
    minimising the OF (of the ``mask``ed samples): (parameters, OF), never
    worse than ``start``'s."""
    _, b, space, evaluate = _problem(model, record, bounds, mask=mask)
    start = np.clip(np.asarray(start, dtype=float), b[:, 0], b[:, 1])
    of0 = evaluate_params(model, record, start, mask)
    x, of = polish(evaluate, space.to_unit(start), of0, max_evals, [0])
    return (start, of0) if of0 <= of else (space.to_params(x), float(of))


def evaluate_params(model, record, params, mask: np.ndarray | None = None) -> float:
    """The OF (eq. 18; of the ``mask``ed samples) of one parameter vector, inf when not finite."""
    of = float(objective(record.F, model.force(record, np.asarray(params, dtype=float)[None, :])[0],
                         record.t, mask))
    return of if np.isfinite(of) else float("inf")
