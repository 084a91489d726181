"""Velocity and acceleration from sampled displacement: Savitzky-Golay
differentiators with a window chosen per sample by the ICI rule.

Savitzky-Golay (scipy.signal.savgol_filter, mode='interp'): a polynomial of
order p fitted by least squares to ``w`` samples around each point; its k-th
derivative there is a linear filter h_w of the samples, so white
displacement noise of std sigma_d [mm] gives the derivative a noise std

    sigma_w = sigma_d ||h_w|| / dt^k        (k = 1: mm/s, k = 2: mm/s^2)

(exact; the first and last w//2 samples use the end windows' polynomials,
whose ||h|| grows towards the ends: ``noise_gain``).

Adaptive window (the default), the intersection-of-confidence-intervals rule
(ICI; Goldenshluger & Nemirovski 1997, Katkovnik 1999, after Lepski): the
derivative x_w is computed for every window of the ladder ``LADDER``
(5, 7, 9, 13, ... samples, up to the record's length); at each sample the
chosen window is the largest w whose interval [x_w - Gamma sigma_w,
x_w + Gamma sigma_w] still intersects the intervals of all smaller windows.
A short window has little bias and much noise, a long one the opposite; the
intervals stop intersecting where the bias of the longer window exceeds its
noise (times Gamma), so slow cycles and rests get long windows and fast
cycles and reversals short ones. The chosen ladder index is then smoothed
along the record (``smooth_index``: a running median, then a running
minimum, over ``SMOOTH_SPAN`` samples) so that it does not flicker between
neighbouring samples, and taken ``BACK_OFF`` ladder step shorter: the ICI
window is the one whose bias has just reached Gamma times its noise, one
step shorter has a fraction of that bias for a little more noise (measured
on the paper and acceptance protocols at 0.005 and 0.02 mm of noise, the RMS
velocity error is 1.6 to 2 times lower than without the step; Gamma 2.5 to
3 are best, 3 is kept for fewer false alarms on non-Gaussian lab noise).
sigma_d is estimated from the record itself
(cycles.displacement_noise). The acceleration is chosen the same way with
its own sigma_w (k = 2).

Rests (``rests``): where the actuator holds still (before the motion
starts, after it ends, between levels), the derived velocity is the
differentiator's noise, and a law with alpha < 1 turns a velocity of
0.01 mm/s into a tenth of its force at 1 mm/s: on lab-like law-2 records
with 0.5 s rests, C came out 1.6% low (2 s rests: 11%), several standard
errors.  A run of at least ``REST_S`` in which the velocity stays within
GAMMA of its own noise (|v| < GAMMA v_noise) is a rest: v and a are 0
there, as the motion is.  The run ends where the velocity leaves its noise,
so the departure from rest keeps its derived velocity.

A user's window (``--sg-window``) is used for the whole record instead. The
settings, the window range used, Gamma, sigma_d [mm] and the median velocity
noise [mm/s] go into the record's provenance.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from math import factorial

import numpy as np

from ..errors import InputError, option
from .cycles import displacement_noise

#: odd windows [samples] the adaptive rule chooses from (about x sqrt(2) apart)
LADDER = (5, 7, 9, 13, 17, 25, 33, 49, 65, 97, 129, 193, 257, 385, 513, 769, 1025)
#: half-width of the confidence intervals, in noise standard deviations
GAMMA = 3.0
#: ladder steps taken back from the ICI window (whose bias is at the edge of its noise)
BACK_OFF = 1
#: samples over which the chosen window index is smoothed (median, then minimum)
SMOOTH_SPAN = 9
#: the shortest rest [s]: a run this long with the velocity inside its noise
#: (0.1 s missed the rig's 0.1 s rests in 4 of 10 lab-like records, whose
#: velocity noise then made up 40-60% of the true model's OF)
REST_S = 0.05


@dataclass
class Derivatives:
    """v [mm/s] and a [mm/s^2] of a displacement record with their per-sample
    noise std v_noise [mm/s] and a_noise [mm/s^2] (from sigma_d alone, bias
    not included), the windows [samples] used at each sample (v_window,
    a_window), the displacement noise d_noise [mm] they assume and the
    settings for the provenance."""

    v: np.ndarray
    a: np.ndarray
    v_noise: np.ndarray
    a_noise: np.ndarray
    d_noise: float
    settings: dict
    v_window: np.ndarray
    a_window: np.ndarray


def check_settings(window: int | None, polyorder: int, n: int | None = None, where: str = "") -> None:
    """Refuse a window [samples] / order pair the filter cannot use on n samples
    (window None: the order alone; n None: not checked against a record)."""
    if polyorder < 1:
        raise InputError(f"{option('--sg-order', polyorder)}: must be at least 1")
    if window is None:
        return
    if window % 2 == 0:
        raise InputError(f"{option('--sg-window', window)}: must be odd")
    if window <= polyorder:
        raise InputError(f"{option('--sg-window', window)}: must be larger than {option('--sg-order', polyorder)}")
    if n is not None and window > n:
        raise InputError(f"{where}{option('--sg-window', window)}: larger than the record's {n} samples")


def noise_gain(window: int, polyorder: int, deriv: int, dt: float) -> tuple[float, np.ndarray]:
    """||h|| / dt^deriv of the Savitzky-Golay derivative filter [1/s^deriv]:
    (at the centre of a window, at the first window//2 samples of a record).

    The filter evaluates the least-squares polynomial of the window at an
    offset x0 from its centre; with u = x/h (h = window//2) and the
    monomials' Gram matrix G = V^T V, the noise gain is sqrt(b^T G^-1 b),
    b_j = j!/(j-k)! u0^(j-k) / h^k. The centre (u0 = 0) equals
    ||scipy.signal.savgol_coeffs(window, polyorder, deriv)||; the last
    window//2 samples mirror the first.
    """
    h = window // 2
    p = min(polyorder, window - 1)
    if deriv > p:
        return 0.0, np.zeros(h)
    u = np.arange(-h, h + 1) / h
    ginv = np.linalg.inv(np.vander(u, p + 1, increasing=True).T @ np.vander(u, p + 1, increasing=True))
    j = np.arange(deriv, p + 1)
    falling = np.array([factorial(i) / factorial(i - deriv) for i in j]) / float(h) ** deriv
    u0 = np.concatenate([[0.0], (np.arange(h) - h) / h])
    B = np.zeros((u0.size, p + 1))
    B[:, deriv:] = falling * u0[:, None] ** (j - deriv)
    gain = np.sqrt(np.einsum("ij,jk,ik->i", B, ginv, B)) / dt**deriv
    return float(gain[0]), gain[1:]


def _gain_along(window: int, polyorder: int, deriv: int, dt: float, n: int) -> np.ndarray:
    """noise_gain at every sample of an n-sample record [1/s^deriv]."""
    centre, edge = noise_gain(window, polyorder, deriv, dt)
    g = np.full(n, centre)
    h = window // 2
    g[:h], g[n - h:] = edge, edge[::-1]
    return g


def _savgol(x: np.ndarray, window: int, polyorder: int, deriv: int, dt: float) -> np.ndarray:
    from scipy.signal import savgol_filter  # lazily: +0.5 s on `fvd-bridge --help`

    if deriv > polyorder:
        return np.zeros_like(x, dtype=float)
    return savgol_filter(x, window, polyorder, deriv=deriv, delta=dt, mode="interp")  # along the last axis


def ladder(n: int, polyorder: int) -> list[int]:
    """The windows of LADDER that fit an n-sample record and exceed polyorder + 1."""
    return [w for w in LADDER if polyorder + 1 < w <= n] or [_odd_at_most(n)]


def _odd_at_most(n: int) -> int:
    return n if n % 2 else n - 1


def smooth_index(idx: np.ndarray, span: int = SMOOTH_SPAN) -> np.ndarray:
    """Running median, then running minimum, over ``span`` samples of the
    chosen ladder index (an isolated jump is dropped; a drop spreads over
    the span, so no sample takes a longer window than its neighbours allow)."""
    from scipy.ndimage import median_filter, minimum_filter1d  # lazily: +60 ms on `fvd-bridge --help`

    if span <= 1 or idx.size < span:
        return idx
    return minimum_filter1d(median_filter(idx, size=span, mode="nearest"), span, mode="nearest")


def ici_choice(estimates: np.ndarray, sigmas: np.ndarray, gamma: float = GAMMA) -> np.ndarray:
    """Index (into the windows, shortest first) of the largest window whose
    confidence interval intersects those of all shorter windows, per sample.

    ``estimates`` and ``sigmas`` have shape (windows, samples)."""
    lo = np.maximum.accumulate(estimates - gamma * sigmas, axis=0)
    hi = np.minimum.accumulate(estimates + gamma * sigmas, axis=0)
    return np.sum(lo <= hi, axis=0).astype(int) - 1  # the running intersection only shrinks


def adaptive_derivative(x: np.ndarray, dt: float, sigma: float, deriv: int, polyorder: int = 3,
                        gamma: float = GAMMA, span: int = SMOOTH_SPAN,
                        back_off: int = BACK_OFF) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict]:
    """The deriv-th derivative of x (white noise std ``sigma``) with the
    window chosen per sample by ICI; returns it, its per-sample noise std,
    the window used at each sample [samples] and the settings (windows tried
    and used, median window, polynomial order)."""
    p = max(polyorder, deriv)
    wins = ladder(x.size, p)
    est, sig = [], []
    lo, hi = np.full(x.size, -np.inf), np.full(x.size, np.inf)
    for w in wins:  # shortest first; stop once no sample's intersection is left (ici_choice, streamed)
        est.append(_savgol(x, w, p, deriv, dt))
        sig.append(sigma * _gain_along(w, p, deriv, dt, x.size))
        lo, hi = np.maximum(lo, est[-1] - gamma * sig[-1]), np.minimum(hi, est[-1] + gamma * sig[-1])
        if not np.any(lo <= hi):
            break
    est, sig = np.array(est), np.array(sig)
    idx = np.maximum(smooth_index(ici_choice(est, sig, gamma), span) - back_off, 0)
    cols = np.arange(x.size)
    out, noise = est[idx, cols], sig[idx, cols]
    used = np.asarray(wins)[idx]
    return out, noise, used, {"windows_tried": [int(wins[0]), int(wins[len(est) - 1])],
                        "windows_used": [int(used.min()), int(used.max())],
                        "window_median": int(np.median(used)), "polyorder": int(p)}


def fixed_derivative(x: np.ndarray, dt: float, sigma: float, deriv: int, window: int,
                     polyorder: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """The deriv-th derivative of x with one window [samples] and its per-sample noise std."""
    p = min(max(polyorder, deriv), window - 1)
    return _savgol(x, window, p, deriv, dt), sigma * _gain_along(window, p, deriv, dt, x.size)


def derive(d: np.ndarray, dt: float, window: int | None = None, polyorder: int = 3, where: str = "",
           d_noise: float | None = None, gamma: float = GAMMA, t0: float = 0.0) -> Derivatives:
    """v [mm/s], a [mm/s^2] and their noise from displacement d [mm] on step dt [s].

    ``window`` None: adaptive (ICI, module docstring); an odd number of
    samples: that window everywhere. ``d_noise`` [mm]: the displacement
    noise std (None: estimated from d, cycles.displacement_noise).
    ``where`` prefixes messages (e.g. the file name).  The rests go into
    the settings as ``rests_s``: [start, end) [s] on the record's clock,
    whose first sample is at ``t0`` (so a slice of the record keeps them).
    """
    check_settings(window, polyorder, d.size, where)
    if polyorder + 2 > d.size:
        raise InputError(f"{where}{option('--sg-order', polyorder)}: needs at least {polyorder + 2} samples, "
                         f"the record has {d.size}")
    sigma = float(displacement_noise(d)) if d_noise is None else float(d_noise)
    base = {"method": "savgol", "polyorder": int(polyorder), "d_noise_mm": sigma}
    if window is None:
        v, v_noise, v_window, sv = adaptive_derivative(d, dt, sigma, 1, polyorder, gamma)
        a, a_noise, a_window, sa = adaptive_derivative(d, dt, sigma, 2, max(polyorder, 2), gamma)
        settings = dict(base, window_chosen="adaptive", rule="ICI", gamma=float(gamma),
                        windows_tried=sv["windows_tried"], windows_used=sv["windows_used"],
                        window_median=sv["window_median"],
                        window_median_s=float(sv["window_median"] * dt),
                        acceleration={"windows_used": sa["windows_used"], "window_median": sa["window_median"],
                                      "polyorder": sa["polyorder"],
                                      "noise_mm_s2": float(np.median(a_noise))})
    else:
        v, v_noise = fixed_derivative(d, dt, sigma, 1, window, polyorder)
        a, a_noise = fixed_derivative(d, dt, sigma, 2, window, max(polyorder, 2))
        v_window = a_window = np.full(d.size, int(window))
        settings = dict(base, window_chosen="user", window=int(window), window_s=float(window * dt),
                        acceleration={"window": int(window), "polyorder": int(max(polyorder, 2)),
                                      "noise_mm_s2": float(np.median(a_noise))})
    settings["v_noise_mm_s"] = float(np.median(v_noise))
    at_rest = rests(v, v_noise, dt, gamma)
    if at_rest.any():
        v, a = np.where(at_rest, 0.0, v), np.where(at_rest, 0.0, a)
        settings["rests_s"] = [[float(t0 + i * dt), float(t0 + j * dt)] for i, j in runs(at_rest)]
    return Derivatives(v, a, v_noise, a_noise, sigma, settings, v_window, a_window)


def derive_with_windows(D: np.ndarray, dt: float, windows: tuple, polyorder: int, v_noise: np.ndarray,
                        gamma: float = GAMMA, acceleration: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
    """V [mm/s] and A [mm/s^2] of displacements D [mm] (rows: records of one
    grid) with the windows [samples] a record's derivation chose at each
    sample, ``windows`` = (v_window, a_window), and its rests found in each
    row (v_noise [mm/s]: that derivation's per-sample noise).  The bootstrap's
    differentiator (``fit.intervals``): the same linear filters, one batch.
    A is None without ``acceleration`` (a model that does not read it)."""
    V = with_windows(D, dt, windows[0], polyorder, 1)
    A = with_windows(D, dt, windows[1], max(polyorder, 2), 2) if acceleration else None
    for row in range(V.shape[0]):
        still = rests(V[row], v_noise, dt, gamma)
        V[row, still] = 0.0
        if A is not None:
            A[row, still] = 0.0
    return V, A


def with_windows(X: np.ndarray, dt: float, window: np.ndarray, polyorder: int, deriv: int) -> np.ndarray:
    """The deriv-th Savitzky-Golay derivative of the rows of X, each sample
    with its own window [samples] (``window``, (n,)): at each sample the
    polynomial of its window (the record's end window near an end, as
    savgol_filter's mode 'interp'), from scipy's ``savgol_coeffs`` at that
    sample's position; only the samples a window serves are computed (a
    rest's long window costs its samples, not the record's)."""
    from numpy.lib.stride_tricks import sliding_window_view

    X = np.atleast_2d(np.asarray(X, dtype=float))
    n = X.shape[1]
    out = np.zeros_like(X)
    for w in np.unique(window).astype(int):
        p = min(polyorder, w - 1)
        if deriv > p:
            continue
        at = np.flatnonzero(window == w)
        starts = np.clip(at - w // 2, 0, n - w)
        pos = at - starts
        views = sliding_window_view(X, w, axis=-1)  # (rows, n - w + 1, w), no copy
        chunk = max(1, CHUNK // (X.shape[0] * w))
        for where in np.unique(pos):  # the centre, then each position of an end window
            cols = np.flatnonzero(pos == where)
            h = _coeffs(w, p, deriv, dt, int(where))
            for k in range(0, cols.size, chunk):
                part = cols[k:k + chunk]
                out[:, at[part]] = views[:, starts[part]] @ h
    return out


#: samples x window x rows gathered at once by ``with_windows``
CHUNK = 2_000_000


@lru_cache(maxsize=512)
def _coeffs(window: int, polyorder: int, deriv: int, dt: float, pos: int) -> np.ndarray:
    from scipy.signal import savgol_coeffs

    return savgol_coeffs(window, polyorder, deriv=deriv, delta=dt, pos=pos, use="dot")


def rest_mask(record) -> np.ndarray:
    """Boolean (n,): the samples of the record's rests (its provenance's
    ``velocity.rests_s``; none for a record without)."""
    still = np.zeros(record.n, dtype=bool)
    for start, end in ((record.provenance or {}).get("velocity") or {}).get("rests_s") or ():
        still |= (record.t > start - 0.5 * record.dt) & (record.t < end - 0.5 * record.dt)  # on the grid
    return still


def runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(first, last + 1) sample of each run of True in a boolean array."""
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(edges == 1).tolist(), np.flatnonzero(edges == -1).tolist()))


