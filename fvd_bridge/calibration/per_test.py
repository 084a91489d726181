"""One test's calibration out of one with parameters fitted per test
(``Calibration.for_test``): the refusal that names the tests, and the
intervals that test keeps."""

from __future__ import annotations

from dataclasses import replace

from ..errors import option
from ..fit.layout import SEP
from ..text.calibration import per_test_text


def refusal(cal) -> str:
    """'cal.yaml: beta was fitted per test (A: 2.1, B: 3.35 kN/mm); name one with --test A or --test B'."""
    tests = " or ".join(option("--test", t.name) for t in cal.tests)
    return f"{cal.where()}: {per_test_text(cal)}; name one with {tests}"


def intervals_on(intervals, test: str, first: str, per_test: tuple):
    """One test's intervals: a parameter fitted per test takes that test's
    ('C@B' as 'C'; none when not computed); the other tests' columns, the
    correlation and (on a test but the first) the derived quantities' are left out."""
    if intervals is None:
        return None
    own = {n: e for n, e in intervals.parameters.items() if SEP not in n and (n not in per_test or test == first)}
    if test != first:
        own.update({n: intervals.parameters[f"{n}{SEP}{test}"] for n in per_test
                    if f"{n}{SEP}{test}" in intervals.parameters})
    return replace(intervals, parameters=own, correlation=None, derived=intervals.derived if test == first else {})

