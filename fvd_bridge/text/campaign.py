"""Terminal report of a campaign: Table A.7-like summary, Pareto set, warnings.

Columns are as wide as their longest entry: no name is cut, no two columns
touch.  Numbers go through ``report.numbers``: a mean rounded to its sigma
over runs (``with_spread``; the mean alone where the runs agree), the
robustness index to three digits.  The robustness index and the Pareto set
are series material: with one device they are not printed.
"""

from __future__ import annotations

from ..errors import option
from ..report.numbers import has_spread, rounded, with_spread

GAP = 2  # spaces between columns


def _width(items, minimum: int = 0) -> int:
    return max([minimum] + [len(str(x)) for x in items])


def format_report(summary: dict) -> str:
    devices = summary["devices"]
    models = summary["models"]
    labels = [f"law {spec}" for spec in models]
    quantities = (["OF"] + [f"{n} [{u}]" for m in models.values() for n, u in zip(m["names"], m["units"])]
                  + [row[0] for m in models.values() for row in _test_rows(m, len(devices))])
    w_model, w_q = _width(labels, 5) + GAP, _width(quantities, 8) + GAP
    w_cell = max(_width(devices), 20) + GAP  # '1.2345e+05 (1.2e+03)'
    rows = {spec: _rows(m, len(devices)) for spec, m in models.items()}
    spread = any(has_spread(mean[i], sigma[i]) for r in rows.values() for _, mean, sigma in r
                 for i in range(len(devices)))
    lines = ["", _table_title(spread), ""]
    head = f"{'model':<{w_model}}{'quantity':<{w_q}}" + "".join(f"{d:>{w_cell}}" for d in devices)
    lines += [head, "-" * len(head)]
    for spec, model_rows in rows.items():
        for k, (q, mean, sigma) in enumerate(model_rows):
            label = f"law {spec}" if k == 0 else ""
            cells = "".join(f"{with_spread(mean[i], sigma[i]):>{w_cell}}" for i in range(len(devices)))
            lines.append(f"{label:<{w_model}}{q:<{w_q}}{cells}")
    lines += _runs_lines(models, summary.get("runs"))
    lines += [""] + _pareto_lines(models, w_model, len(devices))
    ivals = summary.get("intervals") or {}
    if ivals:
        lines += ["", "95% intervals of the calibrations (bootstrap of the measurement chain):"]
        for (dev, spec), rows in ivals.items():
            lines.append(f"  law {spec}, {dev}:")
            lines += [f"    {row}" for row in rows]
    warn = [(spec, dev, w["message"]) for spec, m in models.items()
            for dev, ws in m["warnings"].items() for w in ws]
    if warn:
        lines += ["", "Warnings:"]
        lines += [f"  law {spec}, {dev}: {msg}" for spec, dev, msg in warn]
    return "\n".join(lines)


def _rows(m: dict, n_devices: int) -> list:
    """A model's rows of the table: (quantity, mean per device, sigma over runs per device)."""
    rows = [("OF", m["of_mean"], m["of_sigma"])] + _test_rows(m, n_devices)
    return rows + [(f"{n} [{u}]", m["p_mean"][:, j], m["p_sigma"][:, j])
                   for j, (n, u) in enumerate(zip(m["names"], m["units"]))]


def _table_title(spread: bool) -> str:
    """The table's title: a sigma is promised only where one is shown."""
    if spread:
        return "Mean (sigma) over runs of OF and parameters (cf. paper Table A.7; a mean alone: the runs agree)"
    return "Mean over runs of OF and parameters (cf. paper Table A.7; the runs agree: no sigma to show)"


def _runs_lines(models: dict, asked: int | None) -> list:
    """Which models' first runs ended on one optimum, so the others were not made."""
    settled = [spec for spec, m in models.items() if asked and m.get("runs_made", asked) < asked]
    if not settled:
        return []
    made = models[settled[0]]["runs_made"]
    return [f"law {', '.join(settled)}: the first {made} runs ended on one optimum on every device; the other "
            f"{asked - made} of {asked} were not made ({option('--all-runs')} makes them)"]


def _test_rows(m: dict, n_devices: int) -> list:
    """Rows of the OF on each test, for devices identified from several tests."""
    n_tests = max((len(names) for names in m.get("test_names", [])), default=1)
    if n_tests < 2:
        return []
    rows = []
    for k in range(n_tests):
        label = f"  OF {m['test_names'][0][k]}" if n_devices == 1 else f"  OF test {k + 1}"
        mean = [m["test_of"][i][0][k] if k < len(m["test_names"][i]) else None for i in range(n_devices)]
        sigma = [m["test_of"][i][1][k] if k < len(m["test_names"][i]) else None for i in range(n_devices)]
        rows.append((label, mean, sigma))
    return rows


def _pareto_lines(models: dict, w_model: int, n_devices: int) -> list:
    """Per model: mean OF, the robustness index beta_r (paper eq. 23; 'beta_r', not a
    law's parameter beta) and the Pareto flag; the Pareto set; the robustness
    notes (about beta_r: with one device, neither is shown)."""
    if n_devices < 2:
        lines = [f"{'model':<{w_model}}{'OF':>10}  (best first)"]
        lines += [f"{'law ' + spec:<{w_model}}{rounded(m['of_overall']):>10}"
                  for spec, m in sorted(models.items(), key=lambda item: item[1]["of_overall"])]
        lines.append("one device: beta_r (the robustness index) and the Pareto front measure the scatter over "
                     "devices, so they are not shown; calibrate several devices of the series to compare robustness")
    else:
        lines = [f"{'model':<{w_model}}{'mean OF':>10}{'beta_r':>10}  Pareto  (beta_r: robustness index over devices)"]
        for spec, m in models.items():
            lines.append(f"{'law ' + spec:<{w_model}}{rounded(m['of_overall']):>10}{rounded(m['beta'], digits=3):>10}  "
                         f"{'non-dominated' if m['non_dominated'] else ''}")
        front = [s for s, m in models.items() if m["non_dominated"]]
        lines.append(f"Pareto set (accuracy vs robustness): {', '.join('law ' + s for s in front)}")
        notes = [(spec, note) for spec, m in models.items() for note in m.get("notes", [])]  # about beta_r
        if notes:
            lines += ["", "Robustness notes:"] + [f"  law {spec}, {note}" for spec, note in notes]
    return lines


def format_series(summary: dict, shown: int = 3) -> str:
    """The report of a large series: per model mean OF, beta, Pareto flag and the
    warnings counted by kind (the first few devices named); every value is in the files."""
    models = summary["models"]
    w_model = _width([f"law {s}" for s in models], 5) + GAP
    lines = ["", f"{len(summary['devices'])} devices", ""] + _pareto_lines(models, w_model, len(summary["devices"]))
    counts = []
    for spec, m in models.items():
        by_code: dict = {}
        for dev, ws in m["warnings"].items():
            for w in ws:
                by_code.setdefault(w["code"], []).append(dev)
        for code, devs in by_code.items():
            devs = list(dict.fromkeys(devs))
            more = ", ..." if len(devs) > shown else ""
            counts.append(f"  law {spec}: {code} on {len(devs)} device(s) ({', '.join(devs[:shown])}{more})")
    if counts:
        lines += ["", "Warnings (messages in summary.json and the parameter files):"] + counts
    return "\n".join(lines)
