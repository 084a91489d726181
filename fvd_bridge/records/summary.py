"""Summary of a record: what ``fvd-bridge inspect`` prints (as text: ``text.record``)."""

from __future__ import annotations

import numpy as np

from .cycles import count_cycles, displacement_noise, force_noise
from .record import Record


def summarize(rec: Record) -> dict:
    """Samples, time step [s], duration [s], cycles, peaks (d [mm] about the
    median, |v| [mm/s], |F| [kN]), force noise [kN] (cycles.force_noise),
    displacement noise [mm] (cycles.displacement_noise, or the record's
    d_noise), velocity noise [mm/s] (median over the record of its per-sample
    v_noise; nan when unknown), velocity method and the reader's warnings."""
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
        "disp_noise_mm": float(rec.d_noise) if rec.d_noise is not None else displacement_noise(rec.d),
        "velocity_noise_mm_s": float(np.median(rec.v_noise)) if rec.v_noise is not None else float("nan"),
        "velocity": velocity_text(vel),
        "columns": rec.provenance.get("columns", {}),
        "units": rec.provenance.get("units", {}),
        "header_units": rec.provenance.get("header_units", {}),
        "warnings": list(rec.warnings),
    }


def velocity_text(vel: dict) -> str:
    """One line describing how velocity was obtained."""
    if vel.get("method") == "measured":
        return f"measured (column '{vel.get('column')}')"
    if vel.get("method") == "savgol" and vel.get("window_chosen") == "adaptive":
        lo, hi = vel["windows_used"]
        return (f"Savitzky-Golay derivative of d, order {vel['polyorder']}, window chosen per sample by ICI "
                f"(Gamma {vel['gamma']:g}): {lo}..{hi} samples, median {vel['window_median']}")
    if vel.get("method") == "savgol":
        return (f"Savitzky-Golay derivative of d, window {vel['window']} samples "
                f"({vel['window_s']:.4g} s, {vel.get('window_chosen', 'user')}), order {vel['polyorder']}")
    return str(vel.get("method", "unknown"))
