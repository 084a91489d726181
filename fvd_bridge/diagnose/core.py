"""diagnose: fit a model, show where it fails, rank every missing effect by a
real refit, and compare what is left with the record's own noise floor.

The base is fitted as ``calibrate`` fits it (its default optimizer settings
and its first run's seed), so both report the same base OF.  Every candidate
starts from the base optimum with its effect switched off; when a refit
shows that the base itself can go lower (the refit with its effect switched
off is below the base), the base is polished from there and every
candidate whose OF is above the new base is refitted, until no refit finds
a lower base (at most ``MAX_BASE_ROUNDS`` rounds).  Gains are measured
against that converged base; the noise floor counts the record's force and
displacement noise (``floor.py``).

Given several tests of one device (a Device), the base and every candidate
are fitted to the tests together, the floor is the tests' weighted mean,
the residual's analysis and the effects' sizes are those of the test the
base misses most (the focus), and the held-out check leaves one test out
in turn.  Before effects are ranked, each law parameter is freed per test
in turn: where one explains most of how the tests disagree, the verdict
says so first (``agree.py``).  An effect that can act as a force offset
(a preload, an asymmetry) is credited only beyond the tests' force zero,
an offset and drift fitted per test as a nuisance (``zero.py``).  ``per_test``: parameters the base and every
candidate fit per test (``--per-test``, as calibrate fits them)."""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from typing import NamedTuple

import numpy as np

from ..catalog import catalog as default_catalog
from .. import timing
from ..errors import InputError
from ..fit import DEFAULT_OPTIMIZER, evaluate_params, fit_model, polish_model, settings_for
from ..fit.layout import Layout
from ..fit.objective import NEAR_FLOOR
from ..fit.intervals import REPLICATES, intervals as bootstrap
from ..fit.result import Parent
from ..model import EXPORT_TARGETS, export_target
from ..records.device import as_device
from . import where as where_mod
from . import agree, zero as zero_mod
from ..fit.floor import NoiseFloor, record_floor
from .rank import Candidate, Judge, assess, lower_base, refit_all

#: rounds of "a refit found a lower base: polish the base, refit again"
MAX_BASE_ROUNDS = 3
#: a base counts as lowered when its OF falls by more than this fraction
BASE_TOL = 1e-6

#: diagnose's cap on the generations of the DE check a model declaring
#: global_search gets (calibrate's: 300; a diagnosis runs 1 + 7 fits and the
#: ladder many more, and the check stops after 20 without a better point)
DIAGNOSE_GENS = 120


def diagnose_settings(pop: int | None = None, gens: int | None = None):
    """Settings of diagnose's fits: the default optimizer's (``local``); a
    model that declares global_search gets its DE check with population
    ``pop`` per parameter and at most ``gens`` generations.  None keeps the
    diagnose default."""
    return settings_for(DEFAULT_OPTIMIZER, pop, gens or DIAGNOSE_GENS)


class BaseRound(NamedTuple):
    """One round of a diagnosis' base fit: ``how`` it was reached, its ``of`` (eq. 18)."""

    how: str
    of: float


class TestOF(NamedTuple):
    """One test of a diagnosed device: its ``name`` and the base fit's ``of`` (eq. 18) on it."""

    __test__ = False  # a data record, not a pytest class
    name: str
    of: float


@dataclass(frozen=True)
class DiagnosisInputs:
    """What a diagnosis was run on: ``Diagnosis.ladder()`` and ``accept()`` go on from there."""

    record: object
    """The Record or Device diagnosed (kN, mm, s)."""
    seed: int
    """The seed of its fits."""
    settings: object
    """Its fits' optimizer settings (``diagnose_settings``)."""
    catalog: object
    """The Catalog its model and candidate effects came from."""
    floors: list
    """Per test, its NoiseFloor (``floor.record_floor``)."""


