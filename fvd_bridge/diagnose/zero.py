"""The tests' force zero: a nuisance of the measurement, fitted per test, never exported.

A load cell is zeroed before a test day, its zero moves from day to day and
drifts slowly during a test (temperature, the amplifier).  What it reads is

    F_measured = F_device + F0 + F1 (t - t_mid),    t_mid = (t_start + t_end) / 2

with a force offset F0 [kN] and a drift F1 [kN/s], one pair per test
(``zero_force``).  Both belong to the test, not to the device: diagnose
fits them beside a model only to judge its effects and shows them as the
tests' force zero; they never enter a Model, so no calibration file,
spec or exporter ever carries them.

The rests are the evidence of the zero: there the actuator holds still
(``records.velocity.rest_mask``: v = a = 0 as read), the model's force is
its force at rest, and what the load cell reads beyond it is the zero
itself, with no misfit of the law's to take it up.  So a test with rests
has its zero pinned by them (``RestPin``): F0 (and F1, when the rests lie
at both ends of the test, at least ``BOTH_ENDS`` of its duration apart)
follow from the median of the rests' residual, F_measured - F_model, at
each end, for the model's parameters of the moment (a profile: not free
parameters); with rests at one end only, F1 = 0 (one end cannot tell a
drift).  A test
without rests has F0 and F1 free, fitted on its motion.  The objective is
eq. 18 over every sample, rests included (``solve``: least squares from
the model's optimum, as ``fit.polish_model`` solves).

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
force the motion shows and the rests do not read) counts.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..fit.api import apply_overrides
from ..fit.layout import Layout
from ..fit.local import FROM_START, run_local
from ..fit.objective import objective_weights
from ..fit.space import Space
from ..records.device import as_device
from ..records.velocity import rest_mask
from .agree import free

#: rests pin the drift too when they lie this share of the test's duration apart (start and end)
BOTH_ENDS = 0.5
#: bounds of a free zero: |F0| <= ZERO_SPAN F, |F1| <= ZERO_SPAN F v / d (the peak force over
#: the time of one radian of the fastest cycle: any slow drift is inside)
ZERO_SPAN = 0.3


def zero_force(F0, F1, t) -> np.ndarray:
    """The load cell's zero F0 + F1 (t - t_mid) [kN] on the test's clock t [s]
    (t_mid its middle); F0 [kN], F1 [kN/s] scalars or (pop, 1) columns."""
    t = np.asarray(t, dtype=float)
    return F0 + F1 * (t - 0.5 * (t[0] + t[-1]))


@dataclass(frozen=True)
class RestPin:
    """The rests of one test, in two groups (before and after its middle
    time, t_mid), and the zero they read: the median of the residual over
    each group (eq. 18's L1 constant, robust to a sample at a rest's edge
    where the motion has begun), a line through the two medians (at the
    groups' median times) when they lie at least BOTH_ENDS of the test's
    duration apart, else that constant with F1 = 0."""

    groups: tuple  # boolean (n,) masks, one or two
    times: tuple  # their median times [s] - t_mid

    @classmethod
    def of(cls, test) -> "RestPin | None":
        still = rest_mask(test)
        if not still.any():
            return None
        mid = 0.5 * (test.t[0] + test.t[-1])
        groups = [g for g in (still & (test.t < mid), still & (test.t >= mid)) if g.any()]
        times = [float(np.median(test.t[g])) - mid for g in groups]
        if len(groups) == 2 and times[1] - times[0] < BOTH_ENDS * (test.t[-1] - test.t[0]):
            groups, times = [still], [float(np.median(test.t[still])) - mid]
        return cls(tuple(groups), tuple(times))

    @property
    def still(self) -> np.ndarray:
        return np.logical_or.reduce(self.groups)

    def zero(self, r: np.ndarray) -> np.ndarray:
        """(pop, 2) (F0, F1) of residuals r (pop, n) = F_measured - F_model."""
        r = np.atleast_2d(r)
        m = [np.median(r[:, g], axis=1) for g in self.groups]
        if len(m) == 1:
            return np.column_stack([m[0], np.zeros(len(r))])
        ta, tb = self.times
        slope = (m[1] - m[0]) / (tb - ta)
        return np.column_stack([m[0] - slope * ta, slope])


class ZeroProblem:
    """Eq. 18 of ``model`` plus each test's zero on a device (module
    docstring): the model's parameters (``Layout``, the caller's per-test
    ones too) and (F0, F1) of each test without rests are the unknowns;
    the zero of a test with rests follows from them (``RestPin``)."""

    def __init__(self, model, device, per_test=(), overrides=None, start=None):
        self.model, self.device = model, device
        self.layout = Layout(model, tuple(device.test_names), tuple(per_test))
        s = device.scales()
        b = np.array(self.layout.repeat(list(model.bounds("auto", s))), dtype=float)
        b = apply_overrides(self.layout.names, model.spec, b, overrides or {})
        log = list(self.layout.repeat(list(model.log_scale("auto"))))
        self.pins = [RestPin.of(t) for t in device.tests]
        self.free = [k for k, p in enumerate(self.pins) if p is None]
        span = ZERO_SPAN * s["F"]
        for _ in self.free:
            b = np.vstack([b, [-span, span], [-span * s["v"] / s["d"], span * s["v"] / s["d"]]])
            log += [False, False]
        if start is not None:  # the start inside (a widened bound of the base's)
            b[:, 0], b[:, 1] = np.minimum(b[:, 0], start), np.maximum(b[:, 1], start)
        self.space = Space.of(b, log)
        self.c = [w * objective_weights(t.F, t.t) if w != 0.0 else None
                  for t, w in zip(device.tests, device.weights)]

    @property
    def n_model(self) -> int:
        return len(self.layout.names)

    def parts(self, P) -> list:
        """Per test: (model force (pop, n), zero (pop, 2)) of parameter rows P (pop, n_cols)."""
        P = np.atleast_2d(P)
        out, j = [], self.n_model
        for k, (test, pin) in enumerate(zip(self.device.tests, self.pins)):
            F = self.model.force(test, self.layout.for_test(P[:, :self.n_model], k))
            if pin is None:
                z = P[:, j:j + 2]
                j += 2
            else:
                z = pin.zero(test.F[None, :] - F)
            out.append((F, z))
        return out

    def residuals(self, X) -> np.ndarray:
        """w_k c (F_model + zero - F), test after test: eq. 18's terms (pop, sum n)."""
        P = self.space.to_params(np.atleast_2d(X))
        return np.concatenate([c * (F + zero_force(z[:, :1], z[:, 1:], t.t) - t.F)
                               for (F, z), t, c in zip(self.parts(P), self.device.tests, self.c) if c is not None],
                              axis=-1)

    def evaluate(self, X) -> np.ndarray:
        of = np.abs(self.residuals(X)).sum(axis=-1)
        return np.where(np.isfinite(of), of, np.inf)

    def values(self, P) -> tuple[dict, dict]:
        """({test: (F0 [kN], F1 [kN/s])}, {test: the model's median force over
        its rests [kN], None without rests}) at one parameter row."""
        parts = self.parts(np.asarray(P)[None, :])
        zeros = {name: (float(z[0, 0]), float(z[0, 1])) for name, (_, z) in zip(self.device.test_names, parts)}
        rest = {name: None if pin is None else float(np.median(F[0, pin.still]))
                for name, (F, _), pin in zip(self.device.test_names, parts, self.pins)}
        return zeros, rest


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


