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

A generation costs the kernels' evaluation of its new children and a few
array operations on the (pop, n) population around it: the random numbers
of a generation are drawn in two calls (the parents', then the genes'), in
the order numpy's ``Generator.choice`` and three ``Generator.random`` calls
drew them, so a seed gives the same run as before (benchmarks/bench_ga.py).
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
    history = [float(f.min())]
    stalled = 0
    n_child = s.pop - s.elite
    for gen in range(1, s.gens):
        kept = np.argsort(f)[: s.elite]
        parents = roulette(f, rng.random(2 * n_child))
        take_a, mutate, fresh = rng.random((3, n_child, n))
        children = np.where(take_a < 0.5, X[parents[:n_child]], X[parents[n_child:]])
        children = np.where(mutate < s.mutation, fresh, children)
        np.clip(children, 0.0, 1.0, out=children)
        fc, n_new = _evaluate_new(evaluate, children, X, f)
        evaluations += n_new
        X = np.concatenate([X[kept], children])
        f = np.concatenate([f[kept], fc])
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


def roulette(f: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Indices of the members drawn by roulette wheel on fitness 1/OF (a
    member whose OF is not finite is never drawn; all uniformly when none is
    finite), one per uniform number in ``u``: what
    ``Generator.choice(len(f), len(u), p=fitness / sum)`` draws from those
    numbers."""
    fitness = np.where(np.isfinite(f), 1.0 / np.maximum(f, 1e-300), 0.0)
    total = fitness.sum()
    prob = fitness / total if total > 0 else np.full(f.size, 1.0 / f.size)
    cdf = prob.cumsum()
    cdf /= cdf[-1]
    return cdf.searchsorted(u, side="right")


def _evaluate_new(evaluate, children: np.ndarray, parents: np.ndarray, f_parents: np.ndarray):
    """OF of every child, evaluating only rows not seen among the parents or
    other children (equal bytes), in the rows' lexicographic order.

    Returns (OF per child, number of rows evaluated)."""
    n_par = len(parents)
    rows = np.concatenate([parents[::-1], children])  # a repeated parent's OF: its last copy's
    keys = rows.view(np.dtype((np.void, rows.itemsize * rows.shape[1]))).ravel()
    _, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
    f_rows = np.concatenate([f_parents[::-1], np.full(len(children), np.nan)])[first]
    todo = np.flatnonzero(first >= n_par)
    if todo.size:
        new = rows[first[todo]]
        order = np.lexsort(new.T[::-1])
        f_rows[todo[order]] = evaluate(new[order])
    return f_rows[inverse.ravel()[n_par:]], int(todo.size)
