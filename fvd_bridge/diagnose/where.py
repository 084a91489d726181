"""Where a fitted model fails: the residual r = F_measured - F_model, cut by
the quantities that fingerprint the physical effects (README, "Physical effects"):

- near the reversals vs at peak velocity (series stiffness, gap, inertia),
- early vs late cycles of each velocity level (heating),
- tension vs compression (asymmetry),
- velocity levels, when the record has several (friction, inertia),
- per cycle, and the residual's correlation with d, v, sign(v), a
  (SysIdentPy-style, against the 1.96 / sqrt(N_eff) band).

Everything here is numbers (``Where``, frozen); the text and the figures
are built from them.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ..records.cycles import reversals

#: |v| below this fraction of the half-cycle's peak velocity is "near a reversal"
NEAR_REVERSAL = 0.2
#: |v| above this fraction of the half-cycle's peak velocity is "at peak velocity"
AT_PEAK = 0.8
#: half-cycles whose peak velocities differ by more than this factor are different levels
LEVEL_RATIO = 1.3
#: fewest half-cycles that make a velocity level (fewer: a transition, not a level)
LEVEL_MIN_HALVES = 3


@dataclass(frozen=True)
class Share:
    """The residual's share of the error (|r| integrated) and the share of
    the record's time in one part of it."""

    error_share: float
    time_share: float


@dataclass(frozen=True)
class Side:
    """mean |r| [kN] in one part of the record, and the mean of r sign(F_model)
    [kN] (> 0: the model is too weak there)."""

    mean_abs: float
    signed: float


@dataclass(frozen=True)
class Level:
    """One velocity level: its half-cycles' median peak velocity [mm/s], mean
    |r| [kN], that over the mean |F| [-], mean r sign(F_model) [kN] and its
    number of half-cycles."""

    peak_v: float
    mean_abs: float
    relative: float
    signed: float
    n_half: int


@dataclass(frozen=True)
class Cycle:
    """One full cycle: start and end [s], mean |r| [kN], peak velocity [mm/s]."""

    t_start: float
    t_end: float
    mean_abs: float
    peak_v: float


@dataclass(frozen=True)
class Correlation:
    """The residual's correlation with d, v, sign(v) (smoothed) and a [-]."""

    d: float
    v: float
    sign_v: float
    a: float


@dataclass(frozen=True)
class Where:
    """Where a model fails (module docstring): n samples and half-cycles, the
    mean |r| and mean r [kN], near the reversals and at peak velocity, early
    and late cycles, tension and compression, the velocity levels, the
    cycles, the correlations with their 1.96/sqrt(N_eff) band."""

    n: int
    half_cycles: int
    residual_mean_abs: float
    residual_signed_mean: float
    reversal: Share
    peak: Share
    levels: tuple
    early: Side
    late: Side
    tension: Side
    compression: Side
    cycles: tuple
    correlation: Correlation
    n_eff: float
    band: float

    def as_dict(self) -> dict:
        """The numbers as a JSON-ready mapping (diagnose --json)."""
        return asdict(self)


def half_cycles(d: np.ndarray) -> np.ndarray:
    """Sample index where each half-cycle starts (0, then every reversal of d)."""
    r = reversals(d)
    return np.concatenate([[0], r[r > 0]]).astype(int)


def effective_samples(r: np.ndarray) -> float:
    """N (1 - rho) / (1 + rho) with rho the lag-1 autocorrelation of r: the
    number of independent samples an AR(1) residual is worth (at least 2)."""
    r = np.asarray(r, dtype=float) - np.mean(r)
    den = float(np.dot(r, r))
    if r.size < 3 or den == 0.0:
        return float(max(r.size, 2))
    rho = float(np.clip(np.dot(r[:-1], r[1:]) / den, -0.99, 0.999))
    return float(max(r.size * (1.0 - rho) / (1.0 + rho), 2.0))


def _levels(peaks: np.ndarray) -> np.ndarray:
    """Level index of each half-cycle by its peak velocity (ratio > LEVEL_RATIO apart)."""
    order = np.argsort(peaks)
    level = np.zeros(peaks.size, dtype=int)
    k = 0
    for a, b in zip(order[:-1], order[1:]):
        if peaks[a] > 0 and peaks[b] / peaks[a] > LEVEL_RATIO:
            k += 1
        level[b] = k
    return level


def _share(err, mask, dt_w):
    tot = float(np.sum(err * dt_w))
    return (float(np.sum(err[mask] * dt_w[mask])) / tot if tot > 0 else 0.0,
            float(np.sum(dt_w[mask]) / np.sum(dt_w)))


