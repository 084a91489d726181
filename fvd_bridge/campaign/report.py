"""Terminal report of a campaign: Table A.7-like summary, Pareto set, warnings."""

from __future__ import annotations


def format_report(summary: dict) -> str:
    devices = summary["devices"]
    lines = ["", "Mean (sigma) over runs of OF and parameters (cf. paper Table A.7)", ""]
    head = f"{'model':<14}{'quantity':<18}" + "".join(f"{d[:16]:>24}" for d in devices)
    lines.append(head)
    lines.append("-" * len(head))
    for spec, m in summary["models"].items():
        rows = [("OF", m["of_mean"], m["of_sigma"])]
        rows += [(f"{n} [{u}]", m["p_mean"][:, j], m["p_sigma"][:, j])
                 for j, (n, u) in enumerate(zip(m["names"], m["units"]))]
        for k, (q, mean, sigma) in enumerate(rows):
            label = f"law {spec}" if k == 0 else ""
            cells = "".join(f"{mean[i]:>13.4g} ({sigma[i]:7.2g})" for i in range(len(devices)))
            lines.append(f"{label:<14}{q[:17]:<18}{cells}")
    lines += ["", f"{'model':<14}{'mean OF':>10}{'beta':>10}  Pareto"]
    for spec, m in summary["models"].items():
        lines.append(f"law {spec:<10}{m['of_overall']:>10.4f}{m['beta']:>10.4f}  "
                     f"{'non-dominated' if m['non_dominated'] else ''}")
    front = [s for s, m in summary["models"].items() if m["non_dominated"]]
    lines.append(f"Pareto set (accuracy vs robustness): {', '.join('law ' + s for s in front)}")
    warn = [(spec, dev, w["message"]) for spec, m in summary["models"].items()
            for dev, ws in m["warnings"].items() for w in ws]
    if warn:
        lines += ["", "Warnings:"]
        lines += [f"  law {spec}, {dev}: {msg}" for spec, dev, msg in warn]
    return "\n".join(lines)
