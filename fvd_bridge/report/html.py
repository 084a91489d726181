"""HTML fragments of results: self-contained tables, no resource from another host."""

from __future__ import annotations

from html import escape


def table(header: list, rows: list, caption: str = "") -> str:
    """An HTML table; every cell is escaped text."""
    head = "".join(f"<th>{escape(str(h))}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{escape(str(c))}</td>" for c in row) + "</tr>" for row in rows)
    cap = f"<caption>{escape(caption)}</caption>" if caption else ""
    return f"<table class='fvd'>{cap}<thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def short(x, digits: int = 5) -> str:
    """A number in ``digits`` significant digits; "-" for None."""
    return "-" if x is None else f"{x:.{digits}g}"


def calibration_table(cal) -> str:
    """A calibration: its model and OF, then one row per parameter (value,
    unit, stderr, 95% interval, bounds) and its warnings."""
    rows = [[p.name, short(p.value, 6), p.unit, short(p.stderr, 2),
             "-" if p.ci95 is None else f"[{p.ci95[0]:.5g}, {p.ci95[1]:.5g}]",
             "-" if None in p.bounds else f"[{p.bounds[0]:.4g}, {p.bounds[1]:.4g}]"]
            for p in cal.params.values()]
    rows += [[name, short(value, 6), unit, "", "", "(derived)"] for name, (value, unit) in cal.derived().items()]
    caption = (f"{cal.spec} on {cal.device or cal.record.get('name', '?')}: OF {cal.of:.5g} "
               f"({len(cal.tests) or 1} test(s))")
    out = table(["parameter", "value", "unit", "stderr", "95% interval", "bounds"], rows, caption)
    if cal.warnings:
        out += "<ul>" + "".join(f"<li>{escape(str(w))}</li>" for w in cal.warnings) + "</ul>"
    return out


def diagnosis_table(diag) -> str:
    """A diagnosis: the verdict, then one row per candidate effect."""
    rows = [[c.effect, short(c.of), f"{c.improvement:.1%}", "yes" if c.significant else "no",
             c.size.text if c.size else "", c.reason] for c in diag.candidates]
    caption = f"{diag.spec} on {diag.record}: OF {diag.of:.5g}, noise floor {diag.floor:.4g}"
    return (f"<p>{escape(diag.verdict())}</p>"
            + table(["effect", "OF", "lower by", "credited", "size", "why not"], rows, caption)
            + ("" if diag.zero is None else zero_table(diag.zero.as_dict())))


def zero_table(zero: dict) -> str:
    """The tests' force zero of a diagnosis (``Zero.as_dict``): one row per test."""
    rows = [[name, f"{z['F0_kN']:+.3g}", f"{z['F1_kN_per_s']:+.2g}",
             "-" if z["at_rest_kN"] is None else f"{z['at_rest_kN']:+.3g}"] for name, z in zero["tests"].items()]
    return table(["test", "offset F0 [kN]", "drift F1 [kN/s]", "force at rest [kN]"], rows,
                 f"the tests' force zero (a measurement nuisance, not exported): OF {zero['of_base']:.4g} -> "
                 f"{zero['of']:.4g} with it")
