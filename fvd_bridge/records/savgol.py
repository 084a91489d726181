"""Savitzky-Golay derivative of a uniformly sampled signal (numpy only).

Savitzky and Golay, Anal. Chem. 36 (1964) 1627: a polynomial of order p is
fitted by least squares to the ``window`` = 2h+1 samples around each point,
x[i+k] ~ sum_m c_m k^m (k = -h..h), and the derivative of order r is read
from it: x^(r)[i] = r! c_r / dt^r. The c_m are rows of the pseudo-inverse of
the Vandermonde matrix V[k, m] = k^m, so the interior is one correlation.
The first and last h points take the derivative of the polynomial fitted to
the first / last window, as scipy.signal.savgol_filter(mode='interp') does.
Kept here so that reading a record does not import scipy.signal (~1 s).
"""

from __future__ import annotations

from math import factorial

import numpy as np


def savgol_derivative(x: np.ndarray, window: int, polyorder: int, deriv: int, dt: float) -> np.ndarray:
    """Derivative of order ``deriv`` of x on step dt [s] (units of x per s^deriv).

    Needs an odd ``window`` <= x.size and polyorder < window; a derivative
    above the polynomial order is zero.
    """
    if deriv > polyorder:
        return np.zeros(x.size)
    h = window // 2
    k = np.arange(-h, h + 1, dtype=float)
    pinv = np.linalg.pinv(np.vander(k, polyorder + 1, increasing=True))  # (p+1, window): x -> c
    out = np.empty(x.size)
    scale = factorial(deriv) / dt**deriv
    out[h:x.size - h] = np.correlate(x, pinv[deriv], mode="valid") * scale
    # edges: derivative of the end windows' polynomials at their outer points
    m = np.arange(deriv, polyorder + 1)
    falling = np.array([factorial(j) / factorial(j - deriv) for j in m])
    for seg, pos in ((x[:window], k[:h]), (x[x.size - window:], k[h + 1:])):
        c = pinv[deriv:] @ seg
        vals = (pos[:, None] ** (m - deriv)[None, :]) @ (falling * c) / dt**deriv
        if pos[0] < 0:
            out[:h] = vals
        else:
            out[x.size - h:] = vals
    return out