def analyse(record, F_model: np.ndarray) -> Where:
    """Numbers that say where the model fails (forces in kN, velocities in mm/s; ``Where``)."""
    F, d, v, a, t = record.F, record.d, record.v, record.a, record.t
    r = F - np.asarray(F_model)
    err = np.abs(r)
    n = r.size
    w = np.gradient(t)  # time weights (uniform grid)
    starts = half_cycles(d)
    bounds = np.append(starts, n)
    half = np.repeat(np.arange(starts.size), np.diff(bounds))
    peaks = np.array([np.max(np.abs(v[s:e])) for s, e in zip(bounds[:-1], bounds[1:])])
    peak_at = peaks[half]
    absv = np.abs(v)
    moving = peak_at > 0
    near = moving & (absv <= NEAR_REVERSAL * peak_at)
    top = moving & (absv >= AT_PEAK * peak_at)
    near_share, top_share = Share(*_share(err, near, w)), Share(*_share(err, top, w))
    # velocity levels of the half-cycles (only those with real motion)
    real = peaks > 1e-3 * peaks.max() if peaks.size else peaks.astype(bool)
    level_of_half = np.full(peaks.size, -1)
    if real.any():
        level_of_half[real] = _levels(peaks[real])
    # a level needs LEVEL_MIN_HALVES half-cycles; fewer are transitions (tapers, pauses)
    for k in range(int(level_of_half.max()) + 1 if real.any() else 0):
        if np.count_nonzero(level_of_half == k) < LEVEL_MIN_HALVES:
            level_of_half[level_of_half == k] = -1
    kept = sorted(set(level_of_half[level_of_half >= 0]))
    level_of_half = np.array([kept.index(k) if k >= 0 else -1 for k in level_of_half], dtype=int)
    levels = []
    for k in range(len(kept)):
        halves = np.flatnonzero(level_of_half == k)
        m = np.isin(half, halves)
        mean_abs_F = float(np.mean(np.abs(F[m]))) if m.any() else 0.0
        levels.append(Level(float(np.median(peaks[halves])), float(np.mean(err[m])),
                            float(np.mean(err[m]) / mean_abs_F) if mean_abs_F > 0 else 0.0,
                            float(np.mean(r[m] * np.sign(F_model[m]))), int(halves.size)))
    # early vs late: first and second half of the half-cycles of each level
    early = np.zeros(n, bool)
    late = np.zeros(n, bool)
    for k in range(len(levels)):
        halves = np.flatnonzero(level_of_half == k)
        if halves.size < 2:
            continue
        cut = halves.size // 2
        early |= np.isin(half, halves[:cut])
        late |= np.isin(half, halves[halves.size - cut:])
    sF = np.sign(F_model)

    def side(m) -> Side:
        return Side(float(np.mean(err[m])), float(np.mean(r[m] * sF[m]))) if m.any() else Side(0.0, 0.0)

    # per full cycle (two half-cycles)
    cycles = []
    for c in range(0, starts.size, 2):
        s, e = bounds[c], bounds[min(c + 2, starts.size)]
        if e - s < 3 or level_of_half[c] < 0:
            continue
        cycles.append(Cycle(float(t[s]), float(t[e - 1]), float(np.mean(err[s:e])), float(max(peaks[c:c + 2]))))
    n_eff = effective_samples(r)
    corr = {}
    for key, x in (("d", d), ("v", v), ("sign_v", np.tanh(v / max(1e-9, 0.01 * absv.max()))), ("a", a)):
        xs = x - np.mean(x)
        den = np.sqrt(np.dot(xs, xs) * np.dot(r - r.mean(), r - r.mean()))
        corr[key] = float(np.dot(xs, r - r.mean()) / den) if den > 0 else 0.0
    return Where(int(n), int(starts.size), float(np.mean(err)), float(np.mean(r)), near_share, top_share,
                 tuple(levels), side(early), side(late), side(F > 0), side(F < 0), tuple(cycles),
                 Correlation(**corr), float(n_eff), float(1.96 / np.sqrt(n_eff)))


def summary_lines(w: Where, floor_kN: float | None = None) -> list[str]:
    """The short text summary of ``analyse``'s numbers (one finding per line)."""
    lines = []
    rv, pk = w.reversal, w.peak
    lines.append(f"near reversals (|v| < {NEAR_REVERSAL:.0%} of the half-cycle peak): "
                 f"{rv.error_share:.0%} of the error in {rv.time_share:.0%} of the time")
    lines.append(f"at peak velocity (|v| > {AT_PEAK:.0%}): "
                 f"{pk.error_share:.0%} of the error in {pk.time_share:.0%} of the time")
    e, la = w.early, w.late
    if e.mean_abs or la.mean_abs:
        lines.append(f"early vs late cycles: mean |r| {e.mean_abs:.3g} vs {la.mean_abs:.3g} kN; "
                     f"r.sign(F) {e.signed:+.3g} vs {la.signed:+.3g} kN "
                     f"(> 0: model too weak)")
    te, co = w.tension, w.compression
    lines.append(f"tension vs compression: mean |r| {te.mean_abs:.3g} vs {co.mean_abs:.3g} kN; "
                 f"r.sign(F) {te.signed:+.3g} vs {co.signed:+.3g} kN")
    if len(w.levels) > 1:
        parts = [f"{lv.peak_v:.3g} mm/s: {lv.mean_abs:.3g} kN ({lv.relative:.0%} of |F|)" for lv in w.levels]
        lines.append("velocity levels, mean |r|: " + "; ".join(parts))
    c = asdict(w.correlation)
    strong = [f"{k} {c[k]:+.2f}" for k in ("d", "v", "sign_v", "a") if abs(c[k]) > w.band]
    if strong:
        lines.append(f"residual correlates with {', '.join(strong)} (band +-{w.band:.2f})")
    if floor_kN is not None:
        lines.append(f"mean |r| {w.residual_mean_abs:.3g} kN against {floor_kN:.3g} kN "
                     f"expected from the force noise alone")
    return lines
