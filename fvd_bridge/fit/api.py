"""fit_model: one model, one record or one device's tests, one seeded optimizer run."""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from ..errors import InputError, bound_option, command, option, parameter_option
from ..records.device import as_device
from .de import DESettings, polish, run_de
from .ga import GASettings, run_ga
from .local import FROM_START, LocalSettings, run_local
from .layout import Layout
from .nested import WIDEN_EVALS, WIDEN_GAIN, WIDEN_ROUNDS, data_start, nested_start, wider_bounds
from .objective import objective_weights
from .result import FitResult, Parent
from .space import Space
from . import zero as zero_mod

OPTIMIZERS = ("local", "local+de", "de", "ga", "ga+polish")
DEFAULT_OPTIMIZER = "local"


def settings_for(optimizer: str, pop: int | None = None, gens: int | None = None, stall: int | None = None):
    """Optimizer settings with CLI/YAML overrides (None keeps the default)."""
    if optimizer not in OPTIMIZERS:
        raise InputError(f"{option('--optimizer', optimizer)}: expected one of {', '.join(OPTIMIZERS)}")
    if optimizer.startswith("local"):  # pop, gens: the DE check's (local+de: always run)
        base = LocalSettings()
        return replace(base, always_check=optimizer == "local+de",
                       search=replace(base.search, popsize=pop or base.search.popsize, gens=gens or base.search.gens))
    if optimizer.startswith("ga"):
        base = GASettings()
        return GASettings(pop=pop or base.pop, gens=gens or base.gens, stall=stall or base.stall)
    base = DESettings()
    return DESettings(popsize=pop or base.popsize, gens=gens or base.gens)


def apply_overrides(model, names: list, bounds: np.ndarray, overrides: dict) -> np.ndarray:
    """Replace the bounds of ``model``'s named parameters (and of their
    per-test columns 'NAME@TEST' among ``names``); unknown names and empty
    ranges are input errors."""
    b = bounds.copy()
    for name, (lo, hi) in overrides.items():
        model.known_parameter(name, bound_option(name, lo, hi))
        cols = [k for k, n in enumerate(names) if n == name or n.startswith(name + "@")]
        if not lo <= hi:  # lower == upper: the caller fixes the parameter there
            raise InputError(f"{bound_option(name, lo, hi)}: the lower bound must be below the upper")
        b[cols] = (lo, hi)
    return b


def refuse_all_fixed(model, overrides: dict) -> None:
    """An InputError when ``overrides`` ({name: (lower, upper)}) fix every parameter: nothing to fit."""
    pinned = [n for n, (lo, hi) in overrides.items() if n in model.names and lo == hi]
    if len(pinned) == len(model.names):
        raise InputError(f"{option('--fix')}: every parameter of model {model.spec} is fixed ({', '.join(pinned)}): "
                         f"nothing to fit; compare it on the record instead ({command('compare')})")


