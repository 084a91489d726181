"""Statistics of a campaign (paper sections 6-7, Table A.7, eqs. 19-23) and of a
production series (robust outliers).

Rules at the edges, stated once here:

- **near-zero mean** (``near_zero``): eqs. 19-21 divide by a parameter's mean
  over devices.  A linearly searched parameter whose mean over devices is
  within ``NEAR_ZERO`` = 1% of the width of its search range from zero
  (|mean| < 0.01 (upper - lower)) has no meaningful relative scatter (law 6's
  alpha = 0 on one device and 0.0025 on another: mean 0.00125 in [0, 1]
  would give Delta = +-100%).  Its Delta_mn and Delta_n are NaN, it is
  reported as near-zero and kept out of beta.  A parameter searched on a
  log scale (lower bound > 0, range over decades) keeps its relative scatter.
- **outliers** (``robust_outliers``): x is an outlier when
  |x - median| > k 1.4826 MAD (k = ``OUTLIER_K`` = 3.5 unless stated;
  1.4826 MAD estimates the standard deviation of normal data; Iglewicz and
  Hoaglin's modified z-score > 3.5).  When MAD = 0 (over half the values
  equal) the scale is 1.2533 times the mean absolute deviation from the
  median; when that is 0 too, nothing is an outlier.
"""

from __future__ import annotations

import numpy as np

#: a parameter's mean over devices is near zero below this share of its search range width
NEAR_ZERO = 0.01
#: outlier threshold in robust standard deviations (1.4826 MAD)
OUTLIER_K = 3.5
#: fewest values for which outliers are judged
MIN_FOR_OUTLIERS = 5


def near_zero(device_means: np.ndarray, ranges=None, log=None) -> np.ndarray:
    """Per parameter: True when its mean over devices is near zero (module rule).

    ``device_means`` (n_devices, n_par); ``ranges`` (n_par, 2) the search
    range [lower, upper] in the parameter's unit (None: only an exact 0 is
    near zero); ``log`` (n_par,) True for parameters searched on a log scale.
    """
    means = np.atleast_2d(np.asarray(device_means, dtype=float))
    mean = means.mean(axis=0) if len(means) else np.zeros(means.shape[1])
    if ranges is None:
        return mean == 0.0
    r = np.asarray(ranges, dtype=float).reshape(-1, 2)
    width = r[:, 1] - r[:, 0]
    linear = ~np.asarray(log, dtype=bool) if log is not None and len(log) else np.ones(len(mean), bool)
    return (mean == 0.0) | (linear & (np.abs(mean) < NEAR_ZERO * width))


def deltas(device_means: np.ndarray, excluded=None) -> np.ndarray:
    """Delta_mn = (alpha_mn - mean_m alpha_mn) / mean_m alpha_mn  (eq. 19-21).

    ``device_means`` (n_devices, n_par): each parameter identified on each
    device as the mean over runs.  A parameter whose mean over devices is 0,
    or that ``excluded`` (n_par bools, e.g. from ``near_zero``) marks, has
    no relative scatter: NaN.
    """
    mean = device_means.mean(axis=0)
    bad = mean == 0.0
    if excluded is not None:
        bad = bad | np.asarray(excluded, dtype=bool)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(bad, np.nan, (device_means - mean) / np.where(bad, 1.0, mean))


def robustness(device_means: np.ndarray, excluded=None) -> tuple[np.ndarray, float]:
    """Delta_n = max_m |Delta_mn| (eq. 22) and beta_j = mean_n Delta_n (eq. 23)
    over the parameters with a finite Delta_n (``excluded`` ones are NaN)."""
    if not len(device_means):
        return np.array([]), float("nan")
    d = np.abs(deltas(device_means, excluded))
    finite_cols = np.any(np.isfinite(d), axis=0)
    delta_n = np.full(d.shape[1], np.nan)
    delta_n[finite_cols] = np.nanmax(d[:, finite_cols], axis=0)
    finite = delta_n[np.isfinite(delta_n)]
    return delta_n, float(finite.mean()) if finite.size else float("nan")


def robust_scale(x) -> tuple[float, float]:
    """(median, robust standard deviation): 1.4826 MAD, or 1.2533 x the mean
    absolute deviation from the median when MAD = 0 (module rule)."""
    x = np.asarray(x, dtype=float)
    med = float(np.median(x))
    dev = np.abs(x - med)
    mad = float(np.median(dev))
    return med, 1.4826 * mad if mad > 0 else 1.2533 * float(dev.mean())


def robust_outliers(x, k: float = OUTLIER_K) -> tuple[np.ndarray, np.ndarray]:
    """(outlier flags, robust z = (x - median) / (1.4826 MAD)) of the finite values
    of ``x``; nothing is flagged among fewer than MIN_FOR_OUTLIERS values or
    when the robust scale is 0 (module rule).  Non-finite values are outliers."""
    x = np.asarray(x, dtype=float)
    ok = np.isfinite(x)
    z = np.full(x.shape, np.nan)
    if ok.sum() < MIN_FOR_OUTLIERS:
        return ~ok, z
    med, scale = robust_scale(x[ok])
    if scale > 0:
        z[ok] = (x[ok] - med) / scale
    flags = ~ok | (np.abs(np.nan_to_num(z, nan=0.0)) > k)
    return flags, z


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
