"""Ground motions: the GroundMotion record and its readers.

Below both the frames (their excitation) and the rig (``rig.protocols.read_history``
reads plain 2-column text with ``read_two_column``).

Every reader returns a GroundMotion: ground acceleration [mm/s^2] on a
uniform time grid of step dt [s]. ``read_motion`` picks the reader from the
suffix:

- text (any other suffix): 2 columns t [s], a [unit, default g], or 1 column
  a with ``dt`` given; '#' starts a comment; blanks, commas or semicolons
  separate the cells.
- .smc: USGS SMC corrected accelerogram [cm/s^2], one component a file.
- .V2A: GeoNet V2A corrected accelerogram [mm/s^2], components in sequence.
- .AT2: PEER NGA AT2 [g].

SMC and V2A fields are cut by character position, not split on blanks, since
neighbouring values can touch ("-6454.0-10565.6"). Bad input raises
InputError naming the file, the line (counted from 1) and the field or
column; a record is never returned shorter than its header says.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError, positive
from ..units import FACTORS

#: standard gravity [mm/s^2] (3rd CGPM, 1901)
G_MM_S2 = 9806.65

#: a plain decimal number, Fortran D exponents allowed (no nan, inf or '_')
_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][+-]?\d+)?")
_INTEGER = re.compile(r"[+-]?\d+")
_SEPARATORS = re.compile(r"[,;]")


# ------------------------------------------------------------------ the record

@dataclass(frozen=True, eq=False)
class GroundMotion:
    """A ground acceleration history: sample k at t = k dt.

    name; dt [s]; accel [mm/s^2] (a read-only copy); source: provenance
    (file, format, units read, scale factor, window).
    """

    name: str
    dt: float
    accel: np.ndarray
    source: dict = field(default_factory=dict)

    def __post_init__(self):
        where = f"ground motion {self.name}"
        dt = float(self.dt)
        if not (math.isfinite(dt) and dt > 0.0):
            raise InputError(f"{where}: dt = {self.dt} s must be a finite number > 0")
        a = np.array(self.accel, dtype=float).ravel()
        if a.size == 0:
            raise InputError(f"{where}: no samples")
        bad = np.flatnonzero(~np.isfinite(a))
        if bad.size:
            raise InputError(f"{where}: sample {bad[0]} is not finite ({a[bad[0]]})")
        a.setflags(write=False)
        object.__setattr__(self, "dt", dt)
        object.__setattr__(self, "accel", a)
        object.__setattr__(self, "source", dict(self.source))

    @property
    def t(self) -> np.ndarray:
        """Sample times k dt [s]."""
        return self.dt * np.arange(self.accel.size)

    @property
    def pga_g(self) -> float:
        """Peak ground acceleration max |accel| [g] (g = 9806.65 mm/s^2)."""
        return float(np.max(np.abs(self.accel))) / G_MM_S2

    @property
    def duration(self) -> float:
        """(n - 1) dt [s]."""
        return (self.accel.size - 1) * self.dt

    def scaled_to_pga(self, pga_g: float) -> "GroundMotion":
        """The record times the factor that makes its PGA ``pga_g`` [g]; the
        factor (times any earlier one) goes into source['scale_factor']."""
        target = positive(f"ground motion {self.name}: target PGA [g]", pga_g)
        if self.pga_g == 0.0:
            raise InputError(f"ground motion {self.name}: all samples are zero; it cannot be scaled to a PGA")
        k = target / self.pga_g
        src = dict(self.source, scale_factor=self.source.get("scale_factor", 1.0) * k, scaled_to_pga_g=target)
        return GroundMotion(self.name, self.dt, self.accel * k, src)

    def arias(self) -> float:
        """The record's energy as its Arias intensity up to the factor pi / (2 g):
        integral a^2 dt [mm^2/s^3]."""
        return float(np.sum(self.accel ** 2) * self.dt)

    def strong_motion(self, low: float = 0.05, high: float = 0.95) -> tuple[float, float]:
        """Times [s] at which the record has built up ``low`` and ``high`` of
        its energy (the 5-95% significant duration's ends)."""
        cum = np.cumsum(self.accel ** 2)
        if cum[-1] <= 0.0:
            return 0.0, self.duration
        return (float(np.searchsorted(cum, low * cum[-1]) * self.dt),
                float(np.searchsorted(cum, high * cum[-1]) * self.dt))

    def window(self, t_end: float) -> "GroundMotion":
        """The first ``t_end`` [s]: samples at t <= t_end (all of them if the
        record is shorter); the kept span goes into source['window_s']."""
        t_end = positive(f"ground motion {self.name}: window end [s]", t_end)
        n = min(self.accel.size, int(math.floor(t_end / self.dt + 1e-9)) + 1)
        src = dict(self.source, window_s=(0.0, (n - 1) * self.dt))
        return GroundMotion(self.name, self.dt, self.accel[:n], src)


def accel_factor(unit: str, where: str = "") -> float:
    """Factor converting an acceleration in ``unit`` to mm/s^2: 'g'
    (9806.65 mm/s^2), 'gal' (cm/s^2) or LENGTH/s^2 (also LENGTH/s/s,
    LENGTH/s2) with a length unit of fvd_bridge.units (mm, m, cm, in, um)."""
    u = str(unit).strip()
    if u == "g":
        return G_MM_S2
    if u.lower() == "gal":
        return FACTORS["d"]["cm"]
    m = re.fullmatch(r"(\w+)/(?:s\^2|s2|s\*\*2|s/s)", u)
    if m and m.group(1) in FACTORS["d"]:
        return FACTORS["d"][m.group(1)]
    known = ", ".join(["g", "gal"] + [f"{x}/s^2" for x in FACTORS["d"]])
    raise InputError(f"{where}unknown acceleration unit '{unit}' (known: {known})")


# ------------------------------------------------------------- text and cells

def _lines(path: str) -> list:
    """The file's lines without line ends (LF or CR LF)."""
    try:
        with open(path, encoding="latin-1") as fh:
            text = fh.read()
    except FileNotFoundError:
        raise InputError(f"{path}: no such file") from None
    except OSError as e:
        raise InputError(f"{path}: cannot read ({e.strerror})") from None
    if not text.strip():
        raise InputError(f"{path}: empty file")
    lines = text.split("\n")
    if lines[-1] == "":
        lines.pop()
    return lines


def _show(text: str) -> str:
    """A file's text, cut to 40 characters and escaped, for a one-line message."""
    return text.strip()[:40].encode("unicode_escape").decode("ascii")


def _number(cell: str, where: str) -> float:
    s = cell.strip()
    if not s:
        raise InputError(f"{where}: blank, a number was expected")
    if not _NUMBER.fullmatch(s):
        raise InputError(f"{where}: '{_show(s)}' is not a number")
    x = float(s.replace("D", "E").replace("d", "e"))
    if not math.isfinite(x):
        raise InputError(f"{where}: '{_show(s)}' is out of range")
    return x


def _integer(cell: str, where: str) -> int:
    s = cell.strip()
    if not _INTEGER.fullmatch(s):
        raise InputError(f"{where}: '{_show(s)}' is not an integer")
    return int(s)


def _cells(line: str) -> list:
    """A text line's cells: split on commas or semicolons if it has any, else on blanks."""
    if _SEPARATORS.search(line):
        cells = [c.strip() for c in _SEPARATORS.split(line)]
        return cells[:-1] if len(cells) > 1 and not cells[-1] else cells
    return line.split()


def starts_with_number(line: str) -> bool:
    """True if the first cell of a text line is a number: a data line, not a header."""
    cells = _cells(line.split("#", 1)[0])
    return bool(cells) and _NUMBER.fullmatch(cells[0]) is not None


def _table(path: str):
    """Rows of numbers from a 1- or 2-column text file: (array [n, ncols], line numbers)."""
    rows, nos = [], []
    for no, line in enumerate(_lines(path), start=1):
        cells = _cells(line.split("#", 1)[0])
        if not cells:
            continue
        if rows and len(cells) != len(rows[0]):
            raise InputError(f"{path}: line {no} has {len(cells)} columns, line {nos[0]} has {len(rows[0])}")
        if len(cells) > 2:
            raise InputError(f"{path}: line {no} has {len(cells)} columns; expected 2 (t, value) or 1 (value)")
        rows.append([_number(c, f"{path}: line {no}, column {k}") for k, c in enumerate(cells, start=1)])
        nos.append(no)
    if not rows:
        raise InputError(f"{path}: no data lines (only comments or blanks)")
    return np.asarray(rows), nos


def _two_column(path: str, dt=None):
    """(t [s], values, line numbers, whether the file has a time column) of a
    2-column file, or of a 1-column one with dt [s]."""
    data, nos = _table(path)
    if data.shape[1] == 1:
        if dt is None:
            raise InputError(f"{path}: 1 column; give the time step dt [s] or add a time column")
        step = positive(f"{path}: dt [s]", dt)
        return step * np.arange(data.shape[0]), data[:, 0], nos, False
    t = data[:, 0]
    bad = np.flatnonzero(np.diff(t) <= 0.0)
    if bad.size:
        k = bad[0] + 1
        raise InputError(f"{path}: line {nos[k]}, column 1: time {t[k]:g} s does not increase "
                         f"(line {nos[k - 1]} has {t[k - 1]:g} s)")
    return t, data[:, 1], nos, True


def read_two_column(path, dt=None):
    """(t [s], values) from a text file of 2 columns t, value (or 1 column
    value with ``dt`` [s]); '#' comments; blanks, commas or semicolons between
    cells. Times strictly increase. Values stay in the file's unit."""
    t, v, _, _ = _two_column(os.fspath(path), dt)
    return t, v


# ------------------------------------------------------------------- readers

def read_text(path, units: str = "g", dt=None) -> GroundMotion:
    """A text accelerogram: 2 columns t [s], a [units], or 1 column a [units]
    with ``dt`` [s]. The times must lie on a uniform grid t0 + k dt within
    dt/4 (times are often printed with few digits); t0 goes into source."""
    p = os.fspath(path)
    k = accel_factor(units, f"{p}: ")
    dt = None if dt is None else positive(f"{p}: dt [s]", dt)
    t, a, nos, timed = _two_column(p, dt)
    if t.size < 2:
        raise InputError(f"{p}: line {nos[0]}: a single sample; a record needs at least 2")
    step = (t[-1] - t[0]) / (t.size - 1) if timed else float(dt)
    if timed and dt is not None and abs(step - float(dt)) > 0.25 * step:
        raise InputError(f"{p}: the time column's step {step:g} s differs from dt = {dt} s")
    off = np.flatnonzero(np.abs(t - t[0] - step * np.arange(t.size)) > 0.25 * step)
    if off.size:
        i = off[0]
        raise InputError(f"{p}: line {nos[i]}, column 1: time {t[i]:g} s is off the uniform grid "
                         f"{t[0]:g} + k {step:g} s (resample the record first)")
    src = {"file": p, "format": "text", "units": str(units), "to_mm_s2": k, "t0_s": float(t[0]), "npts": int(t.size)}
    return GroundMotion(Path(p).stem, step, a * k, src)


def _field(path, lines, i, k, width, what, conv=_number):
    """Field k (from 0) of ``width`` characters on line index i (from 0)."""
    if i >= len(lines):
        raise InputError(f"{path}: line {i + 1}: the file ends; expected {what}")
    a = k * width
    where = f"{path}: line {i + 1}, field {k + 1} (characters {a + 1}-{a + width}, {what})"
    return conv(lines[i][a:a + width], where)


def _block(path, lines, i, npts, per_line, width, what):
    """``npts`` values of fixed ``width``, ``per_line`` a line, from line index
    i: (values, index of the next line)."""
    out = np.empty(npts)
    n = 0
    while n < npts:
        if i >= len(lines):
            raise InputError(f"{path}: line {i}: the file ends after {n} of the {npts} {what} points the header gives")
        m = min(per_line, npts - n)
        have = -(-len(lines[i].rstrip()) // width)
        if have < m:
            raise InputError(f"{path}: line {i + 1}: the data ends after {n + have} of the {npts} {what} "
                             "points the header gives")
        for k in range(m):
            out[n + k] = _field(path, lines, i, k, width, f"{what} point {n + k + 1} of {npts}")
        if lines[i][m * width:].strip():
            raise InputError(f"{path}: line {i + 1}, characters {m * width + 1}-: more {what} values "
                             f"than the {npts} points the header gives")
        n += m
        i += 1
    return out, i


def _no_more_data(path, lines, i, npts, what):
    for j in range(i, len(lines)):
        if lines[j].strip():
            raise InputError(f"{path}: line {j + 1}: data after the {npts} points {what} gives")


def read_smc(path) -> GroundMotion:
    """A USGS SMC corrected accelerogram [cm/s^2], one component.

    Layout (USGS SMC format): 11 text lines, the first '2 CORRECTED
    ACCELEROGRAM'; 6 lines of 8 integers (I10); 10 lines of 5 reals (E15.7);
    N comment lines, N = integer no. 16; then npts = integer no. 17 values,
    8 a line (F10). dt = 1 / (real no. 2, samples per second) [s].
    """
    p = os.fspath(path)
    lines = _lines(p)
    head = lines[0].strip()
    if "CORRECTED ACCELEROGRAM" not in head.upper() or "UNCORRECTED" in head.upper():
        raise InputError(f"{p}: line 1: '{_show(head)}' is not the header of a USGS SMC corrected "
                         "accelerogram ('2 CORRECTED ACCELEROGRAM')")

    def integer(no):  # integer header no. (1-based): lines 12-17, 8 x I10
        return _field(p, lines, 11 + (no - 1) // 8, (no - 1) % 8, 10, f"integer header no. {no}", _integer)

    n_comments, npts = integer(16), integer(17)
    rate = _field(p, lines, 17, 1, 15, "real header no. 2, samples per second")
    if n_comments < 0:
        raise InputError(f"{p}: line 13, field 8: {n_comments} comment lines (integer header no. 16) must be >= 0")
    if npts <= 0:
        raise InputError(f"{p}: line 14, field 1: {npts} points (integer header no. 17) must be > 0")
    if not 0.0 < rate < 1e30:  # 1.7E+38 marks an unset real
        raise InputError(f"{p}: line 18, field 2: sample rate {rate:g} /s (real header no. 2) is unset or not > 0")
    accel, i = _block(p, lines, 27 + n_comments, npts, 8, 10, "acceleration")
    _no_more_data(p, lines, i, npts, "integer header no. 17")
    k = accel_factor("cm/s^2")
    src = {"file": p, "format": "smc", "units": "cm/s^2", "to_mm_s2": k, "npts": npts,
           "event": lines[3].strip(), "station": lines[5].strip()}
    return GroundMotion(Path(p).stem, 1.0 / rate, accel * k, src)


def _v2a_components(p, lines):
    """Each V2A component: (name, description, first data line index, npts, dt [s])."""
    comps, i = [], 0
    while i < len(lines) and any(ln.strip() for ln in lines[i:]):
        head = lines[i].strip()
        if "accelerogram" not in head.lower() or "uncorrected" in head.lower():
            raise InputError(f"{p}: line {i + 1}: '{_show(head)}' is not the header of a GeoNet V2A "
                             "component ('Corrected accelerogram ...')")
        label = lines[i + 12].strip() if i + 12 < len(lines) else ""
        if not label.lower().startswith("component"):
            raise InputError(f"{p}: line {i + 13}: expected 'Component NAME ...', found '{_show(label)}'")
        desc = label[len("component"):].strip()
        # 10 x 10 header: integers on rows 1-4 (10 x I8), reals on rows 5-10 (10 x F8)
        counts = [_field(p, lines, i + 19, k, 8, f"integer header row 4, column {k + 1}", _integer)
                  for k in (3, 4, 5)]
        dt = _field(p, lines, i + 22, 5, 8, "real header row 7, column 6: dt [s]")
        if counts[0] <= 0 or min(counts) < 0:
            raise InputError(f"{p}: line {i + 20}, fields 4-6: point counts {counts} must be > 0 "
                             "(acceleration) and >= 0 (velocity, displacement)")
        if not dt > 0.0:
            raise InputError(f"{p}: line {i + 23}, field 6: dt = {dt:g} s must be > 0")
        comps.append((desc.split()[0] if desc else str(len(comps)), desc, i + 26, counts[0], dt))
        i += 26 + sum(-(-n // 10) for n in counts)
        if i > len(lines):
            raise InputError(f"{p}: line {len(lines)}: the file ends inside component {comps[-1][0]}'s data "
                             f"(header: {counts[0]}, {counts[1]}, {counts[2]} points; lines missing: {i - len(lines)})")
    return comps


def _pick(p, names, descs, component) -> int:
    listing = ", ".join(f"{k} {n}" for k, n in enumerate(names))
    if component is None:
        return 0
    if isinstance(component, (int, np.integer)) or str(component).strip().isdigit():
        k = int(component)
        if 0 <= k < len(names):
            return k
        raise InputError(f"{p}: no component {k}; the file has: {listing}")
    key = str(component).strip().lower()
    for pool in (names, descs):
        hits = [k for k, n in enumerate(pool) if key in n.lower()]
        if len(hits) == 1:
            return hits[0]
        if len(hits) > 1:
            raise InputError(f"{p}: component '{component}' matches {len(hits)} components; the file has: {listing}")
    raise InputError(f"{p}: component '{component}' not found; the file has: {listing}")


def read_v2a(path, component=None) -> GroundMotion:
    """A GeoNet V2A corrected accelerogram [mm/s^2]; ``component``: index from
    0 or part of its name ('N28W', 'up'); default the first.

    Each component (GeoNet strong-motion file format): 16 text lines (the 13th
    'Component NAME ...'), a 10 x 10 header of 4 lines of integers (I8) and 6
    lines of reals (F8), then acceleration, velocity and displacement blocks,
    10 values a line (F8.1). Header row 4, columns 4-6: the blocks' point
    counts; row 7, column 6: dt [s] (1-based).
    """
    p = os.fspath(path)
    lines = _lines(p)
    comps = _v2a_components(p, lines)
    k = _pick(p, [c[0] for c in comps], [c[1] for c in comps], component)
    name, desc, i, npts, dt = comps[k]
    accel, _ = _block(p, lines, i, npts, 10, 8, f"component {name} acceleration")
    src = {"file": p, "format": "v2a", "units": "mm/s^2", "to_mm_s2": 1.0, "npts": npts,
           "component": name, "component_index": k, "components": [c[0] for c in comps],
           "station": lines[1].strip()}
    return GroundMotion(f"{Path(p).stem}:{name}", dt, accel, src)


_AT2_NPTS_DT = (re.compile(r"NPTS\s*=\s*(\d+)\s*,?\s*DT\s*=\s*(\S+?)\s*(?:SEC|$)", re.I),  # NGA-West2
                re.compile(r"^\s*(\d+)\s+(\S+)\s+NPTS", re.I))                         # older NGA


def read_at2(path) -> GroundMotion:
    """A PEER NGA AT2 accelerogram [g]: 4 header lines (the 3rd '... IN UNITS
    OF G', the 4th 'NPTS=  2000, DT=   .0100 SEC' or the older
    '2000   .0100   NPTS, DT'), then NPTS values, blank-separated."""
    p = os.fspath(path)
    lines = _lines(p)
    if len(lines) < 4:
        raise InputError(f"{p}: line {len(lines)}: the file ends inside the 4-line AT2 header")
    if "UNITS OF G" not in lines[2].upper():
        raise InputError(f"{p}: line 3: expected '... IN UNITS OF G' (a PEER AT2 acceleration), "
                         f"found '{_show(lines[2])}'")
    m = next((r.search(lines[3]) for r in _AT2_NPTS_DT if r.search(lines[3])), None)
    if m is None:
        raise InputError(f"{p}: line 4: expected 'NPTS= n, DT= dt SEC' or 'n dt NPTS, DT', "
                         f"found '{_show(lines[3])}'")
    npts = int(m.group(1))
    dt = _number(m.group(2), f"{p}: line 4, DT")
    if npts <= 0 or not dt > 0.0:
        raise InputError(f"{p}: line 4: NPTS = {npts} and DT = {dt:g} s must be > 0")
    vals, last = [], 4
    for no, line in enumerate(lines[4:], start=5):
        cells = line.split()
        if cells and len(vals) >= npts:
            raise InputError(f"{p}: line {no}: more values than the {npts} points line 4 gives")
        vals += [_number(c, f"{p}: line {no}, column {k}") for k, c in enumerate(cells, start=1)]
        last = no if cells else last
    if len(vals) != npts:
        what = "ends after" if len(vals) < npts else "has"
        raise InputError(f"{p}: line {last}: the file {what} {len(vals)} of the {npts} points line 4 gives")
    src = {"file": p, "format": "at2", "units": "g", "to_mm_s2": G_MM_S2, "npts": npts,
           "title": lines[1].strip()}
    return GroundMotion(Path(p).stem, dt, np.asarray(vals) * G_MM_S2, src)


#: reader and native units of each format
FORMATS = {"text": (read_text, None), "smc": (read_smc, "cm/s^2"), "v2a": (read_v2a, "mm/s^2"),
           "at2": (read_at2, "g")}
SUFFIXES = {".smc": "smc", ".v2a": "v2a", ".at2": "at2"}


#: records shipped with the package (records/data), by the name a user gives
#: instead of a file: the 1940 El Centro NS record (public domain; source in its header)
BUILTIN = {"el-centro-1940": "elcentro_1940_NS.txt"}


def builtin_motion_path(name: str) -> str | None:
    """The package's file of the built-in record ``name`` (``BUILTIN``), None for any other name."""
    file = BUILTIN.get(str(name).lower())
    return None if file is None else os.path.join(os.path.dirname(__file__), "data", file)


def read_motion(path, fmt=None, component=None, units=None, dt=None) -> GroundMotion:
    """A ground motion from a file, or a record shipped with the package by
    its name (``BUILTIN``: 'el-centro-1940', where no file of that name
    exists); ``fmt`` 'text', 'smc', 'v2a' or 'at2' (default from the
    suffix: .smc, .V2A, .AT2, otherwise text).

    ``component`` picks a V2A component (index or part of its name);
    ``units`` (default g) and ``dt`` [s] (1-column files) are for text; the
    other formats give their own units and dt.
    """
    p = os.fspath(path)
    if not os.path.exists(p) and builtin_motion_path(p):
        p = builtin_motion_path(p)
    fmt = str(fmt or SUFFIXES.get(Path(p).suffix.lower(), "text")).lower()
    if fmt not in FORMATS:
        raise InputError(f"{p}: unknown format '{fmt}' (known: {', '.join(FORMATS)})")
    reader, native = FORMATS[fmt]
    if fmt == "v2a":
        motion = reader(p, component)
    elif component not in (None, 0, "0"):
        raise InputError(f"{p}: a {fmt} file holds one component; component {component!r} does not apply")
    elif fmt == "text":
        return reader(p, units=units or "g", dt=dt)
    else:
        motion = reader(p)
    if units is not None and accel_factor(units, f"{p}: ") != accel_factor(native):
        raise InputError(f"{p}: a {fmt} file is in {native}; units '{units}' do not apply")
    if dt is not None and not math.isclose(float(dt), motion.dt, rel_tol=1e-6):
        raise InputError(f"{p}: the {fmt} header gives dt = {motion.dt:g} s; dt = {dt} does not apply")
    return motion
