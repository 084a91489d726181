"""How to read a record: column mapping, units, .mat variable, time step [s], force sign.

The same keys come from CLI options (``--columns``, ``--units``, ``--mat-var``,
``--dt``, ``--force-sign``) or from a YAML sidecar ``NAME.yaml`` next to the
record file::

    columns: {t: time, d: disp, F: load}   # CSV header names, or .mat indices
    units:   {t: ms, d: m, F: N}           # default s, mm, kN, mm/s
    mat_var: x_F                            # .mat only
    dt: 0.01                                # [s], when there is no time column
    force_sign: flip                        # the load cell reads the opposite sign

Options given explicitly win over the sidecar, key by key; a unit that
replaces another the file states (its sidecar's, its header's) by a
different factor is noted on reading (``readers.unit_overrides``).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field, replace

import yaml

from ..errors import InputError
from ..units import CANONICAL, factor

SIDECAR_KEYS = ("columns", "units", "mat_var", "dt", "force_sign")
#: ``--force-sign``: flip (negate F: the load cell reads the opposite sign) or
#: keep (the sign is right: loops that generate energy are not doubted)
FORCE_SIGNS = ("flip", "keep")
#: ``--columns v=none``: leave a measured velocity out and derive v from d
NO_COLUMN = "none"


class Given(dict):
    """Columns or units as each caller writes them (errors.option): 'd=F,F=d'
    on the command line (str), {'d': 'F', 'F': 'd'} in Python (repr)."""

    def __str__(self) -> str:
        return ",".join(f"{k}={v}" for k, v in self.items())


@dataclass
class ReadOptions:
    """How to read a record.

    ``columns`` maps t/d/F/v to a CSV header name, a column index of
    ``mat_var`` or a .mat variable name; ``units`` maps t/d/F/v to a unit
    (see fvd_bridge.units); ``dt`` [s] builds the time column when the file
    has none; ``sg_window`` [samples] and ``sg_order`` set the Savitzky-Golay
    velocity differentiator (window None: chosen per sample, records/velocity.py);
    ``derive_velocity``: ignore a measured velocity column and derive v from
    d (``--columns v=none``); ``force_sign``: None (loops that generate
    energy are doubted, validate.reversed_force_note), "flip" (F negated) or
    "keep" (F as read, not doubted).  ``sidecar`` is the YAML file the
    options were completed from, if any, and ``sidecar_units`` the units
    it states (those ``units`` replaced are noted on reading).
    """

    columns: dict = field(default_factory=dict)
    units: dict = field(default_factory=dict)
    mat_var: str | None = None
    dt: float | None = None
    sg_window: int | None = None
    sg_order: int = 3
    derive_velocity: bool = False
    force_sign: str | None = None
    sidecar: str | None = None
    sidecar_units: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        """The options a user gave (the sidecar completes them again on reading)."""
        out = {"columns": dict(self.columns), "units": dict(self.units), "mat_var": self.mat_var, "dt": self.dt,
               "sg_window": self.sg_window, "sg_order": self.sg_order, "derive_velocity": self.derive_velocity,
               "force_sign": self.force_sign}
        return {k: v for k, v in out.items() if v not in (None, {}, False) and not (k == "sg_order" and v == 3)}

    @classmethod
    def from_dict(cls, data: dict | None) -> "ReadOptions":
        """Options stored by ``as_dict`` (a calibration file's record.reading)."""
        keys = ("columns", "units", "mat_var", "dt", "sg_window", "sg_order", "derive_velocity", "force_sign")
        return cls(**{k: v for k, v in (data or {}).items() if k in keys})


def parse_mapping(text: str | None, option: str) -> dict:
    """'t=time,d=disp' -> {'t': 'time', 'd': 'disp'}; refuses keys other than t, d, F, v."""
    if not text:
        return {}
    out = {}
    for item in text.split(","):
        key, sep, value = item.partition("=")
        key, value = key.strip(), value.strip()
        if not sep or not key or not value:
            raise InputError(f"{option} '{item}': expected KEY=VALUE (e.g. {option} t=time,d=disp,F=load)")
        if key not in CANONICAL:
            raise InputError(f"{option} '{item}': unknown key '{key}' (expected t, d, F or v)")
        if key in out:
            raise InputError(f"{option} '{item}': key '{key}' given twice")
        if value == NO_COLUMN and key != "v":
            raise InputError(f"{option} '{item}': only the velocity can be left out (v={NO_COLUMN}: derived from d)")
        out[key] = value
    return out


def sidecar_path(path: str) -> str:
    """The sidecar of ``data/run1.csv`` is ``data/run1.yaml``."""
    return os.path.splitext(path)[0] + ".yaml"


def with_sidecar(path: str, opts: ReadOptions) -> ReadOptions:
    """Complete ``opts`` from the sidecar of ``path`` when there is one."""
    side = sidecar_path(path)
    if not os.path.isfile(side):
        return opts
    data = _load_sidecar(side)
    return replace(
        opts,
        columns={**data.get("columns", {}), **opts.columns},
        units={**data.get("units", {}), **opts.units},
        mat_var=opts.mat_var if opts.mat_var is not None else data.get("mat_var"),
        dt=opts.dt if opts.dt is not None else data.get("dt"),
        force_sign=opts.force_sign if opts.force_sign is not None else data.get("force_sign"),
        sidecar=side, sidecar_units=dict(data.get("units", {})))


def _load_sidecar(side: str) -> dict:
    """Parse and check a sidecar; every error names the sidecar and its line."""
    try:
        with open(side, encoding="utf-8-sig") as fh:
            text = fh.read()
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{side}: cannot read the sidecar ({type(exc).__name__})") from None
    try:
        node = yaml.compose(text)
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"row {mark.line + 1}, column {mark.column + 1}: " if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise InputError(f"{side}: {where}not valid YAML ({problem})") from None
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise InputError(f"{side}: row 1: expected a mapping with keys {', '.join(SIDECAR_KEYS)}")
    lines = _key_lines(node)

    def fail(key, message, entry=None):
        row = lines.get((key, entry), lines.get((key, None), 1))
        raise InputError(f"{side}: row {row}, key '{key}': {message}")

    out = {}
    for key, value in data.items():
        if key not in SIDECAR_KEYS:
            fail(key, f"unknown key (expected {', '.join(SIDECAR_KEYS)})")
        if key in ("columns", "units"):
            if not isinstance(value, dict):
                fail(key, "expected a mapping such as {t: time, d: disp, F: load}")
            for k, v in value.items():
                if k not in CANONICAL:
                    fail(key, f"unknown entry '{k}' (expected t, d, F or v)", k)
                if not isinstance(v, (str, int)) or isinstance(v, bool):
                    fail(key, f"{k}: expected a name{' or column index' if key == 'columns' else ''}, got {v!r}", k)
            out[key] = {k: str(v) for k, v in value.items()}
        elif key == "mat_var":
            if not isinstance(value, str):
                fail(key, f"expected a variable name, got {value!r}")
            out[key] = value
        elif key == "dt":
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not (math.isfinite(value) and value > 0):
                fail(key, f"expected a positive time step in s, got {value!r}")
            out[key] = float(value)
        elif key == "force_sign":
            if value not in FORCE_SIGNS:
                fail(key, f"expected {' or '.join(FORCE_SIGNS)}, got {value!r}")
            out[key] = value
    for k, unit in out.get("units", {}).items():
        try:
            factor(k, unit)
        except InputError as exc:
            fail("units", str(exc), k)
    return out


def _key_lines(node) -> dict:
    """{(key, None): line, (key, entry): line} of a two-level YAML mapping (lines from 1)."""
    lines = {}
    if not isinstance(node, yaml.MappingNode):
        return lines
    for k, v in node.value:
        lines[(k.value, None)] = k.start_mark.line + 1
        if isinstance(v, yaml.MappingNode):
            for kk, _ in v.value:
                lines[(k.value, kk.value)] = kk.start_mark.line + 1
    return lines