@dataclass
class Diagnosis:
    """The result of ``diagnose``: the fitted model, where it fails, the
    noise floor and the ranked candidate effects."""

    record: str
    model: object  # fvd_bridge.model.Model
    fit: object
    F_model: np.ndarray
    noise_std: float
    judge: Judge
    where: where_mod.Where
    candidates: list = field(default_factory=list)
    wall_s: float = 0.0
    parent: Parent | None = None  # the model without the last effect: its spec and OF
    noise: NoiseFloor | None = None  # the record's noise floor (a device: the weighted mean of its tests')
    base_history: list = field(default_factory=list)  # a BaseRound per round of the base fit
    tests: list = field(default_factory=list)  # a TestOF per test of a device (one test: none)
    focus: object = None  # the Record analysed (a device: the test the base misses most)
    per_test: tuple = ()  # parameters fitted per test (--per-test)
    agreement: agree.Agreement | None = None  # do the tests agree with one parameter set (several tests)
    zero: zero_mod.Zero | None = None  # the tests' force zero, when an offset-like effect needed it (not exported)
    inputs: DiagnosisInputs | None = field(default=None, repr=False)  # what it was run on: ladder() and accept()
    target: str | None = None  # where the model must go (EXPORT_TARGETS; None: anywhere)
    #: the ladder's climb (``ladder.py`` sets it on import: the ladder sits above the diagnosis)
    _climb = None

    def __repr__(self) -> str:
        return f"<Diagnosis {self.spec} on {self.record}: OF {self.of:.4g}; {self.verdict()}>"

    def _repr_html_(self) -> str:
        from ..report.html import diagnosis_table

        return diagnosis_table(self)

    def candidate(self, effect: str) -> Candidate:
        """The candidate that adds an effect.

        Parameters
        ----------
        effect : str
            The effect's name, e.g. ``"friction"``.

        Returns
        -------
        Candidate
            Its refit (``.fit``), OF, improvement and verdict.
        """
        for c in self.candidates:
            if c.effect == effect:
                return c
        raise InputError(f"effect '{effect}': not a candidate of this diagnosis "
                         f"(candidates: {', '.join(c.effect for c in self.candidates) or 'none'})")

    def accept(self, effect: str | None = None, *, intervals: int = REPLICATES):
        """The model with an effect added, as diagnose refitted it: no second calibration.

        When the diagnosis fitted the tests' force zero (``zero``), the
        refit is refitted beside it (``zero.beside``): an effect credited
        beyond the zero is exported as fitted beyond it.

        Parameters
        ----------
        effect : str, optional
            The effect to add; None: the best candidate (the one that helps most beyond noise).
        intervals : int
            Bootstrap replicates of the 95% intervals, as ``calibrate``'s (0: none).

        Returns
        -------
        Calibration
            The refit, ready to save and export (a candidate diagnose did
            not credit carries that as a warning; the force zero, when
            fitted, in its ``force_zero``, never exported).
        """
        if effect is None and self.best is None:
            raise InputError(f"diagnosis of {self.spec}: no candidate helps beyond noise; "
                             f"accept(effect=...) takes one by name")
        c = self.best if effect is None else self.candidate(effect)
        settings = {"source": "diagnose", "seed": self.inputs.seed, "optimizer": DEFAULT_OPTIMIZER}
        warnings = [] if c.significant else [f"{c.effect} was not credited by diagnose: {c.reason}"]
        fit = c.fit_to_write(self.zero is not None)
        return recommended(c.model, fit, self.inputs.record, settings, zero=self.zero is not None,
                           per_test=self.per_test, seed=self.inputs.seed, replicates=intervals, warnings=warnings)

    def ladder(self, max_rungs: int | None = None, progress=None):
        """The ladder from this diagnosis' model on the same record (``climb``).

        Parameters
        ----------
        max_rungs : int, optional
            Stop after this many added effects.
        progress : callable, optional
            ``progress(message)`` receives one line per fit.

        Returns
        -------
        Ladder
            Each rung's model, OF and gain, and each rung's diagnosis.
        """
        i = self.inputs
        return self._climb(i.record, self.model, seed=i.seed, settings=i.settings, max_rungs=max_rungs,
                           progress=progress, catalog=i.catalog, per_test=self.per_test, target=self.target)

    @property
    def spec(self) -> str:
        """The diagnosed model's spec."""
        return self.model.spec

    @property
    def of(self) -> float:
        """The model's OF (eq. 18) on the record."""
        return float(self.fit.of)

    @property
    def floor(self) -> float:
        """The OF that the record's noise alone gives (the noise floor)."""
        return float(self.judge.floor)

    @property
    def at_floor(self) -> bool:
        """Whether the model's OF is at the noise floor: nothing left to explain."""
        return self.judge.at_floor(self.of)

    @property
    def credited(self) -> list[Candidate]:
        """Candidates that help beyond noise, best first, wherever they export."""
        return [c for c in self.candidates if c.significant]

    @property
    def suggestions(self) -> list[Candidate]:
        """Candidates that help beyond noise and reach the ``target``, best first."""
        return [c for c in self.credited if self.reaches(c)]

    def reaches(self, candidate: Candidate) -> bool:
        """Whether a candidate's model exports to the ``target``.

        Parameters
        ----------
        candidate : Candidate
            One of ``candidates``.

        Returns
        -------
        bool
            True where it exports there, or without a target.
        """
        return self.target is None or not candidate.exports[self.target]

    @property
    def left_out(self) -> Candidate | None:
        """The best credited candidate, when the ``target`` leaves it out (None: it reaches the target)."""
        c = self.credited
        return c[0] if c and not self.reaches(c[0]) else None

    def target_refusal(self) -> str:
        """Why the diagnosed model itself does not reach the ``target`` ('' when it does or there is none)."""
        return self.model.exports(self.named())[self.target] if self.target else ""

    @property
    def advice(self) -> agree.PerTest | None:
        """The parameter the tests disagree on, when freeing it per test
        explains their disagreement (``agree.py``; None: they agree)."""
        return None if self.agreement is None else self.agreement.advice

    @property
    def best(self) -> Candidate | None:
        """The candidate that helps most beyond noise (None: none does)."""
        s = self.suggestions
        return s[0] if s else None

    def on_bound(self, tol: float = 1e-3) -> list[tuple[str, str]]:
        """Parameters that ended on a bound (see FitResult.on_bound).

        Parameters
        ----------
        tol : float
            How close to a bound counts as on it, as a share of the range.
        """
        return self.fit.on_bound(tol)

    @property
    def params(self) -> dict:
        """{name: FittedParameter} of the diagnosed model's fit (``FitResult.params``):
        the estimate [its unit], the search bounds, fixed; as ``Calibration.params``."""
        return self.fit.params

    def named(self) -> dict:
        """{name: value} of the diagnosed model's fit [each its unit], as ``Calibration.named``."""
        return self.fit.named()

    def units(self) -> dict:
        """{name: unit} of the diagnosed model's parameters (a ladder's rung and ``as_dict`` carry them)."""
        return {n: p.unit for n, p in self.params.items()}

    def as_dict(self) -> dict:
        """The --json report: model, of, noise_floor_of, candidates (only those
        that help beyond noise, best first), then the details."""
        return {
            "model": self.spec,
            "of": self.of,
            "noise_floor_of": self.floor,
            "candidates": [{"effect": c.effect, "of": c.of, "improvement": c.improvement}
                           for c in self.suggestions],
            "record": self.record,
            "at_noise_floor": self.at_floor,
            "parent": None if self.parent is None else {"model": self.parent.spec, "of": self.parent.of},
            "verdict": self.verdict(),
            "noise_std_kN": self.noise_std,
            "noise": None if self.noise is None else self.noise.as_dict(),
            "noise_margin_of": self.judge.margin,
            "base_history": [r._asdict() for r in self.base_history],
            "tests": [t._asdict() for t in self.tests],
            "focus": getattr(self.focus, "name", self.record),
            "per_test": list(self.per_test),
            "agreement": None if self.agreement is None else self.agreement.as_dict(),
            "force_zero": None if self.zero is None else self.zero.as_dict(),
            "params": self.named(),
            "units": self.units(),
            "on_bound": [list(x) for x in self.on_bound()],
            "where": self.where.as_dict(),
            "all_candidates": [c.as_dict() for c in self.candidates],
            "target": self.target,
            "left_out": None if self.left_out is None else {"spec": self.left_out.spec, "of": self.left_out.of,
                                                            "why": self.left_out.exports[self.target]},
            "wall_s": self.wall_s,
        }

    def verdict(self) -> str:
        """What to do next, in one line.

        Returns
        -------
        str
            Nothing left to explain, the parameter the tests disagree on,
            the effect to add, or why none helps.
        """
        if self.at_floor and self.best is None and self.advice is None:
            return (f"nothing left to explain: OF {self.of:.4g} is at the noise floor {self.floor:.4g} "
                    f"(within {self.judge.band:.2g})")
        if self.advice is not None:
            return self.agreement.verdict()
        b = self.best
        if b is None and self.left_out is not None:
            c, name = self.left_out, EXPORT_TARGETS[self.target]
            return (f"{c.explanation} (OF {self.of:.4g} -> {c.of:.4g}, {c.improvement:.0%} lower), but {c.spec} does "
                    f"not reach {name}: {c.exports[self.target]}; no effect that reaches {name} helps beyond noise")
        if b is None and self.zero is not None and any(not x.significant for x in self.zero.effects):
            z = self.zero
            return (f"no candidate effect helps beyond noise (OF {self.of:.4g}, {self.of / self.floor:.1f}x the "
                    f"noise floor) once the tests' force zero is fitted (not exported; {z.text()}; "
                    f"OF {z.of_base:.4g} -> {z.of:.4g}): a measurement offset, not device physics; subtract it from "
                    f"the tests' force before calibrating")
        if b is None and not self.candidates:
            return (f"OF {self.of:.4g} is {self.of / self.floor:.1f}x the noise floor; "
                    f"no candidate effects were refitted")
        if b is None and self.of <= NEAR_FLOOR * self.floor:
            return (f"no candidate effect helps beyond noise (OF {self.of:.4g}, {self.of / self.floor:.1f}x "
                    f"the noise floor): close to the noise; what little is left is not one of the known effects, "
                    f"or the floor (an estimate) is low")
        if b is None:
            return (f"no candidate effect helps beyond noise (OF {self.of:.4g}, {self.of / self.floor:.1f}x "
                    f"the noise floor): the misfit is not one of the known effects")
        return b.explanation + self.held_out_scope

    @property
    def held_out_scope(self) -> str:
        """'; checked on this test's held-out cycles only' for a single test
        (a device's effects are checked on each test left out)."""
        return "" if len(self.tests) > 1 else "; checked on this test's held-out cycles only"


