"""A series' upper and lower damper properties as text (``campaign.property_bounds``:
ASCE 7's lambda_min and lambda_max), as ``campaign`` and ``calibrate`` print them."""

from __future__ import annotations

from ..campaign.property_bounds import SOURCE
from ..report.numbers import rounded, share, with_unit
from .table import columns


def format_bounds(bounds: dict) -> str:
    """The printed table: per model and quantity the nominal, lambda_min,
    lambda_max and the bounds, rounded (``report.numbers``)."""
    s = bounds["settings"]
    lines = ["", f"Upper and lower bounds at the design velocity V = {rounded(bounds['velocity'], digits=3)} mm/s "
                 f"({SOURCE})",
             f"{bounds['statistic']}; lambda_spec 1 -+ {share(s['spec'])}; lambda_ae {rounded(s['aging_min'], digits=3)}"
             f" / {rounded(s['aging_max'], digits=3)}"]
    head = ["model", "quantity", "nominal", "lambda_min", "lambda_max", "lower", "upper"]
    body = []
    for spec, m in bounds["models"].items():
        for r in m["rows"]:
            unit = "" if r["unit"] in ("-", "") else r["unit"]
            body.append([f"law {spec}", with_unit(r["quantity"], unit), rounded(r["nominal"]),
                         rounded(r["lambda_min"], digits=3), rounded(r["lambda_max"], digits=3),
                         rounded(r["lower"]), rounded(r["upper"])])
    if body:
        lines += columns(head, body, right_from=2)
    nominal = ", ".join(f"law {spec}: {m['nominal_device']}" for spec, m in bounds["models"].items())
    if nominal:
        lines.append(f"nominal device (force at the design velocity nearest the series' mean): {nominal}")
    lines += [f"no bounds: {why}" for why in bounds.get("skipped", {}).values()]
    return "\n".join(lines)
