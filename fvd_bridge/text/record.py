"""A record's summary as text (``records.summary.summarize``): what ``fvd-bridge inspect`` prints."""

from __future__ import annotations

import numpy as np


def format_summary(s: dict) -> str:
    """The summary as aligned text lines."""
    noise = s["force_noise_kN"]
    rel = f" ({100 * noise / s['peak_F_kN']:.2g}% of peak |F|)" if s["peak_F_kN"] > 0 else ""
    vn = s["velocity_noise_mm_s"]
    vrel = f" ({100 * vn / s['peak_v_mm_s']:.2g}% of peak |v|)" if s["peak_v_mm_s"] > 0 and np.isfinite(vn) else ""
    order = [k for k in ("t", "d", "F", "v") if k in s["columns"]]
    cols = ", ".join(f"{k}={s['columns'][k]}" for k in order)
    units = ", ".join(f"{k}={s['units'][k]}" for k in order if k in s["units"])
    lines = [
        f"record       {s['name']}  ({s['file']})",
        f"columns      {cols}",
        f"read units   {units}  ({'the header' + chr(39) + 's, ' if s.get('header_units') else ''}"
        f"converted to s, mm, kN, mm/s)",
        f"samples      {s['samples']}",
        f"time step    {s['dt_s']:.6g} s  ({1 / s['dt_s']:.4g} Hz)",
        f"duration     {s['duration_s']:.6g} s",
        f"cycles       {s['cycles']:.2f}",
        f"peak d       {s['peak_d_mm']:.4g} mm (about the median)",
        f"peak v       {s['peak_v_mm_s']:.4g} mm/s",
        f"peak F       {s['peak_F_kN']:.4g} kN",
        f"force noise  {noise:.3g} kN{rel}",
        f"disp. noise  {s['disp_noise_mm']:.3g} mm",
        f"vel. noise   {vn:.3g} mm/s{vrel} (median)",
        f"velocity     {s['velocity']}",
        f"warnings     {len(s['warnings']) or 'none'}",
    ]
    lines += [f"  - {w}" for w in s["warnings"]]
    return "\n".join(lines)
