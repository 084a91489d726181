"""A series' production statistics as text (``campaign.production``: outliers per
model, and the acceptance at the design velocity, ``campaign.acceptance``)."""

from __future__ import annotations

import numpy as np

from ..campaign import stats


def format_production(prod: dict, accept: dict | None, shown: int = 8) -> str:
    """A few lines for the terminal: outliers and acceptance per model."""
    devices = prod["devices"]
    lines = ["", f"Production statistics over {len(devices)} devices (outlier: |x - median| > "
                 f"{prod['k']:g} x 1.4826 MAD)"]
    for spec, m in prod["models"].items():
        idx = np.flatnonzero(m["outlier_devices"])
        if len(devices) < stats.MIN_FOR_OUTLIERS:
            text = f"too few devices to judge outliers (fewer than {stats.MIN_FOR_OUTLIERS})"
        elif not idx.size:
            text = "no outliers"
        else:
            names = [f"{devices[i]} ({', '.join(n for n, c in zip(m['names'], m['columns']) if c['flags'][i])})"
                     for i in idx[:shown]]
            text = f"{idx.size} outlier device(s): {'; '.join(names)}{' ...' if idx.size > shown else ''}"
        lines.append(f"  law {spec}: {text}")
    if accept is not None:
        s = accept["settings"]
        if accept.get("why_not"):
            lines.append("  acceptance: no nominal force (give acceptance: {nominal_force: KN} in the campaign file)")
        else:
            lines.append(f"Acceptance at {s['velocity']:g} mm/s: nominal {accept['nominal_force']:.4g} kN "
                         f"({accept['nominal_source']}) +- {s['tolerance']:.0%}")
            for spec, a in accept["models"].items():
                failed = [devices[i] for i in np.flatnonzero(~a["passed"])]
                lines.append(f"  law {spec}: {int(a['passed'].sum())}/{len(devices)} pass"
                             + (f"; fail: {', '.join(failed[:shown])}{' ...' if len(failed) > shown else ''}"
                                if failed else ""))
        lines += [f"  law {spec}: not checked ({why})" for spec, why in accept.get("skipped", {}).items()]
    return "\n".join(lines)
