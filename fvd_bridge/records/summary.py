"""Summary of a record: what ``fvd-bridge inspect`` prints."""

from __future__ import annotations

import numpy as np

from .cycles import count_cycles, force_noise
from .record import Record


def summarize(rec: Record) -> dict:
    """Samples, time step [s], duration [s], cycles, peaks (d [mm] about the
    median, |v| [mm/s], |F| [kN]), force noise [kN] (cycles.force_noise),
    velocity method and the reader's warnings."""
    vel = rec.provenance.get("velocity", {})
    return {
        "name": rec.name,
        "file": rec.provenance.get("file", ""),
        "samples": rec.n,
        "dt_s": rec.dt,
        "duration_s": rec.duration,
        "cycles": count_cycles(rec.d),
        "peak_d_mm": float(np.max(np.abs(rec.d - np.median(rec.d)))),
        "peak_v_mm_s": float(np.max(np.abs(rec.v))),
        "peak_F_kN": float(np.max(np.abs(rec.F))),
        "force_noise_kN": force_noise(rec.F),
        "velocity": velocity_text(vel),
        "columns": rec.provenance.get("columns", {}),
        "units": rec.provenance.get("units", {}),
        "warnings": list(rec.warnings),
    }


def velocity_text(vel: dict) -> str:
    """One line describing how velocity was obtained."""
    if vel.get("method") == "measured":
        return f"measured (column '{vel.get('column')}')"
    if vel.get("method") == "savgol":
        return (f"Savitzky-Golay derivative of d, window {vel['window']} samples "
                f"({vel['window_s']:.4g} s, {vel.get('window_chosen', 'user')}), order {vel['polyorder']}")
    return str(vel.get("method", "unknown"))


def format_summary(s: dict) -> str:
    """The summary as aligned text lines."""
    noise = s["force_noise_kN"]
    rel = f" ({100 * noise / s['peak_F_kN']:.2g}% of peak |F|)" if s["peak_F_kN"] > 0 else ""
    order = [k for k in ("t", "d", "F", "v") if k in s["columns"]]
    cols = ", ".join(f"{k}={s['columns'][k]}" for k in order)
    units = ", ".join(f"{k}={s['units'][k]}" for k in order if k in s["units"])
    lines = [
        f"record       {s['name']}  ({s['file']})",
        f"columns      {cols}",
        f"read units   {units}  (converted to s, mm, kN, mm/s)",
        f"samples      {s['samples']}",
        f"time step    {s['dt_s']:.6g} s  ({1 / s['dt_s']:.4g} Hz)",
        f"duration     {s['duration_s']:.6g} s",
        f"cycles       {s['cycles']:.2f}",
        f"peak d       {s['peak_d_mm']:.4g} mm (about the median)",
        f"peak v       {s['peak_v_mm_s']:.4g} mm/s",
        f"peak F       {s['peak_F_kN']:.4g} kN",
        f"force noise  {noise:.3g} kN{rel}",
        f"velocity     {s['velocity']}",
        f"warnings     {len(s['warnings']) or 'none'}",
    ]
    lines += [f"  - {w}" for w in s["warnings"]]
    return "\n".join(lines)
