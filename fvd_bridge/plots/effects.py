"""Figure of the contact gap: law 9's loop with and without a pin clearance,
and the dead band of zero force after each force reversal
(``fvd-bridge effects --gap-figure FILE.png``)."""

from __future__ import annotations

import numpy as np

from ..catalog import parse_model
from ..golden import REFERENCE
from ..records import Record
from .save import axes, finish


def gap_loops(g: float = 2.0, amp: float = 40.0, freq: float = 0.5, dt: float = 0.002, cycles: float = 2.0):
    """(t [s], d [mm], F without gap, F with a contact gap g [mm]) [kN] of law 9
    (the golden reference parameters) under d = amp sin(2 pi freq t)."""
    t = np.arange(int(round(cycles / freq / dt)) + 1) * dt
    w = 2 * np.pi * freq
    d, v, a = amp * np.sin(w * t), amp * w * np.cos(w * t), -amp * w * w * np.sin(w * t)
    rec = Record(t, d, np.sign(v), v, a, name="sine")
    p = np.array(REFERENCE[9])
    F_law = parse_model("9").force(rec, p[None, :])[0]
    F_gap = parse_model("9+gap").force(rec, np.r_[p, g][None, :])[0]
    return t, d, F_law, F_gap


def gap_figure(path: str | None = None, g: float = 2.0, amp: float = 40.0, freq: float = 0.5, ax=None):
    """F-d loops of law 9 with and without a contact gap of clearance g [mm]
    (last cycle), the dead band (|F| < 1e-6 of the peak) marked, and a zoom
    on the reversal at +amp: after the force reverses, no force passes until
    the pin has crossed the clearance."""
    t, d, F_law, F_gap = gap_loops(g, amp, freq)
    last = t >= t[-1] - 1.0 / freq
    band = last & (np.abs(F_gap) < 1e-6 * np.abs(F_gap).max())
    fig, ax = axes(ax, 1, 2, figsize=(13, 4.8), layout="constrained")
    for a in ax:
        a.plot(d[last], F_law[last], lw=1.0, color="0.45", label="law 9")
        a.plot(d[last], F_gap[last], lw=1.4, color="tab:red", label=f"law 9 + gap, g = {g:g} mm")
        a.plot(d[band], F_gap[band], ".", ms=4, color="k", label="dead band: no force in the clearance")
        a.axhline(0.0, lw=0.5, color="k")
        a.set_xlabel("pin displacement d [mm]")
        a.set_ylabel("force F [kN]")
        a.grid(alpha=0.3)
    zoom = last & (d > amp - 6.0 * g)
    ax[1].set_xlim(amp - 6.0 * g, amp + 0.5)
    span = np.abs(F_gap[zoom]).max() if zoom.any() else 1.0
    ax[1].set_ylim(-1.1 * span, 1.1 * span)
    ax[1].set_title(f"reversal at d = +{amp:g} mm: the force reverses, then the pin crosses g")
    ax[0].set_title("force-displacement loop (last cycle)")
    ax[0].legend(fontsize=8, loc="upper left")
    fig.suptitle(f"contact gap: F = Ks dz(d - x, g/2), no force while the pin crosses its clearance "
                 f"({amp:g} mm at {freq:g} Hz)")
    return finish(fig, path, ax)
