"""What a search back-end hands back, and the count of evaluations it shares.

Every back-end (``local``, ``de``, ``ga`` and the Nelder-Mead ``polish``)
minimises eq. 18 over the unit cube and returns a ``Search``: the point, its
OF, the best OF after each generation or start, how many parameter sets it
evaluated and why it stopped, in words a report can print.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Search:
    """x: the best point of the unit cube (n,); of: its OF (eq. 18);
    history: the best OF after each generation or start; evaluations:
    parameter sets evaluated; stop: why the search stopped."""

    x: np.ndarray
    of: float
    history: tuple
    evaluations: int
    stop: str

    def then(self, other: "Search") -> "Search":
        """This search followed by ``other`` (started from this one's end):
        the better end, both histories, both counts, the last stop."""
        best = other if other.of < self.of else self
        return Search(best.x, best.of, self.history + other.history, self.evaluations + other.evaluations,
                      other.stop)


class Evaluations:
    """The count of parameter sets evaluated, shared by a search and the
    helpers it calls (``n``; ``add(k)``)."""

    def __init__(self, n: int = 0):
        self.n = int(n)

    def add(self, k: int) -> None:
        self.n += int(k)
