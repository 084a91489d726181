"""The ladder: add the best effect, refit, repeat while it helps beyond noise.

Each rung's model is the previous one plus the candidate that lowered the OF
most among those that pass the noise test (rank.Judge: a drop beyond the
noise-floor uncertainty and a lower BIC, the guard against overfitting).
The ladder stops when no candidate passes, when the model reaches the noise
floor, when every effect is in, or, with several tests of a device, when
the tests disagree on one parameter (``agree.py``): effects added to a
model whose tests disagree would fit their difference; run it again with
``--per-test NAME`` (``per_test``), which every rung then fits per test.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

from ..errors import option
from ..fit.result import Parent
from .core import Diagnosis, diagnose


@dataclass
class Rung:
    """One model on the ladder."""

    spec: str
    of: float
    improvement: float | None  # relative to the previous rung
    params: dict
    units: dict
    explanation: str = ""
    added: str = ""  # the effect this rung added (empty for the first)

    def as_dict(self) -> dict:
        return {"model": self.spec, "of": self.of, "improvement": self.improvement,
                "params": self.params, "units": self.units, "why": self.explanation}


@dataclass
class Ladder:
    rungs: list = field(default_factory=list)
    diagnoses: list = field(default_factory=list)
    stop: str = ""
    wall_s: float = 0.0

    @property
    def final(self) -> Diagnosis:
        return self.diagnoses[-1]

    def as_dict(self) -> dict:
        return {"rungs": [r.as_dict() for r in self.rungs], "stop": self.stop,
                "noise_floor_of": self.final.floor, "wall_s": self.wall_s}


def climb(record, model, *, seed: int = 0, settings=None, max_rungs: int | None = None, progress=None,
          catalog=None, per_test=(), target=None) -> Ladder:
    """Run the ladder from ``model`` (a Model, or a spec resolved by ``catalog``;
    ``per_test``: parameters fitted per test; ``target``: climb only on what
    exports there); returns every rung and each rung's diagnosis."""
    t0 = time.perf_counter()
    lad = Ladder()
    diag = diagnose(record, model, seed=seed, settings=settings, progress=progress, parent=None, catalog=catalog,
                    per_test=per_test, target=target)
    lad.diagnoses.append(diag)
    lad.rungs.append(Rung(diag.spec, diag.of, None, diag.named(), diag.units()))
    while True:
        if max_rungs is not None and len(lad.rungs) > max_rungs:
            lad.stop = f"after {max_rungs} added effect(s) ({option('--max-rungs')})"
            break
        if diag.advice is not None:
            lad.stop = diag.verdict()
            break
        best = diag.best
        if best is None:
            lad.stop = (diag.verdict() if diag.left_out is not None
                        else "at the noise floor: nothing left to explain" if diag.at_floor
                        else "no effect helps beyond noise" if diag.candidates
                        else "every effect is already in the model")
            break
        if progress:
            progress(f"ladder: adding {best.effect} -> {best.spec}")
        prev = diag
        # the last rung allowed ends the ladder: its candidates need no refit (whether
        # the new model is at the floor is its own diagnosis's to judge, with its own margin)
        last = max_rungs is not None and len(lad.rungs) >= max_rungs
        diag = diagnose(record, best.model, seed=seed, settings=settings, base_fit=best.fit, candidates=not last,
                        progress=progress, parent=Parent(prev.spec, prev.of), catalog=catalog, per_test=per_test,
                        floors=prev.inputs.floors, target=target)
        lad.diagnoses.append(diag)
        lad.rungs.append(Rung(diag.spec, diag.of, (prev.of - diag.of) / prev.of, diag.named(),
                              diag.units(), best.explanation, best.effect))
    lad.wall_s = time.perf_counter() - t0
    return lad


def recommended_fits(diag, lad=None) -> dict:
    """{spec: (model, fit, zero)} of what a diagnosis (with ``lad``, its
    ladder) recommends keeping: every candidate that passed its checks and
    every rung; ``zero``: fit it beside the tests' force zero
    (``core.recommended``), as every diagnosis up to it that fitted the
    zero credited its effects beyond it."""
    found, zero = {}, False  # a rung's own fit (converged further) replaces its candidate's
    for d in (lad.diagnoses if lad is not None else [diag]):
        if lad is not None:
            found[d.spec] = (d.model, d.fit, zero)
        zero = zero or d.zero is not None
        found.update({c.spec: (c.model, c.fit_to_write(zero), zero)
                      for c in d.candidates if c.significant})
    return found


Diagnosis._climb = staticmethod(climb)  # Diagnosis.ladder() (core.py)
