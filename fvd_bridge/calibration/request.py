"""FitRequest: one model's calibration as asked, every option a named field,
checked once by parameter name.

``fb.calibrate`` builds one; ``fvd-bridge calibrate`` and ``campaign`` build
one per model from their options (``CampaignSettings.request``).  A request
is plain data (the model travels as its spec and plugin files), so a process
pool or a Dask worker can take it; ``model`` loads it there, once per process.
The messages of ``check`` name the option in the caller's words
(``errors.option``: ``bounds={'C': ...}`` from Python, ``--bound C=...`` on
the command line).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

from ..catalog import catalog as load_catalog
from ..errors import InputError, option, parameter_option
from ..fit import DEFAULT_OPTIMIZER, settings_for
from ..fit.api import refuse_all_fixed
from ..fit.intervals import replicates
from ..fit.zero import FORCE_ZERO


@dataclass(frozen=True)
class Extends:
    """A calibration the requested model extends, its values the fit's start:
    its model's spec, its parameter names and values [their units]."""

    spec: str
    names: tuple
    values: tuple

    @classmethod
    def of(cls, cal) -> Extends:
        """The start a Calibration gives."""
        return cls(cal.spec, tuple(cal.model.names), tuple(float(x) for x in cal.values))

    def fits(self, model, cat) -> bool:
        """Whether ``model`` extends it: the same law, its effects among the model's."""
        given = cat.model(self.spec)
        return given.law is model.law and set(given.effect_names) <= set(model.effect_names)


@dataclass(frozen=True)
class FitRequest:
    """One model's calibration on one Record or Device, as asked.

    ``bounds``: 'auto' or 'paper', the search box; ``search_bounds``
    {name: (lower, upper)} replacing the box of those parameters;
    ``fixed`` {name: value}: held there, not fitted; ``per_test``: the
    parameters fitted per test; ``start_values`` {name: value}: where the
    search starts for those; ``extends``: a calibration the model extends,
    its start.  ``runs`` seeded runs from ``seed`` (after the first
    FIRST_RUNS only where they disagree, unless ``all_runs``);
    ``intervals`` bootstrap replicates (0: none); ``force_zero`` 'per-test':
    each test's force zero fitted beside the model.  ``position``: the
    model's place among a campaign's models (its runs' seeds)."""

    spec: str
    plugins: tuple = ()
    bounds: str = "auto"
    search_bounds: dict = field(default_factory=dict)
    fixed: dict = field(default_factory=dict)
    per_test: tuple = ()
    start_values: dict = field(default_factory=dict)
    extends: Extends | None = None
    optimizer: str = DEFAULT_OPTIMIZER
    pop: int | None = None
    gens: int | None = None
    stall: int | None = None
    seed: int = 0
    runs: int = 1
    all_runs: bool = False
    intervals: int = 0
    force_zero: str = "none"
    position: int = 0

    @property
    def model(self):
        """The Model (its plugins' catalog loaded once per process)."""
        return load_catalog(self.plugins).model(self.spec)

    @property
    def settings(self):
        """The optimizer's settings (``fit.settings_for``)."""
        return settings_for(self.optimizer, self.pop, self.gens, self.stall)

    @property
    def overrides(self) -> dict:
        """{name: (lower, upper)}: the search bounds given, a fixed parameter's lower == upper."""
        return {**self.search_bounds, **{name: (v, v) for name, v in self.fixed.items()}}

    @property
    def fits_zero(self) -> bool:
        """Whether each test's force zero is fitted beside the model."""
        return self.force_zero == "per-test"

    @property
    def local(self) -> bool:
        """Whether the search is the local one (its runs get the wider rounds: ``calibration.runs``)."""
        return self.optimizer.startswith("local")

    def check(self) -> FitRequest:
        """The request itself, every option checked (one line each, naming the
        option and the parameter); raises InputError."""
        model = self.model
        for name in ("runs", "pop", "gens", "stall"):
            value = getattr(self, name)
            if value is not None and value < 1:
                raise InputError(f"{option('--' + name, value)}: must be at least 1")
        if self.force_zero not in FORCE_ZERO:
            raise InputError(f"force_zero={self.force_zero!r}: expected one of {', '.join(map(repr, FORCE_ZERO))}")
        self.settings  # the optimizer and its settings
        replicates(self.intervals)
        given = ([("--bound", name, bounds) for name, bounds in self.search_bounds.items()]
                 + [("--fix", name, v) for name, v in self.fixed.items()]
                 + [("--start-value", name, v) for name, v in self.start_values.items()]
                 + [("--per-test", name, None) for name in self.per_test])
        for flag, name, value in given:
            model.known_parameter(name, parameter_option(flag, name, value))
        for name, (lo, hi) in self.search_bounds.items():
            if not lo <= hi:
                raise InputError(f"{parameter_option('--bound', name, (lo, hi))}: the lower bound must be below "
                                 f"the upper")
        refuse_all_fixed(model, self.overrides)
        if self.extends is not None and not self.extends.fits(model, load_catalog(self.plugins)):
            raise InputError(f"start: model {self.spec} does not extend the calibration's model "
                             f"{self.extends.spec} (same law, its effects among the model's)")
        return self

    def as_settings(self) -> dict:
        """The settings a calibration file keeps (``settings_dict`` for this
        one model: its options, each under no model (None), as a one-model
        ``fvd-bridge calibrate`` writes them)."""
        return settings_dict(specs=[self.spec], runs=self.runs, bounds=self.bounds, optimizer=self.optimizer,
                             seed=self.seed, optimizer_settings=self.settings, plugins=self.plugins,
                             bound_overrides=[(None, n, lo, hi) for n, (lo, hi) in self.overrides.items()],
                             per_test=[(None, n) for n in self.per_test], intervals=self.intervals,
                             all_runs=self.all_runs, start_values=[(None, n, v) for n, v in self.start_values.items()],
                             force_zero=self.force_zero, start=self.extends)


def settings_dict(*, specs, runs, bounds, optimizer, seed, optimizer_settings, plugins, bound_overrides, per_test,
                  intervals, all_runs, start_values, force_zero, start) -> dict:
    """The settings dict of a calibration file, a campaign's settings.json
    and its store's fingerprint, built here only (``FitRequest.as_settings``
    for one model, ``CampaignSettings.as_dict`` for a campaign's): its keys
    in their order, each value in its file form.  ``bound_overrides``
    (spec or None, name, lower, upper), ``per_test`` (spec or None, name),
    ``start_values`` (spec or None, name, value): each a row;
    ``optimizer_settings`` the optimizer's settings dataclass; ``start`` an
    Extends or None.  ``force_zero`` is written only when 'per-test' (the
    files written before it was an option stay as they were)."""
    return {"specs": list(specs), "runs": runs, "bounds": bounds, "optimizer": optimizer, "seed": seed,
            "optimizer_settings": asdict(optimizer_settings), "plugins": list(plugins),
            "bound_overrides": [list(o) for o in bound_overrides], "per_test": [list(o) for o in per_test],
            "intervals": intervals, "all_runs": all_runs, "start_values": [list(o) for o in start_values],
            **({"force_zero": force_zero} if force_zero == "per-test" else {}),
            "start": None if start is None else {"model": start.spec, "values": dict(zip(start.names, start.values))}}