def solve(model, params, record, per_test=(), overrides=None, zero=None) -> ZeroFit:
    """``model`` plus the tests' zero on ``record`` (a Record or a Device),
    fitted by least squares on eq. 18 (``ZeroProblem``; FROM_START, as
    ``fit.polish_model`` solves) from ``model``'s ``params`` (a fit's
    vector, with ``per_test``) and, for a test without rests, its zero
    ``zero[test]`` = (F0, F1) (default the least-squares line through its
    residual); never worse than that start."""
    device = as_device(record)
    pt = free(model, per_test)
    params = np.asarray(params, dtype=float)
    layout = Layout(model, tuple(device.test_names), pt)
    start = [params]
    for k in (k for k, t in enumerate(device.tests) if RestPin.of(t) is None):
        test, name = device.tests[k], device.test_names[k]
        if zero is not None:
            start.append(np.asarray(zero[name], dtype=float))
            continue
        r = test.F - model.force(test, layout.for_test(params[None, :], k))[0]
        A = np.column_stack([np.ones(test.n), test.t - 0.5 * (test.t[0] + test.t[-1])])
        start.append(np.linalg.lstsq(A, r, rcond=None)[0])
    x0 = np.concatenate(start)
    prob = ZeroProblem(model, device, pt, overrides, x0)
    u0 = prob.space.to_unit(x0)[None, :]
    found = run_local(prob.evaluate, prob.residuals, prob.space.n, np.random.default_rng(0), FROM_START, None, u0,
                      prob.layout.stepped)
    x, of = found.x, found.of
    P = prob.space.to_params(x) if of < prob.evaluate(u0)[0] else x0
    r = prob.residuals(prob.space.to_unit(P)[None, :])[0]
    weights = np.concatenate([c for c in prob.c if c is not None])
    return ZeroFit(P[:prob.n_model], *prob.values(P), float(np.abs(r).sum()), r / weights)


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
    fit = solve(model, base_fit.params, device, per_test, overrides)
    zero = Zero(float(base_fit.of), fit.of, fit.values, at_rest(device), fit.model_at_rest)
    if progress:
        progress(f"  the tests' force zero     OF {zero.of:.5g} ({(zero.of - base_fit.of) / base_fit.of:+.1%})")
    for c in judged:
        with_effect = solve(c.model, c.fit.params, device, per_test, overrides, fit.values)
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
