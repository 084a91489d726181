"""HTML fragments of results: self-contained tables, no resource from another host.

Every number goes through ``numbers`` (``cell``, ``rounded``, ``interval``,
``share``); every table sits in its own box that scrolls sideways when it
is wider than the page (``.scroll``, overflow-x: auto), and a long text
cell (a note, a rule) wraps while numbers stay on one line (``.note``).
"""

from __future__ import annotations

from html import escape

from .numbers import cell, interval, rounded, small_share, with_unit

#: a text cell longer than this many characters is a note: it may wrap
NOTE_CHARS = 40


def _td(value) -> str:
    text = value if isinstance(value, str) else cell(value)  # text: already formatted
    note = len(text) > NOTE_CHARS and " " in text
    return f"<td class='note'>{escape(text)}</td>" if note else f"<td>{escape(text)}</td>"


def table(header: list, rows: list, caption: str = "", css: str = "") -> str:
    """An HTML table in its own scrolling box; every cell escaped, numbers
    rounded (``numbers.cell``); text is shown as given (already formatted)."""
    head = "".join(f"<th>{escape(str(h))}</th>" for h in header)
    body = "".join("<tr>" + "".join(_td(c) for c in row) + "</tr>" for row in rows)
    cap = f"<caption>{escape(caption)}</caption>" if caption else ""
    return (f"<div class='scroll'><table class='fvd{' ' + css if css else ''}'>{cap}<thead><tr>{head}</tr></thead>"
            f"<tbody>{body}</tbody></table></div>")


def short(x, digits: int = 4) -> str:
    """A number in ``digits`` significant digits (``numbers.rounded``); "-" for None."""
    return rounded(x, digits=digits)


def parameter_rows(cal) -> list:
    """Per parameter: name, value rounded to its stderr, unit, stderr, 95%
    interval, search bounds; a parameter fitted per test, a row for each
    further test (its value and interval there); then the derived quantities."""
    rows = []
    for p in cal.params.values():
        ci = "-" if p.ci95 is None else interval(p.ci95[0], p.ci95[1], p.stderr)
        bounds = "-" if None in p.bounds else interval(p.bounds[0], p.bounds[1])
        unit = "" if p.unit == "-" else p.unit
        first = f" ({next(iter(p.per_test))})" if len(p.per_test) > 1 else ""
        rows.append([p.name + first, rounded(p.value, p.stderr), unit, rounded(p.stderr, digits=2), ci, bounds])
        per_test_ci = (cal.intervals.of_parameter(p.name).get("per_test_ci95") if cal.intervals else None) or {}
        for test, value in list(p.per_test.items())[1:]:
            lo_hi = per_test_ci.get(test)
            rows.append([f"{p.name} ({test})", rounded(value, p.stderr), unit, "",
                         "-" if lo_hi is None else interval(lo_hi[0], lo_hi[1], p.stderr), bounds])
    rows += [[name, rounded(value), unit, "", "", "(derived)"] for name, (value, unit) in cal.derived().items()]
    return rows


def calibration_table(cal) -> str:
    """A calibration: its model and OF, then one row per parameter (value
    rounded to its uncertainty, unit, stderr, 95% interval, bounds) and its warnings."""
    caption = (f"law {cal.spec} on {cal.device or cal.record.name or '?'}: OF {rounded(cal.of)} "
               f"({len(cal.tests) or 1} test(s))")
    out = table(["parameter", "value", "unit", "stderr", "95% interval", "search bounds"], parameter_rows(cal), caption)
    if cal.warnings:
        out += "<ul>" + "".join(f"<li>{escape(str(w))}</li>" for w in cal.warnings) + "</ul>"
    return out


def diagnosis_table(diag) -> str:
    """A diagnosis: the verdict, then one row per candidate effect, each named as the model it is."""
    rows = [[f"{diag.spec}+{c.effect}", rounded(c.of), small_share(c.improvement), "yes" if c.significant else "no",
             c.size.text if c.size else "", c.reason] for c in diag.candidates]
    caption = (f"each effect added to law {diag.spec} on {diag.record} and refitted; law {diag.spec} alone: "
               f"OF {rounded(diag.of)}, noise floor {rounded(diag.floor)}")
    return (f"<p>{escape(diag.verdict())}</p>"
            + table(["model", "OF", "lower by", "credited", "size", "why not"], rows, caption)
            + ("" if diag.zero is None else zero_table(diag.zero.as_dict(), diag.spec)))


def zero_table(zero: dict, spec: str = "") -> str:
    """The tests' force zero of a diagnosis (``Zero.as_dict``): one row per test."""
    rows = [[name, f"{'+' if z['F0_kN'] >= 0 else ''}{rounded(z['F0_kN'], digits=3)}",
             f"{'+' if z['F1_kN_per_s'] >= 0 else ''}{rounded(z['F1_kN_per_s'], digits=2)}",
             rounded(z["at_rest_kN"], digits=3)] for name, z in zero["tests"].items()]
    model = f"law {spec}: " if spec else ""
    return table(["test", with_unit("offset F0", "kN"), with_unit("drift F1", "kN/s"),
                  with_unit("force at rest", "kN")], rows,
                 f"the tests' force zero (a measurement nuisance, not exported); {model}OF {rounded(zero['of_base'])} "
                 f"-> {rounded(zero['of'])} with it")
