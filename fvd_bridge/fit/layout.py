"""The parameter vector of a fit over a device's tests.

Shared parameters appear once; a parameter freed per test (``--per-test``:
a band tension, a temperature-dependent friction) appears once per test:
the model's vector holds the first test's value, and 'NAME@TEST' columns
after it hold the other tests' values.  The tests' force zero
(``fit.zero``), when fitted, is profiled out of the objective: it has no
columns.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import option

#: 'NAME@TEST': a parameter's value on one test of a joint fit
SEP = "@"


@dataclass(frozen=True)
class Layout:
    """Columns of the fitted vector for ``model`` on tests ``tests`` with the
    parameters ``per_test`` freed per test; ``zero``: each test's force zero
    fitted beside them as a nuisance (``fit.zero``: no columns)."""

    model: object  # fvd_bridge.model.Model
    tests: tuple
    per_test: tuple = ()
    zero: bool = False

    def __post_init__(self):
        for name in self.per_test:
            self.model.known_parameter(name, option("--per-test", name))

    @property
    def free(self) -> tuple:
        """The per-test parameters (none with a single test)."""
        return self.per_test if len(self.tests) > 1 else ()

    @property
    def names(self) -> list[str]:
        return list(self.model.names) + [f"{n}{SEP}{t}" for n in self.free for t in self.tests[1:]]

    def repeat(self, per_model: list) -> list:
        """A per-parameter list of the model (units, bounds, log flags) extended to the columns."""
        idx = {n: k for k, n in enumerate(self.model.names)}
        return list(per_model) + [per_model[idx[n]] for n in self.free for _ in self.tests[1:]]

    @property
    def stepped(self) -> list[int]:
        """Columns of the fitted vector on which the OF moves in steps
        (``Model.stepped``: a gap's clearance; per-test ones included)."""
        return [k for k, n in enumerate(self.names) if n.split(SEP)[0] in self.model.stepped]

    def columns(self, test: int) -> list[int]:
        """Columns of the fitted vector that make test ``test``'s model vector."""
        cols = list(range(len(self.model.names)))
        if test == 0:
            return cols
        base = len(cols)
        for k, n in enumerate(self.free):
            cols[self.model.names.index(n)] = base + k * (len(self.tests) - 1) + test - 1
        return cols

    def for_test(self, P: np.ndarray, test: int) -> np.ndarray:
        """(pop, n_cols) -> the model's (pop, n_par) on test ``test``."""
        return np.atleast_2d(P)[:, self.columns(test)]

    def expand(self, values: dict) -> np.ndarray:
        """A full vector from {name: value}: a 'NAME@TEST' column missing from
        ``values`` takes NAME's value."""
        return np.array([values[n] if n in values else values[n.split(SEP)[0]] for n in self.names], dtype=float)