def rests(v: np.ndarray, v_noise: np.ndarray, dt: float, gamma: float = GAMMA) -> np.ndarray:
    """Boolean (n,): the samples of runs of at least REST_S [s] in which
    the derived velocity v [mm/s] stays within gamma of its noise v_noise
    [mm/s] (module docstring)."""
    still = np.abs(v) < gamma * v_noise
    out = np.zeros(v.size, dtype=bool)
    shortest = max(int(round(REST_S / dt)), 2)
    for i, j in runs(still):
        if j - i >= shortest:
            out[i:j] = True
    return out


def differentiate(d: np.ndarray, dt: float, window: int | None = None, polyorder: int = 3,
                  where: str = "", d_noise: float | None = None) -> tuple[np.ndarray, np.ndarray, dict]:
    """v [mm/s], a [mm/s^2] and the settings of ``derive`` (same arguments)."""
    out = derive(d, dt, window, polyorder, where, d_noise)
    return out.v, out.a, out.settings


def acceleration_from_velocity(v: np.ndarray, dt: float, window: int | None = None, polyorder: int = 3,
                               where: str = "", v_noise: float | None = None) -> tuple[np.ndarray, np.ndarray, dict]:
    """Acceleration [mm/s^2] from a measured velocity [mm/s] (Savitzky-Golay
    first derivative; adaptive like ``derive`` unless ``window`` is given).

    ``v_noise`` [mm/s]: the velocity's noise std (None: estimated from v).
    Returns the acceleration, its per-sample noise std and the settings.
    """
    check_settings(window, polyorder, v.size, where)
    if polyorder + 2 > v.size:
        raise InputError(f"{where}{option('--sg-order', polyorder)}: needs at least {polyorder + 2} samples, "
                         f"the record has {v.size}")
    sigma = float(displacement_noise(v)) if v_noise is None else float(v_noise)
    if window is None:
        a, a_noise, _, s = adaptive_derivative(v, dt, sigma, 1, polyorder)
        settings = {"method": "savgol", "window_chosen": "adaptive", "rule": "ICI", "gamma": GAMMA,
                    "windows_used": s["windows_used"], "window_median": s["window_median"],
                    "polyorder": int(polyorder)}
    else:
        a, a_noise = fixed_derivative(v, dt, sigma, 1, window, polyorder)
        settings = {"method": "savgol", "window_chosen": "user", "window": int(window),
                    "window_s": float(window * dt), "polyorder": int(polyorder)}
    settings["noise_mm_s2"] = float(np.median(a_noise))
    return a, a_noise, settings


def rederive(record, d: np.ndarray):
    """(v, a) the record's differentiator gives for displacement d [mm] (its
    provenance: a user's window stays fixed, an automatic one is chosen
    again); None when the record's velocity was not derived from d."""
    vel = record.provenance.get("velocity", {})
    method = str(vel.get("method", ""))
    if not method or method == "measured" or method.startswith("exact"):
        return None
    window = vel.get("window") if vel.get("window_chosen") == "user" else None
    v, a, _ = differentiate(d, record.dt, window=window, polyorder=vel.get("polyorder", 3),
                            d_noise=getattr(record, "d_noise", None))
    return v, a