def recommended(model, fit, record, settings: dict, *, zero: bool, per_test=(), seed: int = 0,
                replicates: int = REPLICATES, warnings=()):
    """The Calibration diagnose recommends of ``model``'s ``fit`` on
    ``record``: refitted beside the tests' force zero when ``zero`` (the
    diagnosis fitted it: ``zero.beside``; a fit that carries its zero,
    ``FitResult.zero``, was refitted there already), with calibrate's
    bootstrap intervals (``replicates``, seeded as calibrate's; 0: none)."""
    from ..calibration import Calibration

    if zero and fit.zero is None:
        fit = zero_mod.beside(model, fit, record, per_test)
    iv = (bootstrap(model, record, fit.values, per_test=agree.free(model, per_test), bounds=fit.bounds,
                    replicates=replicates, seed=[seed, 7],
                    of=fit.of, force_zero=zero) if replicates else None)
    settings = {**settings, "force_zero": "per-test" if zero else "none", "intervals": int(replicates)}
    return Calibration.from_fit(model, fit, record, settings, list(warnings), intervals=iv)


def diagnose(record, model, *, seed: int = 0, settings=None, base_fit=None, candidates: bool = True,
             progress=None, parent=True, catalog=None, per_test=(), floors=None, target=None) -> Diagnosis:
    """Fit ``model`` (a Model, or a spec resolved by ``catalog``, default the
    built-in one) to ``record``, or converge ``base_fit`` further (DE from it),
    analyse the residual, and refit with every effect of the catalog not in
    the model (when ``candidates``), converging the base (module docstring).

    ``parent``: for a model with effects, how far the error fell from the
    model without its last effect: True fits that model too, a Parent
    (spec, OF) is taken as given, None skips it.  ``progress(message)`` receives
    one line per fit.  ``per_test``: parameters fitted per test (a Device).
    ``floors``: per test, its noise floor (``floor.record_floor``) when an
    earlier diagnosis of the same record computed it.  ``target``: suggest
    only what exports there (``EXPORT_TARGETS``; None: anywhere)."""
    t0 = time.perf_counter()
    export_target(target)
    settings = settings or diagnose_settings()
    catalog = catalog or default_catalog()
    if isinstance(model, str):
        model = catalog.model(model)
    say = progress or (lambda message: None)
    device = as_device(record)
    per_test = tuple(dict.fromkeys(per_test)) if len(device.tests) > 1 else ()
    Layout(model, tuple(device.test_names), per_test)  # refuses a name the model lacks
    if base_fit is None:  # as calibrate's first run
        with timing.stage("  base fit"):
            base_fit = fit_model(model, record, bounds="auto", optimizer=DEFAULT_OPTIMIZER, seed=[seed, 0, 0, 0],
                                 settings=settings_for(DEFAULT_OPTIMIZER), per_test=per_test)
        history = [BaseRound("fitted as calibrate", float(base_fit.of))]
        say(f"fitted {model.spec}: OF {base_fit.of:.5g} ({base_fit.wall_s:.1f} s)")
    else:
        history = [BaseRound("given", float(base_fit.of))]
        with timing.stage("  base fit"):
            base_fit = fit_model(model, record, bounds="auto", optimizer=DEFAULT_OPTIMIZER, seed=seed, settings=settings,
                                 start=base_fit.values, per_test=per_test)
        if base_fit.of < history[0].of * (1.0 - BASE_TOL):
            history.append(BaseRound("converged from the given fit", float(base_fit.of)))
    found: list = []
    agreement = None
    if candidates:
        def report(c):
            label = f"~ {c.effect} for {c.replaces}" if c.replaces else f"+ {c.effect}"
            say(f"  {label:<22s} OF {c.of:.5g} ({(base_fit.of - c.of) / base_fit.of:+.1%}, {c.wall_s:.1f} s)")

        keep: dict = {}
        for _ in range(MAX_BASE_ROUNDS):
            found = refit_all(model, base_fit, record, catalog.effects, seed=seed, settings=settings, progress=report,
                              keep=keep, per_test=per_test)
            of_off, start = lower_base(found, model)
            if start is None or not of_off < base_fit.of * (1.0 - BASE_TOL):
                break
            params, of = polish_model(model, record, start, per_test=per_test)
            say(f"the base can go lower: {base_fit.of:.5g} -> {of:.5g} (refitted from a candidate with its effect off)")
            base_fit = replace(base_fit, values=params, of=of)
            history.append(BaseRound("lowered by a candidate's refit", float(of)))
            keep = {c.effect: c for c in found if not c.replaces}
    split = agree.per_test_params(model, device, base_fit.values, per_test)
    test_of = [evaluate_params(model, t, p) for t, p in zip(device.tests, split)]
    k_focus = int(np.argmax(test_of))
    focus = device.tests[k_focus]
    F_model = model.force(focus, split[k_focus][None, :])[0]
    with timing.stage("  input-noise floor"):  # the records', computed once for every rung of a ladder
        noises = floors or [record_floor(model, p, t, seed) for t, p in zip(device.tests, split)]
    noise = replace(noises[k_focus], floor=float(np.dot(device.weights, [n.floor for n in noises])),
                    force_floor=float(np.dot(device.weights, [n.force_floor for n in noises])))
    judge = Judge(noise.floor, device.n, noise.force_floor)
    diag = Diagnosis(device.name, model, base_fit, F_model, noise.sigma_F, judge,
                     where_mod.analyse(focus, F_model), noise=noise, base_history=history,
                     tests=[TestOF(*t) for t in zip(device.test_names, test_of)] if len(device.tests) > 1 else [],
                     focus=focus, per_test=per_test, target=target)
    if candidates and len(device.tests) > 1:  # before the effects: do the tests agree?
        say("do the tests agree? each law parameter freed per test, refitted from the base:")
        with timing.stage("  per-test check"):
            agreement = agree.check(model, base_fit, device, judge, per_test, say)
    diag.candidates = (assess(found, model, base_fit, device, judge, noise.sigma_d, focus, per_test)
                       if found else [])
    if diag.candidates:  # an effect that acts as an offset counts beyond the tests' force zero only
        with timing.stage("  the tests' force zero"):
            diag.zero = zero_mod.check(model, base_fit, device, diag.candidates, judge, per_test, say)
        diag.candidates.sort(key=lambda c: (not c.significant, c.of, c.effect))
    agree.advise(agreement, diag.candidates)
    diag.agreement = agreement
    if parent is True and model.effects and base_fit.parent:  # the nested fit the base started from
        parent = base_fit.parent
    elif parent is True and model.effects:  # fitted as calibrate fits it: the best base available
        parent_model = model.without_effect(model.effects[-1].name)
        pfit = fit_model(parent_model, record, bounds="auto", optimizer=DEFAULT_OPTIMIZER, seed=[seed, 0, 0, 0],
                         settings=settings_for(DEFAULT_OPTIMIZER), per_test=agree.free(parent_model, per_test))
        parent = Parent(parent_model.spec, float(pfit.of))
        say(f"fitted {parent_model.spec} (for comparison): OF {pfit.of:.5g} ({pfit.wall_s:.1f} s)")
    diag.parent = Parent(*parent) if isinstance(parent, tuple) else None
    diag.wall_s = time.perf_counter() - t0
    diag.inputs = DiagnosisInputs(record, seed, settings, catalog, noises)
    return diag
