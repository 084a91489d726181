"""The tests' force zero in a diagnosis: a nuisance of the measurement,
fitted per test beside the model to judge its effects, never exported.

The zero's model and how a test's rests pin it are ``fit.zero``'s (one
place): F_measured = F_device + F0 + F1 (t - t_mid) per test, profiled out
of eq. 18 (``fit_model(..., force_zero=True)``).  Here diagnose fits it
beside a model (``solve``: least squares from the model's optimum, as
``fit.polish_model`` solves) and shows it as the tests' force zero.

An effect that can act like an offset (``Effect.offset_like``:
parallel_stiffness, whose preload F0 is a force at d = 0, v = 0 as the
zero is; asymmetry, F_law + r |F_law|, whose mean over a cycle is
r mean|F_law|, as an offset's is; the other built-in terms are odd over
a cycle: friction, inertia, heating, the connections) is credited only
when it helps beyond noise on top of the zero (``check``):

    OF_z   the base with the zero (from the base's optimum),
    OF_ez  the base with the effect and the zero (from the effect's refit;
           never above OF_z: the effect switched off gives OF_z),
    credited when rank.Judge.verdict(OF_z, OF_ez, dk, residual) holds
    (dk the effect's parameters: the margin and the BIC of every other check);

else it is "explained by the tests' force zero".  Leaving one test out
cannot see a zero the tests share (two tests of one day, one zeroing of
the load cell); this check can.  A preload acts at rest too (its force is
in the model's force at rest), so on a rigid connection a constant preload
is never told apart from the zero: the rests pin zero plus preload, and
only what grows with d (a stiffness) or what the rests do not hold (a
force the motion shows and the rests do not read) counts.  When the zero
was fitted, every calibration the diagnosis recommends is fitted beside
it (``beside``; a candidate judged here, from its fit beside the zero,
``Candidate.zero_fit``): the effects it credits are credited beyond it.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..fit.api import evaluate_params, polish_model, residual_weights
from ..fit.layout import Layout
from ..fit.zero import values as zero_values, zero_force  # noqa: F401  (zero_force: the zero's equation)
from ..records.device import as_device
from ..records.velocity import rest_mask
from .agree import free


@dataclass
class ZeroFit:
    """``solve``'s result: the model's parameters (the fit's layout), each
    test's zero {test: (F0 [kN], F1 [kN/s])}, the model's median force over
    each test's rests [kN] (None without), the OF and the residual
    F - F_model - zero [kN] over every test."""

    params: np.ndarray
    values: dict
    model_at_rest: dict
    of: float
    residual: np.ndarray


def solve(model, params, record, per_test=(), overrides=None) -> ZeroFit:
    """``model`` plus the tests' zero on ``record`` (a Record or a Device),
    fitted by least squares on eq. 18 with the zero profiled out
    (``fit.zero``; FROM_START, as ``fit.polish_model`` solves) from
    ``model``'s ``params`` (a fit's vector, with ``per_test``); never worse
    than that start."""
    device = as_device(record)
    pt = free(model, per_test)
    P, of = polish_model(model, device, np.asarray(params, dtype=float), per_test=pt, overrides=overrides,
                         force_zero=True)
    layout = Layout(model, tuple(device.test_names), pt, True)
    weights = residual_weights(device)
    zero = zero_values(model, device, layout, P, weights)
    residual, rest = [], {}
    for k, test in enumerate(device.tests):
        F = model.force(test, layout.for_test(P[None, :], k))[0]
        residual.append(test.F - F - zero_force(*zero.get(test.name, (0.0, 0.0)), test.t))
        still = rest_mask(test)
        rest[test.name] = float(np.median(F[still])) if still.any() else None
    return ZeroFit(P, zero, rest, float(of), np.concatenate(residual))


def beside(model, fit, record, per_test=()):
    """A FitResult ``fit`` of ``model`` refitted beside the tests' force zero
    (``solve`` from it, within its widened bounds): its parameters, OF, each
    test's OF and the zero (``FitResult.zero``)."""
    return as_fit(model, fit, record, per_test, solve(model, fit.values, record, per_test, dict(fit.widened or {})))


def as_fit(model, fit, record, per_test, solved: ZeroFit):
    """``fit`` (a FitResult of ``model``) as ``solved`` (``solve`` from it)
    left it: its parameters, OF, each test's OF and the zero
    (``FitResult.zero``)."""
    device = as_device(record)
    layout = Layout(model, tuple(device.test_names), free(model, per_test), True)
    test_of = [evaluate_params(model, t, layout.for_test(solved.params[None, :], k)[0], force_zero=True)
               for k, t in enumerate(device.tests)]
    return replace(fit, values=solved.params, of=solved.of, test_of=test_of, zero=solved.values)


