"""Do the tests of a device agree with one parameter set?

Labs test one device several times, and what they set between tests (a
friction damper's band tension, the oil's temperature, a valve's setting)
can change one parameter from test to test.  A model with one parameter set
then misses every test, and the effects ranked against it fit the tests'
disagreement instead of the device's physics.  So before effects are
ranked, diagnose refits the base model with each parameter of its law
freed per test (``--per-test NAME``), in turn, and with every parameter of
the model freed per test (each test fitted on its own), each a local
least-squares solve from the base optimum (``polish_model``: cheap).  With

    G   = OF_base - OF_own           (the disagreement: what separate fits gain)
    D_p = OF_base - OF_p             (what freeing p alone per test gains)

the parameter p with the largest D_p is advised ("the tests disagree: p
differs between tests ...; calibrate with --per-test p") when

1. D_p passes the effects' noise test (``rank.Judge``: above the noise
   margin and a lower BIC, with n_tests - 1 more parameters);
2. it explains most of the disagreement: D_p >= ``MOST`` G;
3. it lowers the OF more than every effect diagnose credits (an effect
   that holds on held-out tests, ``rank.assess``): a device effect that
   explains more comes first.  Effects that fail a held-out test are not
   compared: fitted to tests that disagree, an effect takes up their
   difference on the tests it saw (on the shared friction damper a 2.8 mm
   gap lowers the joint OF by 13%, beta per test by 10%) and predicts the
   test left out no better or worse, which is what a disagreement looks like.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import repeated
from ..fit import polish_model
from ..fit.layout import Layout
from ..records.device import as_device

#: a parameter freed per test must gain at least this share of what separate fits gain
MOST = 0.5


def free(model, per_test) -> tuple:
    """The names of ``per_test`` that ``model`` has (a candidate keeps the base's)."""
    return tuple(n for n in dict.fromkeys(per_test) if n in model.names)


def per_test_params(model, device, params, per_test=()) -> list[np.ndarray]:
    """Each test's parameter vector of ``model`` from a fit's ``params``
    (its per-test columns, ``fit.layout``)."""
    layout = Layout(model, tuple(device.test_names), free(model, per_test))
    return [layout.for_test(params, k)[0] for k in range(len(device.tests))]


def residuals(model, device, params, per_test=()) -> np.ndarray:
    """F - model over every test, one after the other [kN]."""
    return np.concatenate([t.F - model.force(t, p[None, :])[0]
                           for t, p in zip(device.tests, per_test_params(model, device, params, per_test))])


@dataclass
class PerTest:
    """The base model refitted with one parameter (``name``) freed per test."""

    name: str
    unit: str
    of: float
    values: dict  # {test name: value}
    improvement: float = 0.0  # (OF_base - OF) / OF_base
    share: float = 0.0  # of the disagreement G
    delta_bic: float = 0.0
    n_eff: float = 0.0
    significant: bool = False  # rules 1 and 2 of the module docstring
    reason: str = ""

    def text(self) -> str:
        """'A 1.589, B 2.027 kN/mm': the value on each test."""
        return ", ".join(f"{t} {v:.4g}" for t, v in self.values.items()) + f" {self.unit}"

    def as_dict(self) -> dict:
        return {"name": self.name, "unit": self.unit, "of": self.of, "values": dict(self.values),
                "improvement": self.improvement, "share_of_disagreement": self.share,
                "delta_bic": self.delta_bic, "significant": self.significant, "reason": self.reason}


@dataclass
class Agreement:
    """Whether the tests agree with one parameter set (module docstring):
    the base OF, the OF with every parameter per test (``own_of``), each
    law parameter freed per test (best first) and the advice (None: none)."""

    base_of: float
    own_of: float
    params: list = field(default_factory=list)
    given: tuple = ()  # parameters the base already fits per test
    advice: PerTest | None = None
    why: str = ""  # why there is no advice, when a parameter passed rules 1 and 2

    @property
    def gap(self) -> float:
        """G = OF_base - OF_own: what fitting each test on its own gains."""
        return max(self.base_of - self.own_of, 0.0)

    def verdict(self) -> str:
        a = self.advice
        flag = repeated("--per-test", (*self.given, a.name))
        return (f"the tests disagree: {a.name} differs between tests ({a.text()}; with {a.name} per test OF "
                f"{self.base_of:.4g} -> {a.of:.4g}, {a.share:.0%} of what fitting each test on its own gains); "
                f"calibrate with {flag}")

    def as_dict(self) -> dict:
        return {"of": self.base_of, "of_each_test_on_its_own": self.own_of, "disagreement": self.gap,
                "per_test_given": list(self.given), "params": [p.as_dict() for p in self.params],
                "advice": None if self.advice is None else self.advice.name, "why_no_advice": self.why}


def check(model, base_fit, record, judge, per_test=(), progress=None) -> Agreement | None:
    """Refit ``model`` from ``base_fit`` (its optimum, fitted with
    ``per_test``) with each law parameter not yet per test freed per test,
    and with every parameter per test; judge each (rules 1 and 2 of the
    module docstring).  None for a single test."""
    device = as_device(record)
    if len(device.tests) < 2:
        return None
    given = free(model, per_test)
    values = base_fit.named()
    overrides = dict(base_fit.widened or {})

    def refit(names):
        layout = Layout(model, tuple(device.test_names), names)
        return layout, *polish_model(model, device, layout.expand(values), per_test=names, overrides=overrides)

    _, _, own_of = refit(tuple(model.names))
    out = Agreement(float(base_fit.of), float(min(own_of, base_fit.of)), given=given)
    if progress:
        progress(f"  each test on its own     OF {own_of:.5g} ({(own_of - base_fit.of) / base_fit.of:+.1%})")
    dk = len(device.tests) - 1
    for name in (n for n in model.law.names if n not in given):
        layout, params, of = refit((*given, name))
        split = per_test_params(model, device, params, (*given, name))
        j = model.names.index(name)
        p = PerTest(name, model.units[j], float(of), {t: float(v[j]) for t, v in zip(device.test_names, split)})
        drop = out.base_of - p.of
        p.improvement = drop / out.base_of if out.base_of > 0 else 0.0
        p.share = drop / out.gap if out.gap > 0 else 0.0
        ok, p.reason, p.delta_bic, p.n_eff = judge.verdict(out.base_of, p.of, dk,
                                                           residuals(model, device, params, (*given, name)))
        if ok and p.share < MOST:
            ok, p.reason = False, (f"explains {p.share:.0%} of what fitting each test on its own gains "
                                   f"(needs {MOST:.0%})")
        p.significant = ok
        out.params.append(p)
        if progress:
            progress(f"  {name + ' per test':<24} OF {p.of:.5g} ({-p.improvement:+.1%})")
    out.params.sort(key=lambda p: (not p.significant, p.of, p.name))
    return out


def advise(agreement: Agreement | None, candidates) -> None:
    """Rule 3: the best parameter that passed rules 1 and 2 is advised unless
    an effect diagnose credits lowers the OF more (``candidates``: assessed)."""
    if agreement is None or not agreement.params or not agreement.params[0].significant:
        return
    top = agreement.params[0]
    better = [c for c in candidates if c.significant and c.of < top.of]
    if better:
        agreement.why = (f"{better[0].effect} explains more (OF {better[0].of:.4g} against {top.of:.4g} "
                         f"with {top.name} per test)")
        top.reason = f"helps beyond noise, but {agreement.why}"
        return
    top.reason = "the tests disagree: it explains most of their disagreement"
    agreement.advice = top
    for p in agreement.params[1:]:
        if p.significant:
            p.reason = f"helps beyond noise; {top.name} per test explains more"
