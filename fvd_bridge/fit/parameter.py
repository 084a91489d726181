"""FittedParameter: one parameter of a fit (``FitResult.params``) or of
a calibration (``Calibration.params``)."""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class FittedParameter:
    """One fitted parameter: ``value`` [``unit``]; ``stderr`` and the 95%
    interval ``ci95`` (lower, upper) of the bootstrap (``fit.intervals``;
    None: not computed, as for a fit); the search ``bounds`` (lower, upper;
    None where unknown); ``per_test``: {test: value} of a parameter fitted
    per test; ``fixed``: held at its value by the caller (lower bound ==
    upper bound); ``start``: the start value the caller gave (None: the
    data's start)."""

    name: str
    value: float
    unit: str
    stderr: float | None = None
    ci95: tuple | None = None
    bounds: tuple = (None, None)
    per_test: dict = field(default_factory=dict)
    fixed: bool = False
    start: float | None = None

    def __float__(self) -> float:
        return float(self.value)

    def text(self) -> str:
        """'C = 45.06 +/- 0.05 (0.11%) kN/(mm/s)^alpha, 95% [44.96, 45.16]';
        a fixed one 'alpha = 0.3 (fixed)' (its interval is its value)."""
        unit = f" {self.unit}" if self.unit != "-" else ""
        if self.fixed:
            return f"{self.name} = {self.value:.6g}{unit} (fixed)"
        out = f"{self.name} = {self.value:.6g}"
        if self.stderr is not None:
            rel = f" ({abs(self.stderr / self.value):.2%})" if self.value else ""
            out += f" +/- {self.stderr:.2g}{rel}"
        out += unit
        if self.ci95 is not None:
            out += f", 95% [{self.ci95[0]:.6g}, {self.ci95[1]:.6g}]"
        return out

    def __repr__(self) -> str:
        return f"<FittedParameter {self.text()}>"
