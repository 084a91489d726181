"""The default optimizer: differential evolution followed by a Nelder-Mead polish.

scipy's differential_evolution (vectorized: the whole population per call,
seeded) explores the unit cube; Nelder-Mead from the best point polishes the
non-smooth L1 objective of eq. 18 to the noise floor.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import differential_evolution, minimize

from .search import Evaluations, Search


#: with ``stall``: a generation's best that improves by less than this share does not count (default)
STALL_GAIN = 1e-9


@dataclass(frozen=True)
class DESettings:
    """popsize is per parameter (scipy's convention); gens caps generations."""

    popsize: int = 15
    gens: int = 300
    tol: float = 1e-6
    polish: bool = True
    polish_evals: int = 4000
    stall: int | None = None  # stop after this many generations without a better best
    stall_gain: float = STALL_GAIN  # a best better by less than this share is not better (``stall``)


def run_de(evaluate, n: int, rng: np.random.Generator, s: DESettings = DESettings(), on_generation=None,
           x0: np.ndarray | None = None) -> Search:
    """Minimise ``evaluate(X) -> OF`` over [0, 1]^n.

    ``x0`` (a point of the unit cube) replaces the first member of the initial
    population: the result is never worse than it (selection keeps the best)."""
    history: list[float] = []
    count = Evaluations()

    def batch(xt):  # scipy passes (n, S)
        X = np.atleast_2d(xt.T)
        count.add(X.shape[0])
        return evaluate(X)

    stalled = []

    def callback(intermediate_result):
        history.append(float(intermediate_result.fun))
        if on_generation:
            on_generation(len(history), history[-1])
        if s.stall and len(history) > s.stall and not history[-1] < history[-1 - s.stall] * (1.0 - s.stall_gain):
            stalled.append(len(history))
            return True
        return False

    res = differential_evolution(
        batch, [(0.0, 1.0)] * n, popsize=s.popsize, maxiter=s.gens, tol=s.tol, atol=0.0,
        rng=rng, vectorized=True, updating="deferred", polish=False, callback=callback,
        init="sobol" if n > 1 else "latinhypercube", mutation=(0.5, 1.0), recombination=0.9,
        x0=None if x0 is None else np.clip(x0, 0.0, 1.0))
    stop = (f"DE: no better point in {s.stall} generations" if stalled
            else f"DE: {res.message.rstrip('.')} after {res.nit} generations")
    x, fx = np.clip(res.x, 0.0, 1.0), float(res.fun)
    if s.polish:
        polished = polish(evaluate, x, fx, s.polish_evals)
        x, fx = polished.x, polished.of
        count.add(polished.evaluations)
        history.append(fx)
        stop += ", then Nelder-Mead"
    return Search(x, fx, tuple(history), count.n, stop)


def polish(evaluate, x0: np.ndarray, f0: float, max_evals: int, step: float = 0.02) -> Search:
    """Nelder-Mead from x0 (OF f0) inside the unit cube (points outside are
    clipped), its first simplex ``step`` wide, at most ``max_evals``
    evaluations: its Search, never worse than (x0, f0)."""
    def single(x):
        return float(evaluate(np.clip(x, 0.0, 1.0)[None, :])[0])

    simplex = [x0] + [np.clip(x0 + np.eye(x0.size)[i] * (step if x0[i] < 0.5 else -step), 0, 1)
                      for i in range(x0.size)]
    res = minimize(single, x0, method="Nelder-Mead",
                   options={"maxfev": max_evals, "xatol": 1e-9, "fatol": 1e-12,
                            "initial_simplex": np.array(simplex), "adaptive": True})
    x, of = (np.clip(res.x, 0.0, 1.0), float(res.fun)) if res.fun < f0 else (x0, f0)
    return Search(x, of, (of,), int(res.nfev), f"Nelder-Mead: {res.message.rstrip('.')}")
