"""The tests' force zero of a calibration (``calibrate --force-zero
per-test``): per test an offset F0 [kN] and a drift F1 [kN/s] fitted beside
the model as a nuisance of the measurement (``fit.zero``), with their
intervals.  The file keeps it in a block of its own::

    force_zero:                          # never exported: not the device's
      equation: F_measured = F_device + F0 + F1 (t - t_mid), per test
      tests:
        TEST: {F0: {value, unit: kN, stderr, ci95}, F1: {value, unit: kN/s, stderr, ci95},
               pinned_by: its rests at both ends | its rests (at one end: no drift) | its motion}

It is never part of the Model: exports, ``Calibration.force`` and
``compare`` read the device's force only.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..report.numbers import interval, rounded

EQUATION = "F_measured = F_device + F0 + F1 (t - t_mid), per test"
UNITS = {"F0": "kN", "F1": "kN/s"}


@dataclass(frozen=True)
class ForceZero:
    """Per test {F0: {value, unit, stderr, ci95}, F1: ..., pinned_by}: the
    tests' force zero fitted beside the model (module docstring)."""

    tests: dict = field(default_factory=dict)

    @classmethod
    def of_fit(cls, fit, device, intervals=None) -> "ForceZero | None":
        """The tests' force zero of a fit that fitted it (``FitResult.zero``),
        with its intervals (``fit.intervals.Intervals``) and how each test's
        is pinned; None: not fitted."""
        if not fit.zero:
            return None
        from ..fit.api import residual_weights
        from ..fit.zero import how_pinned

        return cls.of(fit.zero, getattr(intervals, "zero", None), how_pinned(device, residual_weights(device)))

    @classmethod
    def of(cls, zero: dict, intervals: dict | None = None, pinned: dict | None = None) -> "ForceZero":
        """From a fit's zero {test: (F0, F1)}, the bootstrap's
        (``fit.intervals.Intervals.zero``) and how each test's is pinned."""
        out = {}
        for test, values in zero.items():
            given = (intervals or {}).get(test) or {}
            out[test] = {name: {"value": float(v), "unit": UNITS[name],
                                **{k: given[name][k] for k in ("stderr", "ci95") if k in given.get(name, {})}}
                         for name, v in zip(("F0", "F1"), values)}
            if pinned and test in pinned:
                out[test]["pinned_by"] = pinned[test]
        return cls(out)

    @classmethod
    def from_dict(cls, block) -> "ForceZero | None":
        """From the file's block (None: none)."""
        if isinstance(block, ForceZero) or not block:
            return block or None
        return cls(dict(block.get("tests") or {}))

    def as_dict(self) -> dict:
        """The file's block."""
        return {"equation": EQUATION, "exported": False, "tests": self.tests}

    def values(self) -> dict:
        """{test: (F0 [kN], F1 [kN/s])}."""
        return {test: (z["F0"]["value"], z["F1"]["value"]) for test, z in self.tests.items()}

    def lines(self) -> list[str]:
        """The report's lines: each test's offset and drift with their intervals."""
        out = [f"the tests' force zero (a nuisance fitted beside the model, not exported; {EQUATION}):"]
        for test, z in self.tests.items():
            parts = [_quantity(name, z[name]) for name in ("F0", "F1")]
            how = f" (pinned by {z['pinned_by']})" if z.get("pinned_by") else ""
            out.append(f"{test}: {', '.join(parts)}{how}")
        return out


def _quantity(name: str, q: dict) -> str:
    """'F0 = -2.03 kN, 95% [-2.4, -1.7]' (without an interval: the value)."""
    stderr, ci = q.get("stderr"), q.get("ci95")
    if ci is None or stderr is None:
        return f"{name} = {rounded(q['value'])} {q['unit']}"
    if ci[0] == ci[1]:
        return f"{name} = {rounded(q['value'])} {q['unit']} (held)"
    return f"{name} = {rounded(q['value'], stderr)} {q['unit']}, 95% {interval(*ci, stderr)}"