@dataclass
class Beside:
    """One offset-like effect judged on top of the zero: OF_ez, the verdict."""

    effect: str
    of: float
    significant: bool
    reason: str

    def as_dict(self) -> dict:
        return {"effect": self.effect, "of_with_zero": self.of, "significant": self.significant,
                "reason": self.reason}


@dataclass
class Zero:
    """The tests' force zero fitted beside the base (module docstring):
    {test: (F0 [kN], F1 [kN/s])}, the base's OF without and with it, each
    test's measured force at rest [kN] (its median over the rests, which
    pin the zero; None without rests), the base's force there and each
    offset-like effect judged on top of it."""

    of_base: float
    of: float
    values: dict
    at_rest: dict
    model_at_rest: dict = field(default_factory=dict)
    effects: list = field(default_factory=list)

    def text(self) -> str:
        """'offset +2.1 kN, drift -0.003 kN/s' (per test, when several)."""
        def one(F0, F1):
            return f"offset {F0:+.3g} kN, drift {F1:+.2g} kN/s"
        if len(self.values) == 1:
            return one(*next(iter(self.values.values())))
        return "; ".join(f"{name}: {one(*v)}" for name, v in self.values.items())

    def lines(self) -> list[str]:
        """The report's lines: each test's zero, its rests' reading, the effects judged beside it."""
        out = [f"the tests' force zero (not exported; F = F_device + F0 + F1 (t - t_mid) per test, pinned by "
               f"the test's rests where it has them: OF {self.of_base:.4g} -> {self.of:.4g} with it):"]
        for name, (F0, F1) in self.values.items():
            rest = self.at_rest.get(name)
            model = self.model_at_rest.get(name)
            out.append(f"  {name}: offset F0 {F0:+.3g} kN, drift F1 {F1:+.2g} kN/s"
                       + (" (no rests: fitted on the motion)" if rest is None
                          else f" (at rest the force reads {rest:+.3g} kN, the model's {model:+.3g} kN)"))
        for b in self.effects:
            out.append(f"  {b.effect} on top of it: OF {b.of:.4g}, "
                       + ("helps beyond noise beside it" if b.significant else b.reason))
        return out

    def as_dict(self) -> dict:
        return {"of_base": self.of_base, "of": self.of,
                "tests": {name: {"F0_kN": F0, "F1_kN_per_s": F1, "at_rest_kN": self.at_rest.get(name),
                                 "model_at_rest_kN": self.model_at_rest.get(name)}
                          for name, (F0, F1) in self.values.items()},
                "effects": [b.as_dict() for b in self.effects], "exported": False}


def at_rest(record) -> dict:
    """{test: median measured force over its rests [kN], None without rests}."""
    out = {}
    for test in as_device(record).tests:
        still = rest_mask(test)
        out[test.name] = float(np.median(test.F[still])) if still.any() else None
    return out


def check(model, base_fit, record, candidates, judge, per_test=(), progress=None) -> Zero | None:
    """Judge each credited offset-like candidate (``Effect.offset_like``)
    on top of the tests' force zero (module docstring); one the zero
    explains loses its credit, its reason saying so.  None when no
    credited candidate can act as an offset (then nothing is fitted: the
    check costs one local solve for the base and one per such candidate)."""
    device = as_device(record)
    judged = [c for c in candidates if c.significant and c.model.effects[-1].offset_like and not c.replaces]
    if not judged:
        return None
    overrides = dict(base_fit.widened or {})
    fit = solve(model, base_fit.values, device, per_test, overrides)
    zero = Zero(float(base_fit.of), fit.of, fit.values, at_rest(device), fit.model_at_rest)
    if progress:
        progress(f"  the tests' force zero     OF {zero.of:.5g} ({(zero.of - base_fit.of) / base_fit.of:+.1%})")
    for c in judged:
        with_effect = solve(c.model, c.fit.values, device, per_test, {**overrides, **dict(c.fit.widened or {})})
        c.zero_fit = as_fit(c.model, c.fit, device, per_test, with_effect)  # what a calibration of it is written from
        of_c = min(with_effect.of, zero.of)  # the effect switched off gives the base's zero fit
        ok, why, _, _ = judge.verdict(zero.of, of_c, len(c.model.parameters) - len(model.parameters),
                                      with_effect.residual)
        zero.effects.append(Beside(c.effect, of_c, ok, why))
        if progress:
            progress(f"  + {c.effect} beside it{'':<{max(0, 13 - len(c.effect))}} OF {of_c:.5g}")
        if not ok:
            c.significant = False
            c.reason = f"explained by the tests' force zero ({zero.text()}): beside it, {why}"
        else:
            c.reason += f"; beyond the tests' force zero too (OF {zero.of:.4g} -> {of_c:.4g})"
    return zero
