"""The parts of a calibration's result, as small frozen records: ``TestFit``
(one test it was fitted on), ``RecordSource`` (where a test's record came
from and how it was read), ``RunStats`` (the statistics over its seeded
runs), ``BootstrapIntervals`` (its parameters' intervals, an ``Interval``
each) and ``SolverStatus`` (how its search ended).  ``schema`` writes and
reads them as the file's blocks."""

from __future__ import annotations

from dataclasses import dataclass, field, fields

from ..errors import InputError
from ..fit.layout import SEP

#: the keys of a test's block in the calibration file, in the order written
TEST_KEYS = ("name", "weight", "of", "range", "record", "parameters")


@dataclass(frozen=True)
class Peaks:
    """A record's peak magnitudes: force ``F`` [kN], velocity ``v`` [mm/s],
    stroke ``d`` [mm] (about its median); None: not recorded."""

    F: float | None = None
    v: float | None = None
    d: float | None = None

    @classmethod
    def from_dict(cls, block: dict | None) -> "Peaks":
        """Peaks from the file's {F, v, d} (missing keys: None)."""
        block = block or {}
        return cls(*(block.get(f.name) for f in fields(cls)))

    def as_dict(self) -> dict:
        """The file's block: {F, v, d}."""
        return {f.name: getattr(self, f.name) for f in fields(self)}


@dataclass(frozen=True)
class RecordSource:
    """Where a calibration's record came from and how it was read (the
    file's 'record' block): its ``name``; its ``file`` and ``format``; its
    ``samples`` and time step ``dt`` [s]; the ``columns`` {t, d, F[, v]}
    read, the time ``window`` (t0, t1 [s]) kept, the ``source_units``
    {t, d, F[, v]} converted from, the ``reading`` options given, the
    ``velocity`` derivation {method, ...}; its ``peaks`` (F [kN], v [mm/s],
    d [mm]).  None (and "", Peaks()): not recorded."""

    name: str = ""
    file: str | None = None
    format: str | None = None
    samples: int | None = None
    dt: float | None = None
    columns: dict | None = None
    window: list | None = None
    source_units: dict | None = None
    reading: dict | None = None
    velocity: dict | None = None
    peaks: Peaks = Peaks()

    @classmethod
    def from_dict(cls, block: dict | None) -> "RecordSource":
        """A record's source from its file block (missing keys take the
        defaults, keys of no field are left out; None or {}: ``RecordSource()``)."""
        block = block or {}
        given = {f.name: block[f.name] for f in fields(cls) if f.name in block and f.name != "peaks"}
        return cls(**given, peaks=Peaks.from_dict(block.get("peaks")))

    def as_dict(self) -> dict:
        """The file's block: {name, file, format, samples, dt, columns, window,
        source_units, reading, velocity, peaks: {F, v, d}}."""
        return {**{f.name: getattr(self, f.name) for f in fields(self)}, "peaks": self.peaks.as_dict()}


@dataclass(frozen=True)
class TestFit:
    """One test of a calibration: its ``name``; its ``weight`` in the OF; its
    ``of`` (eq. 18; None: not recorded); its peak ``range`` {d [mm], v [mm/s],
    f [Hz]}; its ``record``: the RecordSource of its record (file,
    samples, dt [s], peaks, ...); its ``parameters`` fitted per test
    {name: value [the model's units]} ({}: all shared)."""

    __test__ = False  # a data record, not a pytest class

    name: str
    weight: float = 1.0
    of: float | None = None
    range: dict = field(default_factory=dict)
    record: RecordSource = RecordSource()
    parameters: dict = field(default_factory=dict)

    @classmethod
    def from_dict(cls, block: dict) -> "TestFit":
        """A test from its file block (missing keys take the defaults)."""
        return cls(name=block["name"], weight=float(block.get("weight", 1.0)), of=block.get("of"),
                   range=dict(block.get("range") or {}), record=RecordSource.from_dict(block.get("record")),
                   parameters=dict(block.get("parameters") or {}))

    def as_dict(self) -> dict:
        """The file's block: {name, weight, of, range, record, parameters}."""
        return {**{key: getattr(self, key) for key in TEST_KEYS}, "record": self.record.as_dict()}


@dataclass(frozen=True)
class RunStats:
    """Statistics over a calibration's seeded runs: the OF's mean and
    standard deviation (eq. 18), and the parameters' (model order, the
    model's units; None: not recorded)."""

    of_mean: float
    of_sigma: float
    p_mean: tuple | None = None
    p_sigma: tuple | None = None

    @classmethod
    def from_dict(cls, given, n: int | None = None) -> "RunStats | None":
        """RunStats from a RunStats or a dict {of_mean, of_sigma, p_mean,
        p_sigma} (its parameter vectors cut to the first ``n``); None from
        None or {} (no run statistics)."""
        if given is None or isinstance(given, RunStats):
            return given
        if not given:
            return None
        unknown = sorted(set(given) - {"of_mean", "of_sigma", "p_mean", "p_sigma"})
        if unknown or "of_mean" not in given or "of_sigma" not in given:
            raise InputError(f"runs: give of_mean, of_sigma[, p_mean, p_sigma] (got {', '.join(map(str, given))})")

        def vector(key):
            x = given.get(key)
            return None if x is None else tuple(float(v) for v in list(x)[:n])

        return cls(float(given["of_mean"]), float(given["of_sigma"]), vector("p_mean"), vector("p_sigma"))