def fit_model(model, record, *, bounds: str | np.ndarray = "auto", optimizer: str = DEFAULT_OPTIMIZER,
              seed=0, settings=None, substeps: int = 1, on_generation=None,
              overrides: dict | None = None, start: np.ndarray | None = None,
              mask=None, per_test=(), nested: bool = True, widen: bool = True,
              force_zero: bool = False) -> FitResult:
    """Fit ``model`` (fvd_bridge.model.Model) to ``record`` (a Record, or a
    Device: its tests together, the weighted mean of their OFs) by minimising eq. 18.

    ``bounds``: 'auto', 'paper' or an (n_par, 2) array; ``overrides`` maps
    parameter names to (lower, upper) replacing those bounds.  The same seed
    gives the same result (``seed``: an int or a list of ints, as numpy's
    default_rng takes).  ``on_generation(gen, best_of)`` reports progress.
    ``start``: parameters put into DE's first population (clipped into the
    bounds; the fit ends no worse than them).  Without a start, a fit with
    parameters per test first fits them shared, and a model with effects
    first fits the model without its last effect, and starts from there
    (``nested``; ``fit.nested``).  ``widen``: automatic bounds a law
    parameter ends on widen and the fit repeats.  ``mask``: fit the OF of
    those samples only (boolean (n_t,), or one per test; the model still
    runs over the whole record).  ``per_test``: parameters fitted per test.
    ``force_zero``: each test's force zero fitted beside the model as a
    nuisance (``fit.zero``; the result's ``zero``), never a parameter.
    """
    device = as_device(record)
    layout = Layout(model, tuple(device.test_names), tuple(per_test), force_zero)
    own = settings_for(optimizer)
    settings = settings or own
    if type(settings) is not type(own):
        raise InputError(f"optimizer {optimizer}: settings {type(settings).__name__} belong to another optimizer "
                         f"(settings_for('{optimizer}', pop, gens) gives its own)")
    overrides = dict(overrides or {})
    refuse_all_fixed(model, overrides)
    t0, evals, widened, parent_of = time.perf_counter(), 0, {}, None
    if start is None and nested and layout.free:  # the shared-parameter fit is nested in the per-test one
        pfit = fit_model(model, device, bounds=bounds, optimizer=optimizer, seed=seed, settings=settings,
                         substeps=substeps, overrides=overrides, mask=mask, widen=widen, force_zero=force_zero)
        start = layout.expand(pfit.named())
        evals, widened = pfit.evaluations, dict(pfit.widened)
    elif start is None and nested and model.effects:
        parent = model.without_effect(model.effects[-1].name)
        pfit = fit_model(parent, device, bounds=bounds, optimizer=optimizer, seed=seed, settings=settings,
                         substeps=substeps, overrides={k: v for k, v in overrides.items() if k in parent.names},
                         mask=mask, per_test=[n for n in per_test if n in parent.names], widen=widen,
                         force_zero=force_zero)
        start = nested_start(model, device, pfit.names, pfit.values, per_test)
        evals, widened, parent_of = pfit.evaluations, dict(pfit.widened), Parent(parent.spec, float(pfit.of))
    before, flat = None, []
    for rounds in range(WIDEN_ROUNDS + 1):
        fit = _fit_once(model, device, layout, bounds=bounds, overrides={**widened, **overrides}, optimizer=optimizer,
                        seed=seed, settings=settings, substeps=substeps, on_generation=on_generation, start=start,
                        mask=mask, local=rounds > 0)
        evals += fit.evaluations
        if before is not None and not fit.of < before[0].of * (1.0 - WIDEN_GAIN):
            fit, widened, tried = before  # the optimum lies at that end: keep the fit before the widening
            flat = list(tried)
            break
        more = wider_bounds(model, fit, overrides) if widen and fit.bounds_mode == "auto" else {}
        if not more or rounds == WIDEN_ROUNDS:
            break
        before = (fit, dict(widened), more)
        widened = {**widened, **more}
        start = fit.values
    wall_s = time.perf_counter() - t0
    if len(device.tests) == 1 and mask is None and not force_zero:  # the fit's OF is its one test's
        test_of = [fit.of if np.isfinite(fit.of) else float("inf")]
    else:
        test_of = [evaluate_params(model, t, layout.for_test(fit.values, k)[0], force_zero=force_zero)
                   for k, t in enumerate(device.tests)]
    zero = (zero_mod.values(model, device, layout, fit.values, residual_weights(device, mask)) if force_zero
            else None)
    return replace(fit, evaluations=evals, wall_s=wall_s, widened=widened, parent=parent_of, flat_ends=flat,
                   test_of=test_of, zero=zero)


