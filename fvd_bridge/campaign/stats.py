"""Statistics of a campaign (paper sections 6-7, Table A.7, eqs. 19-23)."""

from __future__ import annotations

import numpy as np


def deltas(device_means: np.ndarray) -> np.ndarray:
    """Delta_mn = (alpha_mn - mean_m alpha_mn) / mean_m alpha_mn  (eq. 19-21).

    ``device_means`` (n_devices, n_par): each parameter identified on each
    device as the mean over runs.  A parameter whose mean over devices is 0
    has no relative scatter: NaN.
    """
    mean = device_means.mean(axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(mean != 0.0, (device_means - mean) / mean, np.nan)


def robustness(device_means: np.ndarray) -> tuple[np.ndarray, float]:
    """Delta_n = max_m |Delta_mn| (eq. 22) and beta_j = mean_n Delta_n (eq. 23)."""
    delta_n = np.nanmax(np.abs(deltas(device_means)), axis=0) if len(device_means) else np.array([])
    finite = delta_n[np.isfinite(delta_n)]
    return delta_n, float(finite.mean()) if finite.size else float("nan")


def non_dominated(points: np.ndarray) -> np.ndarray:
    """Pareto set of points (n, 2) to be minimised in both columns (Fig. 14):
    True where no other point is at least as good in both and better in one."""
    pts = np.asarray(points, dtype=float)
    keep = np.ones(len(pts), bool)
    for i, p in enumerate(pts):
        if not np.all(np.isfinite(p)):
            keep[i] = False
            continue
        others = np.delete(pts, i, axis=0)
        others = others[np.all(np.isfinite(others), axis=1)]
        dominated = np.any(np.all(others <= p, axis=1) & np.any(others < p, axis=1))
        keep[i] = not dominated
    return keep
