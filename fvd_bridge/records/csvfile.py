"""CSV reader: comment lines (#), a header row, then one sample per row.

Cells are separated by commas (or semicolons, tabs or blanks, detected from
the header). Canonical columns are ``t,d,F`` (and optional ``v``); other
names come from ``ReadOptions.columns``. A header cell may carry its unit,
``d [mm]`` or ``F (kN)`` (any unit of fvd_bridge.units, ``unit_name``): the
column is then found by its bare name too, and the unit is the file's
(``RawColumns.units``; ``--units`` and the sidecar win). Rows in messages are
the file's own line numbers, counted from 1.
"""

from __future__ import annotations

import csv
import re

import numpy as np

from ..errors import InputError, option
from ..units import FACTORS, unit_name
from .options import Given, ReadOptions
from .raw import RawColumns

#: separators tried on the header line, in order of preference; None: blanks
DELIMITERS = (",", ";", "\t")
#: a header cell with its unit: 'd [mm]', 'F (kN)', 't[s]'
WITH_UNIT = re.compile(r"^(?P<name>.*?)\s*(?:\[(?P<b>[^\]]*)\]|\((?P<p>[^)]*)\))$")


def read_csv(path: str, opts: ReadOptions) -> RawColumns:
    """Read the t/d/F[/v] columns of a CSV file (values in the file's units)."""
    lines = _lines(path)
    body = [(no, ln) for no, ln in enumerate(lines, start=1) if ln.strip() and not ln.lstrip().startswith("#")]
    if not body:
        raise InputError(f"{path}: empty file (expected a header such as t,d,F)")
    (header_no, header_line), body = body[0], body[1:]
    delim = next((c for c in DELIMITERS if c in header_line), None)
    header = [h.strip() for h in _split(header_line, delim)]
    if all(_is_number(h) for h in header):
        raise InputError(f"{path}: row {header_no}: expected a header such as t,d,F, found numbers "
                         f"('{header_line.strip()[:40]}')")
    if not body:
        raise InputError(f"{path}: row {header_no}: a header but no data rows")
    index, names, units = _locate(path, header_no, header, opts)
    rows = np.array([no for no, _ in body], dtype=int)
    data = {key: np.empty(rows.size) for key in index}
    for j, (no, line) in enumerate(body):
        cells = _split(line, delim)
        for key, c in index.items():
            if c >= len(cells):
                raise InputError(f"{path}: row {no}, column '{names[key]}': missing (the row has {len(cells)} "
                                 f"cells, the header {len(header)}: columns of unequal length)")
            cell = cells[c].strip()
            try:
                data[key][j] = float(cell)
            except ValueError:
                what = "empty cell" if not cell else f"'{cell[:30]}' is not a number"
                raise InputError(f"{path}: row {no}, column '{names[key]}': {what}") from None
        if len(cells) > len(header) and any(c.strip() for c in cells[len(header):]):
            raise InputError(f"{path}: row {no}, column {len(header) + 1}: the row has {len(cells)} cells, "
                             f"the header {len(header)} (columns of unequal length)")
    time_given = "t" in data
    if not time_given:
        data["t"], names["t"] = opts.dt * np.arange(rows.size), f"<dt {opts.dt:g} s from --dt or sidecar>"
    return RawColumns(data, rows, names, time_given, units)


def _lines(path: str) -> list[str]:
    """The file's lines (\\n, \\r\\n or \\r endings), as UTF-8 or else Latin-1 text."""
    try:
        with open(path, "rb") as fh:
            raw = fh.read()
    except OSError as exc:
        raise InputError(f"{path}: cannot read ({exc.strerror or type(exc).__name__})") from None
    if b"\x00" in raw[:4096]:
        raise InputError(f"{path}: a binary file, not CSV text (a MATLAB file needs the .mat extension)")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        text = raw.decode("latin-1")
    return re.split(r"\r\n|\r|\n", text)


def _split(line: str, delim: str | None) -> list[str]:
    if delim is None:
        return line.split()
    return next(csv.reader([line], delimiter=delim), [])


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _split_unit(cell: str) -> tuple[str, str | None]:
    """'d [mm]' -> ('d', 'mm'); 'F (kN)' -> ('F', 'kN'); 'load' -> ('load', None)."""
    m = WITH_UNIT.match(cell)
    if not m or not m.group("name"):
        return cell, None
    return m.group("name"), (m.group("b") if m.group("b") is not None else m.group("p")).strip()


def _locate(path: str, header_no: int, header: list[str], opts: ReadOptions) -> tuple[dict, dict, dict]:
    """Header position of each wanted column (by its cell, or its name
    without the unit), and the units the header gives (--units and the
    sidecar win over them, noted where they differ: ``readers.unit_overrides``);
    v is optional, t may come from dt."""
    wanted = {"t": "t", "d": "d", "F": "F", **opts.columns}
    bare = [_split_unit(h) for h in header]
    index, names, units = {}, {}, {}
    for key, col in wanted.items():
        found = header.index(col) if col in header else next(
            (i for i, (name, _) in enumerate(bare) if name == col), None)
        if found is not None:
            index[key], names[key] = found, header[found]
            continue
        if key == "t" and "t" not in opts.columns and opts.dt is not None:
            continue  # time from --dt
        hint = "" if key in opts.columns else (
            f"; name the columns with {option('--columns', Given(t='...', d='...', F='...'))} or a sidecar YAML")
        raise InputError(f"{path}: row {header_no}, column '{col}' (for {key}) not found; the header has: "
                         f"{', '.join(header)}{hint}")
    if "v" not in index and "v" not in opts.columns and not opts.derive_velocity:
        found = next((i for i, (name, _) in enumerate(bare) if name == "v"), None)
        if found is not None:
            index["v"], names["v"] = found, header[found]
    for key, i in index.items():
        text = bare[i][1]
        if text is None:
            continue
        unit = unit_name(key, text)
        if unit is None and key in opts.units:
            continue  # the caller's unit stands for one the table does not know
        if unit is None:
            raise InputError(f"{path}: row {header_no}, column '{header[i]}': unknown unit '{text}' for {key} "
                             f"(known: {', '.join(FACTORS[key])}); give it with "
                             f"{option('--units', Given({key: 'UNIT'}))}")
        units[key] = unit
    return index, names, units