def _fit_once(model, device, layout, *, bounds, overrides, optimizer, seed, settings, substeps, on_generation,
              start, mask, local: bool = False) -> FitResult:
    """One optimizer run inside fixed bounds; ``start`` is kept if the run ends
    above it.  ``local``: from ``start`` only (a widened bound's round: the
    optimum moves on from where it stopped): the local search's least
    squares, or for the other optimizers Nelder-Mead."""
    local_search = optimizer.startswith("local")
    if local_search and model.global_search:  # the law or an effect asks for a global check
        settings = replace(settings, always_check=True)
    mode, b, space, evaluate, residuals = _problem(model, device, layout, bounds, overrides, mask, substeps)
    rng = np.random.default_rng(seed)
    if isinstance(start, dict):  # some parameters' start values, the data's (or the bounds' middle) for the rest
        start = start_with(model, layout.names, data_start(model, device, layout.per_test), b, start)
    if start is None and local_search:  # the local search starts from the data's candidates
        start = data_start(model, device, layout.per_test)
    p0 = None if start is None else np.clip(np.atleast_2d(np.asarray(start, dtype=float)), b[:, 0], b[:, 1])
    x0 = None if p0 is None else space.to_unit(p0)  # (k, n): one row, or the data's k candidates
    if local and x0 is not None and local_search:
        found = run_local(evaluate, residuals, space.n, rng, FROM_START, None, x0, layout.stepped)
    elif local and x0 is not None:
        found = polish(evaluate, x0[0], float(evaluate(x0[:1])[0]), WIDEN_EVALS)
        found = replace(found, evaluations=found.evaluations + 1, stop=f"{found.stop}, from the widened round's start")
    elif optimizer == "de":
        found = run_de(evaluate, space.n, rng, settings, on_generation, None if x0 is None else x0[0])
    elif local_search:
        found = run_local(evaluate, residuals, space.n, rng, settings, on_generation, x0, layout.stepped)
    else:
        found = run_ga(evaluate, space.n, rng, settings, on_generation)
        if optimizer == "ga+polish":
            polished = polish(evaluate, found.x, found.of, 4000)
            found = replace(found.then(polished), stop=f"{found.stop}, then Nelder-Mead")
    x, of = found.x, found.of
    params = space.to_params(x)
    if p0 is not None:  # the start itself, exactly (not through the unit cube)
        of0 = joint_objective(model, device, layout, p0, mask, substeps)
        if np.min(of0) <= of:
            params, of = p0[int(np.argmin(of0))], float(np.min(of0))
    return FitResult(spec=model.spec, names=layout.names, units=layout.repeat(model.units),
                     values=params, of=float(of), bounds=b, bounds_mode=mode,
                     optimizer=optimizer, seed=seed, evaluations=int(found.evaluations),
                     history=list(found.history), stop=found.stop,
                     record=device.name, log=[bool(v) for v in space.log],
                     off=layout.repeat(model.off_values()), tests=list(device.test_names))


def start_with(model, names: list, base, bounds: np.ndarray, values: dict) -> np.ndarray:
    """Start rows (k, n_cols): ``base`` (the data's candidates; None: the
    bounds' middle) with ``model``'s named parameters (and their per-test
    columns among ``names``) at ``values``."""
    rows = np.atleast_2d(np.array(base if base is not None else bounds.mean(axis=1), dtype=float))
    for name, value in values.items():
        model.known_parameter(name, parameter_option("--start-value", name, value))
        cols = [k for k, n in enumerate(names) if n == name or n.startswith(name + "@")]
        rows[:, cols] = float(value)
    return rows


def _problem(model, device, layout, bounds, overrides=None, mask=None, substeps: int = 1):
    """(bounds mode, bounds (n_cols, 2), the unit-cube Space, evaluate(X) -> OF
    (eq. 18, the tests' weighted mean, of the ``mask``ed samples; inf where
    not finite)) of one fit."""
    if isinstance(bounds, str):
        mode, b = bounds, np.array(layout.repeat(list(model.bounds(bounds, device.scales()))), dtype=float)
        log = layout.repeat(list(model.log_scale(mode))) if mode == "auto" else None
    else:
        mode, b, log = "custom", np.asarray(bounds, dtype=float), None
    b = apply_overrides(model, layout.names, b, overrides or {})
    space = Space.of(b, log)

    weights = residual_weights(device, mask)
    terms = residual_terms(device, layout, weights, zero_mod.pins(device, weights) if layout.zero else None)

    def residuals(X):
        return terms_residuals(model, terms, space.to_params(X), substeps)

    def evaluate(X):
        of = absolute_sum(residuals(X))
        return np.where(np.isfinite(of), of, np.inf)

    return mode, b, space, evaluate, residuals


def residual_weights(device, mask=None) -> list:
    """Per test, w_k c (``objective_weights``; None for a test of weight 0)."""
    masks = mask if isinstance(mask, (list, tuple)) else [mask] * len(device.tests)
    return [w * objective_weights(test.F, test.t, m) if w != 0.0 else None
            for test, w, m in zip(device.tests, device.weights, masks)]