#: how the intervals were computed (the file's 'intervals.method')
INTERVALS_METHOD = "bootstrap of the measurement chain (fit.intervals)"


@dataclass(frozen=True)
class Interval:
    """One quantity's bootstrap spread, in its unit: the 95% interval
    ``ci95`` (lower, upper), the standard error ``stderr`` and the bias
    (the replicates' mean minus the estimate; None: not recorded)."""

    ci95: tuple
    stderr: float | None = None
    bias: float | None = None

    @classmethod
    def from_dict(cls, block: dict) -> "Interval":
        """An interval from its block {ci95, stderr[, bias]}."""
        return cls(tuple(float(x) for x in block["ci95"]), block.get("stderr"), block.get("bias"))

    def as_dict(self) -> dict:
        """The file's entry: {stderr, ci95: [lower, upper]} (the bias is not kept)."""
        return {"stderr": self.stderr, "ci95": list(self.ci95)}


@dataclass(frozen=True)
class BootstrapIntervals:
    """A calibration's parameter intervals (``fit.intervals``): ``replicates``
    drawn; per fitted column ('C', 'C@TEST' for a per-test one) and per
    derived quantity an ``Interval``; the correlation over the replicates
    {names, matrix} (None: not recorded); what is ``not_identified`` (one
    line each); ``noise_of``: the model's mean OF on the replicates (what
    noise alone gives); ``note``: why the intervals count the noise only."""

    replicates: int
    parameters: dict = field(default_factory=dict)
    derived: dict = field(default_factory=dict)
    correlation: dict | None = None
    not_identified: tuple = ()
    noise_of: float | None = None
    note: str = ""
    method: str = INTERVALS_METHOD

    @classmethod
    def from_dict(cls, given) -> "BootstrapIntervals | None":
        """From ``fit.intervals.Intervals.as_dict()`` or a file's blocks
        gathered (``schema``); None from None or {} (no intervals)."""
        if given is None or isinstance(given, BootstrapIntervals):
            return given
        if not given:
            return None
        return cls(int(given.get("replicates") or 0),
                   {n: Interval.from_dict(e) for n, e in (given.get("parameters") or {}).items()},
                   {n: Interval.from_dict(e) for n, e in (given.get("derived") or {}).items()},
                   given.get("correlation"), tuple(given.get("not_identified") or ()),
                   given.get("noise_of"), str(given.get("note") or ""), str(given.get("method") or INTERVALS_METHOD))

    def of_parameter(self, name: str) -> dict:
        """The file's entry of one parameter: {stderr, ci95[, per_test_ci95:
        {TEST: ci95}]} (its per-test columns' too), or {}."""
        if name not in self.parameters:
            return {}
        out = self.parameters[name].as_dict()
        per = {n.split(SEP)[1]: list(i.ci95) for n, i in self.parameters.items() if n.startswith(name + SEP)}
        return {**out, "per_test_ci95": per} if per else out


@dataclass(frozen=True)
class SolverStatus:
    """How the search of the calibration's best run ended: its ``optimizer``,
    why it stopped (``stop``: the search's words, e.g. 'local: 1 basin(s)
    from 3 start(s); solves ended: cost settled 3') and the parameter sets it
    evaluated (``evaluations``, its nested and widened rounds included);
    ``floor``: the OF the records' noise alone gives (``fit.floor``), which
    the search was judged by (None: not judged)."""

    optimizer: str
    stop: str = ""
    evaluations: int = 0
    floor: float | None = None

    @classmethod
    def from_dict(cls, block) -> "SolverStatus | None":
        """From the file's 'solver' block (None: not recorded, a file written before it)."""
        if not block:
            return None
        floor = block.get("floor")
        return cls(str(block.get("optimizer") or ""), str(block.get("stop") or ""), int(block.get("evaluations") or 0),
                   None if floor is None else float(floor))

    def as_dict(self) -> dict:
        """The file's block: {optimizer, stop, evaluations[, floor]}."""
        return {f.name: getattr(self, f.name) for f in fields(self)
                if not (f.name == "floor" and self.floor is None)}

    def times_floor(self, of: float) -> float | None:
        """``of`` over the noise floor (None: no floor)."""
        return of / self.floor if self.floor else None
