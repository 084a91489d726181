"""A campaign's settings (CampaignSettings: its models and its options,
some per model) and its runs: one FitRequest per model
(``CampaignSettings.requests``), run over every device by the one
calibration path (``calibration.runs``) through the campaign's executor."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

from .. import timing
from ..calibration.request import Extends, FitRequest, settings_dict
from ..calibration.runs import fit_intervals, fit_runs
from ..catalog import catalog as load_catalog
from ..fit import DEFAULT_OPTIMIZER, settings_for
from .executors import Processes


class BoundOption(NamedTuple):
    """A --bound (or a --fix: lower == upper) of the models ``spec`` names (None: every model having it)."""

    spec: str | None
    name: str
    lower: float
    upper: float


class PerTestOption(NamedTuple):
    """A --per-test: a parameter fitted per test, of ``spec``'s model (None: every model having it)."""

    spec: str | None
    name: str


class ValueOption(NamedTuple):
    """A --start-value: where the search of a parameter starts, in ``spec``'s model (None: every model having it)."""

    spec: str | None
    name: str
    value: float


@dataclass(frozen=True)
class CampaignSettings:
    """What a campaign runs: model specs, runs per (device, model), the
    optimizer and its settings, and options that apply to some models
    (``BoundOption``, ``PerTestOption``, ``ValueOption``; plain tuples
    are taken as them); ``request(spec)`` is what one model is asked."""

    specs: tuple
    runs: int = 20
    bounds: str = "auto"
    optimizer: str = DEFAULT_OPTIMIZER
    seed: int = 0
    pop: int | None = None
    gens: int | None = None
    stall: int | None = None
    jobs: int = 0  # 0: one process per core
    plugins: tuple = field(default_factory=tuple)  # plugin file paths
    bound_overrides: tuple = field(default_factory=tuple)  # BoundOptions
    per_test: tuple = field(default_factory=tuple)  # PerTestOptions: parameters fitted per test
    start: Extends | None = None  # a calibration file to start from (the models that extend it)
    start_values: tuple = field(default_factory=tuple)  # ValueOptions: start values of some parameters
    intervals: int = 0  # bootstrap replicates of each calibration's parameter intervals (0: none)
    all_runs: bool = False  # make every run, also after the first ones agreed (``first_runs``)
    force_zero: str = "none"  # 'per-test': each test's force zero fitted beside the model (fit.zero; not exported)

    def __post_init__(self):
        """Options given as plain tuples become their named forms."""
        object.__setattr__(self, "bound_overrides", tuple(BoundOption(*o) for o in self.bound_overrides))
        object.__setattr__(self, "per_test", tuple(PerTestOption(*o) for o in self.per_test))
        object.__setattr__(self, "start_values", tuple(ValueOption(*o) for o in self.start_values))
        if self.start is not None and not isinstance(self.start, Extends):
            object.__setattr__(self, "start", Extends(*self.start))

    @property
    def catalog(self):
        """Laws and effects with this campaign's plugins (loaded once per process)."""
        return load_catalog(self.plugins)

    def model(self, spec: str):
        """The Model of one of the campaign's specs."""
        return self.catalog.model(spec)

    def _applies(self, options, spec: str) -> list:
        """The options that apply to ``spec``'s model: its own and every model's, naming one of its parameters."""
        names = self.model(spec).names
        return [o for o in options if o.spec in (None, spec) and o.name in names]

    @property
    def fits_zero(self) -> bool:
        """Whether each test's force zero is fitted beside the models (``force_zero`` 'per-test')."""
        return self.force_zero == "per-test"

    def request(self, spec: str) -> FitRequest:
        """The FitRequest of one of the campaign's models: the options that apply to it."""
        given = {o.name: (o.lower, o.upper) for o in self._applies(self.bound_overrides, spec)}
        extends = self.start if self.start is not None and self.start.fits(self.model(spec), self.catalog) else None
        return FitRequest(spec=spec, plugins=self.plugins, bounds=self.bounds,
                          search_bounds={n: (lo, hi) for n, (lo, hi) in given.items() if lo != hi},
                          fixed={n: lo for n, (lo, hi) in given.items() if lo == hi},
                          per_test=tuple(dict.fromkeys(o.name for o in self._applies(self.per_test, spec))),
                          start_values={o.name: o.value for o in self._applies(self.start_values, spec)},
                          extends=extends, optimizer=self.optimizer, pop=self.pop, gens=self.gens, stall=self.stall,
                          seed=self.seed, runs=self.runs, all_runs=self.all_runs, intervals=self.intervals,
                          force_zero=self.force_zero, position=self.specs.index(spec))

    def per_test_for(self, spec: str) -> tuple:
        """The parameters ``spec``'s model fits per test."""
        return self.request(spec).per_test

    def requests(self) -> list[FitRequest]:
        """One FitRequest per model, in the campaign's order."""
        return [self.request(spec) for spec in self.specs]

    def as_dict(self) -> dict:
        """The campaign's settings (``calibration.request.settings_dict``: the
        keys and forms of ``FitRequest.as_settings``), its options each with
        the model it names (None: every model having it)."""
        return settings_dict(specs=self.specs, runs=self.runs, bounds=self.bounds, optimizer=self.optimizer,
                             seed=self.seed, optimizer_settings=settings_for(self.optimizer, self.pop, self.gens,
                                                                             self.stall),
                             plugins=self.plugins, bound_overrides=self.bound_overrides, per_test=self.per_test,
                             intervals=self.intervals, all_runs=self.all_runs, start_values=self.start_values,
                             force_zero=self.force_zero, start=self.start)


def run_campaign(records, cs: CampaignSettings, progress: bool = True, executor=None) -> dict:
    """Every model of ``cs`` fitted to every record (``calibration.runs.fit_runs``)
    through ``executor`` (default: a local process pool of ``cs.jobs``
    workers): {(device name, spec): FittedRuns}."""
    return fit_runs(records, cs.requests(), executor=executor or Processes(cs.jobs), progress=progress)


def run_intervals(records, results: dict, cs: CampaignSettings, executor=None, progress: bool = True) -> dict:
    """{(device, spec): Intervals} of every calibration of the campaign
    (``calibration.runs.fit_intervals``) through ``executor`` (default: a
    local process pool); empty when ``cs.intervals`` is 0."""
    if not cs.intervals:
        return {}
    return fit_intervals(records, results, cs.requests(), executor=executor or Processes(cs.jobs), progress=progress)


def book_fit_times(results: dict) -> None:
    """Each model's fits' own wall times (in whichever process ran them) as
    ``--profile`` stages."""
    for (_, spec), runs in results.items():
        timing.add(f"  law {spec} (summed over workers)", sum(r.wall_s for r in runs if r is not None), len(runs))