def joint_residuals(model, device, layout, P: np.ndarray, mask=None, substeps: int = 1,
                    weights: list | None = None, pins: list | None = None) -> np.ndarray:
    """The weighted residuals (pop, sum n_t) of every test, whose absolute sum
    is ``joint_objective``: w_k c (F_model - F) test after test
    (``weights``: ``residual_weights(device, mask)``, computed once); with
    ``layout.zero``, w_k c (F_model + zero - F), each test's force zero
    profiled out (``fit.zero``; ``pins``: ``fit.zero.pins(device, weights)``)."""
    weights = residual_weights(device, mask) if weights is None else weights
    if layout.zero and pins is None:
        pins = zero_mod.pins(device, weights)
    return terms_residuals(model, residual_terms(device, layout, weights, pins), P, substeps)


def residual_terms(device, layout, weights: list, pins: list | None) -> list:
    """Per test of nonzero weight, what its residuals take (``joint_residuals``;
    a fit's, once): (the test, its model vector's columns of the fitted vector
    (None: all, in order), w_k c, its force zero's pin (None: not fitted))."""
    terms = []
    for k, (test, c) in enumerate(zip(device.tests, weights)):
        if c is not None:
            columns = layout.columns(k)
            terms.append((test, None if columns == list(range(len(layout.names))) else columns, c,
                          pins[k] if layout.zero else None))
    return terms


def terms_residuals(model, terms: list, P: np.ndarray, substeps: int = 1) -> np.ndarray:
    """``joint_residuals`` from its ``residual_terms``."""
    parts = []
    for test, columns, c, pin in terms:
        own = P if columns is None else np.atleast_2d(P)[:, columns]  # the test's model vectors
        e = model.force(test, own, substeps)  # a new array: the steps below work in it
        e -= test.F
        e = pin.remove(e) if pin is not None else e
        e *= c
        parts.append(e)
    return parts[0] if len(parts) == 1 else np.concatenate(parts, axis=-1)


def joint_objective(model, device, layout, P: np.ndarray, mask=None, substeps: int = 1,
                    weights: list | None = None, pins: list | None = None) -> np.ndarray:
    """Eq. 18 on each test, weighted by the device's weights: (pop,) for P (pop, n_cols).
    ``mask``: one boolean array (a single test) or a list (per test, None: all samples)."""
    return absolute_sum(joint_residuals(model, device, layout, P, mask, substeps, weights, pins))


def absolute_sum(R: np.ndarray) -> np.ndarray:
    """Eq. 18 of weighted residuals R (pop, m): sum |R| per row (pop,); R is overwritten."""
    return np.abs(R, out=R).sum(axis=-1)


def polish_model(model, record, start: np.ndarray, mask=None, bounds: str = "auto",
                 per_test=(), overrides: dict | None = None, *, force_zero: bool = False) -> tuple[np.ndarray, float]:
    """From ``start`` (parameters) inside the model's bounds (``overrides``:
    {name: (lower, upper)} replacing some, e.g. a fit's widened ones),
    minimise the OF (of the ``mask``ed samples): (parameters, OF), never
    worse than ``start``'s.  The local search's least squares from that start alone
    (``fit.local``; also for a model that declares ``global_search``: the
    start is an optimum of a nearby problem, in the right basin).
    ``force_zero``: with each test's force zero beside it (``fit.zero``)."""
    device = as_device(record)
    layout = Layout(model, tuple(device.test_names), tuple(per_test), force_zero)
    _, b, space, evaluate, residuals = _problem(model, device, layout, bounds, overrides, mask)
    start = np.clip(np.asarray(start, dtype=float), b[:, 0], b[:, 1])
    found = run_local(evaluate, residuals, space.n, np.random.default_rng(0), FROM_START, None,
                      space.to_unit(start), layout.stepped)
    of0 = found.history[0]  # FROM_START's one sample: the start
    return (start, of0) if of0 <= found.of else (space.to_params(found.x), float(found.of))



def evaluate_params(model, record, params, mask=None, per_test=(), *, force_zero: bool = False) -> float:
    """The OF (eq. 18; of the ``mask``ed samples; a device's weighted mean) of
    one parameter vector, inf when not finite (``force_zero``: with each
    test's force zero profiled out, ``fit.zero``)."""
    device = as_device(record)
    layout = Layout(model, tuple(device.test_names), tuple(per_test), force_zero)
    of = float(joint_objective(model, device, layout, np.asarray(params, dtype=float)[None, :], mask)[0])
    return of if np.isfinite(of) else float("inf")
