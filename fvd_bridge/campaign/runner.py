"""A campaign's settings (CampaignSettings: its models and its options,
some per model) and its runs: one FitRequest per model
(``CampaignSettings.requests``), run over every device by the one
calibration path (``calibration.runs``) through the campaign's executor."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

from .. import timing
from ..calibration.request import Extends, FitRequest
from ..calibration.runs import fit_intervals, fit_runs
from ..catalog import catalog as load_catalog
from ..fit import DEFAULT_OPTIMIZER, settings_for
from .executors import Processes


@dataclass(frozen=True)
class CampaignSettings:
    """What a campaign runs: model specs, runs per (device, model), optimizer and its settings."""

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
    bound_overrides: tuple = field(default_factory=tuple)  # (spec or None, name, lower, upper)
    per_test: tuple = field(default_factory=tuple)  # (spec or None, name): parameters fitted per test
    start: tuple | None = None  # (spec, names, values) of a calibration file to start from
    start_values: tuple = field(default_factory=tuple)  # (spec or None, name, value): start values of some parameters
    intervals: int = 0  # bootstrap replicates of each calibration's parameter intervals (0: none)
    all_runs: bool = False  # make every run, also after the first ones agreed (``first_runs``)
    force_zero: str = "none"  # 'per-test': each test's force zero fitted beside the model (fit.zero; not exported)

    @property
    def catalog(self):
        """Laws and effects with this campaign's plugins (loaded once per process)."""
        return load_catalog(self.plugins)

    def model(self, spec: str):
        """The Model of one of the campaign's specs."""
        return self.catalog.model(spec)

    def overrides_for(self, spec: str) -> dict:
        """{name: (lower, upper)} of the --bound options that apply to ``spec``."""
        return {name: (lo, hi) for s, name, lo, hi in self.bound_overrides if s in (None, spec)}

    def per_test_for(self, spec: str) -> tuple:
        """The --per-test parameters that apply to ``spec``."""
        names = self.model(spec).names
        return tuple(dict.fromkeys(n for s, n in self.per_test if s in (None, spec) and n in names))

    def start_for(self, spec: str) -> tuple | None:
        """(names, values) of the --start calibration when ``spec``'s model
        extends it (same law, its effects among the model's), else None."""
        if self.start is None:
            return None
        given, model = self.model(self.start[0]), self.model(spec)
        if given.law is not model.law or not set(given.effect_names) <= set(model.effect_names):
            return None
        return self.start[1], self.start[2]

    @property
    def fits_zero(self) -> bool:
        """Whether each test's force zero is fitted beside the models (``force_zero`` 'per-test')."""
        return self.force_zero == "per-test"

    def start_values_for(self, spec: str) -> dict:
        """{name: value} of the --start-value options that apply to ``spec``."""
        names = self.model(spec).names
        return {name: v for s, name, v in self.start_values if s in (None, spec) and name in names}

    def request(self, spec: str) -> FitRequest:
        """The FitRequest of one of the campaign's models: the options that apply to it."""
        names = self.model(spec).names
        given = {n: bounds for n, bounds in self.overrides_for(spec).items() if n in names}
        start = self.start_for(spec)
        return FitRequest(spec=spec, plugins=self.plugins, bounds=self.bounds,
                          search_bounds={n: (lo, hi) for n, (lo, hi) in given.items() if lo != hi},
                          fixed={n: lo for n, (lo, hi) in given.items() if lo == hi},
                          per_test=self.per_test_for(spec), start_values=self.start_values_for(spec),
                          extends=None if start is None else Extends(self.start[0], *start),
                          optimizer=self.optimizer, pop=self.pop, gens=self.gens, stall=self.stall, seed=self.seed,
                          runs=self.runs, all_runs=self.all_runs, intervals=self.intervals,
                          force_zero=self.force_zero, position=self.specs.index(spec))

    def requests(self) -> list[FitRequest]:
        """One FitRequest per model, in the campaign's order."""
        return [self.request(spec) for spec in self.specs]

    def as_dict(self) -> dict:
        s = settings_for(self.optimizer, self.pop, self.gens, self.stall)
        return {"specs": list(self.specs), "runs": self.runs, "bounds": self.bounds,
                "optimizer": self.optimizer, "seed": self.seed, "optimizer_settings": asdict(s),
                "plugins": list(self.plugins),
                "bound_overrides": [list(o) for o in self.bound_overrides],
                "per_test": [list(o) for o in self.per_test], "intervals": self.intervals,
                "all_runs": self.all_runs, "start_values": [list(o) for o in self.start_values],
                **({"force_zero": self.force_zero} if self.fits_zero else {}),  # (files of before: unchanged)
                "start": None if self.start is None else {"model": self.start[0],
                                                          "values": dict(zip(self.start[1], self.start[2]))}}


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
