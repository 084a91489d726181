"""The paper's real-coded genetic algorithm (section 4.2, Table 3).

Roulette-wheel selection on fitness 1/OF, uniform crossover of two parents
(each gene from either parent with probability 1/2), mutation resetting a gene
uniformly within its bounds with probability ``mutation``, genes clipped to
the bounds, elitism (the best individual is copied into the next
generation); stop after ``gens`` generations or ``stall`` generations
without improvement of the best OF.  The whole population is evaluated at
once by the vectorized kernels; a child identical to another child or to a
member of the previous generation (common once the population converges:
uniform crossover of two equal parents) reuses that OF instead of being
evaluated again, which changes nothing but the work.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .search import Search


@dataclass(frozen=True)
class GASettings:
    """Table 3 defaults: population 200, 200 generations, stall 20, 1% mutation."""

    pop: int = 200
    gens: int = 200
    stall: int = 20
    mutation: float = 0.01
    elite: int = 1


def run_ga(evaluate, n: int, rng: np.random.Generator, s: GASettings = GASettings(), on_generation=None) -> Search:
    """Minimise ``evaluate(X) -> OF`` over the unit cube [0, 1]^n.

    ``on_generation(gen, best_of)`` is called after every generation.
    """
    X = rng.random((s.pop, n))
    f = evaluate(X)
    evaluations = s.pop
    best = int(np.argmin(f))
    history = [float(f[best])]
    stalled = 0
    for gen in range(1, s.gens):
        order = np.argsort(f)
        elite = X[order[: s.elite]]
        fitness = 1.0 / np.maximum(f, 1e-300)
        fitness = np.where(np.isfinite(f), fitness, 0.0)
        prob = fitness / fitness.sum() if fitness.sum() > 0 else np.full(s.pop, 1.0 / s.pop)
        n_child = s.pop - s.elite
        pa = rng.choice(s.pop, n_child, p=prob)
        pb = rng.choice(s.pop, n_child, p=prob)
        take_a = rng.random((n_child, n)) < 0.5
        children = np.where(take_a, X[pa], X[pb])
        mutate = rng.random((n_child, n)) < s.mutation
        children = np.clip(np.where(mutate, rng.random((n_child, n)), children), 0.0, 1.0)
        fc, n_new = _evaluate_new(evaluate, children, X, f)
        evaluations += n_new
        X = np.vstack([elite, children])
        f = np.concatenate([f[order[: s.elite]], fc])
        best_now = float(f.min())
        stalled = stalled + 1 if best_now >= history[-1] else 0
        history.append(min(best_now, history[-1]))
        if on_generation:
            on_generation(gen, history[-1])
        if stalled >= s.stall:
            stop = f"GA: no better point in {s.stall} generations (generation {gen + 1})"
            break
    else:
        stop = f"GA: all {s.gens} generations"
    best = int(np.argmin(f))
    return Search(X[best], float(f[best]), tuple(history), evaluations, stop)


def _evaluate_new(evaluate, children: np.ndarray, parents: np.ndarray, f_parents: np.ndarray):
    """OF of every child, evaluating only rows not seen among the parents or other children.

    Returns (OF per child, number of rows evaluated)."""
    known = {row.tobytes(): fp for row, fp in zip(parents, f_parents)}
    unique, inverse = np.unique(children, axis=0, return_inverse=True)
    f_unique = np.array([known.get(row.tobytes(), np.nan) for row in unique])
    todo = np.flatnonzero(np.isnan(f_unique))
    if todo.size:
        f_unique[todo] = evaluate(unique[todo])
    return f_unique[inverse.ravel()], int(todo.size)

