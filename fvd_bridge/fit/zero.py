"""The tests' force zero: a nuisance of the measurement, profiled out of eq. 18, never exported.

A load cell is zeroed before a test day, its zero moves from day to day and
drifts slowly during a test (temperature, the amplifier).  What it reads is

    F_measured = F_device + F0 + F1 (t - t_mid),    t_mid = (t_start + t_end) / 2

with a force offset F0 [kN] and a drift F1 [kN/s], one pair per test
(``zero_force``).  Both belong to the test, not to the device: they never
enter a Model, so no spec or exporter carries them; a calibration file
keeps them in a block of their own.

The zero is profiled, not searched: for the model's parameters of the
moment, each test's zero is eq. 18's own best line through its residual
F_measured - F_model over the samples that pin it (``ZeroPin``: the
weighted L1 line, by IRLS_STEPS steps of iteratively reweighted least
squares from the least-squares line, Schlossmacher 1973), and eq. 18 sums
what is left, F_model + zero - F_measured.  An L1 line, not a least-squares
one: on a friction damper's skewed residual the least-squares offset raised
eq. 18 (0.151 -> 0.1535 on the shared 1 Hz test, where a zero of 0 gives
0.151), so a fit "beside the zero" could end worse than without it.
Every optimizer, the bootstrap's Newton refits and a campaign's runs fit
the same objective with it (``Layout.zero``, ``fit.api.joint_residuals``).

The rests are the evidence of the zero: there the actuator holds still
(``records.velocity.rest_mask``: v = a = 0 as read), the model's force is
its force at rest, and what the load cell reads beyond it is the zero
itself, with no misfit of the law's to take it up.  So:

    rests at both ends, at least BOTH_ENDS of the test's duration apart:
        F0 and F1 from the rests alone (a line through them);
    rests at one end (or close together): F0 from the rests, F1 = 0
        (one end cannot tell a drift);
    no rests: F0 and F1 from the whole motion.

The rests stay in eq. 18 (every sample counts); they only pin the zero.
A drift is fitted only on a test of at least DRIFT_S: within a few
seconds the zero is an offset, and a line through a short test's residual
follows the derived velocity's ends instead.  The first and last half
window of the record's differentiator (``edges``) never pin the zero: a
velocity derived at a record's ends is poor, and one sample there can miss
by 60 kN where the law is steep (the mean of a 500-sample test then moves
0.3 kN).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..records.velocity import rest_mask

#: what ``force_zero`` takes: 'none', or each test's zero fitted beside the model
FORCE_ZERO = ("none", "per-test")
#: a test this long [s] or longer has its drift F1 fitted; a shorter one F1 = 0
DRIFT_S = 5.0
#: rests pin the drift too when they lie this share of the test's duration apart (start and end)
BOTH_ENDS = 0.5
#: reweighted least-squares steps of the L1 line (from the least-squares one)
IRLS_STEPS = 6
#: a residual below this share of the pinning samples' mean |residual| weighs as this (IRLS's guard)
IRLS_FLOOR = 1e-3
#: how a test's zero is pinned, per ``ZeroPin.how``
PINNED = {"both": "its rests at both ends", "one": "its rests (at one end: no drift)", "motion": "its motion",
          "short": f"no drift: shorter than {DRIFT_S:g} s"}


def zero_force(F0, F1, t) -> np.ndarray:
    """The load cell's zero F0 + F1 (t - t_mid) [kN] on the test's clock t [s]
    (t_mid its middle); F0 [kN], F1 [kN/s] scalars or (pop, 1) columns."""
    t = np.asarray(t, dtype=float)
    return F0 + F1 * (t - 0.5 * (t[0] + t[-1]))


@dataclass(frozen=True)
class ZeroPin:
    """One test's zero, a line through its residual (module docstring):
    ``basis`` (n, k) the columns [1, t - t_mid] it has (k = 1: no drift),
    ``fit`` (k, n) the weighted least squares over the samples that pin it
    (zeros elsewhere: the L1 line's start), ``weight`` (n,) eq. 18's
    weights of the samples that pin it (0 elsewhere), ``how`` a key of
    PINNED, ``drift`` whether F1 is fitted."""

    basis: np.ndarray
    fit: np.ndarray
    how: str
    drift: bool = True
    weight: np.ndarray | None = None

    @classmethod
    def of(cls, test, c: np.ndarray) -> "ZeroPin":
        """The pin of ``test`` whose eq. 18 weights are ``c`` (n,) (zero
        outside a mask: those samples neither pin nor count)."""
        counted = (np.asarray(c) > 0) & ~edges(test)
        still = rest_mask(test) & counted
        tm = test.t - 0.5 * (test.t[0] + test.t[-1])
        how, on = ("motion", counted) if not still.any() else (_rests_reach(test, still), still)
        drift = how != "one" and test.t[-1] - test.t[0] >= DRIFT_S
        basis = np.column_stack([np.ones(test.n), tm] if drift else [np.ones(test.n)])
        w = np.where(on, np.abs(c), 0.0)
        normal = (basis * w[:, None]).T @ basis
        return cls(basis, np.linalg.pinv(normal) @ (basis * w[:, None]).T, how, drift, w)

    def line(self, x: np.ndarray) -> np.ndarray:
        """(pop, k): the weighted L1 line's coefficients through the rows of x
        (pop, n) over the pinning samples (module docstring; an odd map:
        line(-x) = -line(x))."""
        x = np.atleast_2d(x)
        z = x @ self.fit.T  # the least-squares line: the start
        on = self.weight > 0
        B, w, xs = self.basis[on], self.weight[on], x[:, on]
        guard = IRLS_FLOOR * np.abs(xs - z @ B.T).mean(axis=1, keepdims=True) + 1e-12
        k = B.shape[1]
        BB = (B[:, :, None] * B[:, None, :]).reshape(len(B), k * k)  # (m, k k): each sample's b b^T
        for _ in range(IRLS_STEPS):
            u = w / np.maximum(np.abs(xs - z @ B.T), guard)  # (pop, m): 1/|residual|, eq. 18's weights
            normal = (u @ BB).reshape(-1, k, k)
            z = np.linalg.solve(normal, ((u * xs) @ B)[..., None])[..., 0]
        return z

    def zero(self, r: np.ndarray) -> np.ndarray:
        """(pop, 2) (F0 [kN], F1 [kN/s]) of residuals r (pop, n) = F_measured - F_model."""
        z = self.line(r)
        return z if z.shape[1] == 2 else np.column_stack([z[:, 0], np.zeros(len(z))])

    def remove(self, e: np.ndarray) -> np.ndarray:
        """F_model + zero - F_measured of e (pop, n) = F_model - F_measured: what eq. 18 sums."""
        return e - self.line(e) @ self.basis.T


def edges(test) -> np.ndarray:
    """Boolean (n,): the first and last half window of the velocity's
    Savitzky-Golay differentiator (none for a measured velocity)."""
    vel = (test.provenance or {}).get("velocity") or {}
    half = int(vel.get("window_median") or vel.get("window") or 0) // 2 if vel.get("method") == "savgol" else 0
    out = np.zeros(test.n, dtype=bool)
    if 0 < half < test.n // 4:
        out[:half], out[-half:] = True, True
    return out


def _rests_reach(test, still: np.ndarray) -> str:
    """'both' when ``test``'s rests lie at both ends, BOTH_ENDS of its duration apart, else 'one'."""
    mid = 0.5 * (test.t[0] + test.t[-1])
    groups = [g for g in (still & (test.t < mid), still & (test.t >= mid)) if g.any()]
    if len(groups) < 2:
        return "one"
    ta, tb = (float(np.median(test.t[g])) for g in groups)
    return "both" if tb - ta >= BOTH_ENDS * (test.t[-1] - test.t[0]) else "one"


def pins(device, weights: list) -> list:
    """Per test, its ZeroPin (None for a test of weight 0); ``weights``:
    ``fit.api.residual_weights``."""
    return [None if c is None else ZeroPin.of(test, c) for test, c in zip(device.tests, weights)]


def values(model, device, layout, params, weights: list) -> dict:
    """{test: (F0 [kN], F1 [kN/s])}: each test's zero at one parameter row
    (the fit's columns)."""
    P = np.asarray(params, dtype=float)[None, :]
    out = {}
    for k, (test, pin) in enumerate(zip(device.tests, pins(device, weights))):
        if pin is not None:
            z = pin.zero(test.F[None, :] - model.force(test, layout.for_test(P, k)))[0]
            out[test.name] = (float(z[0]), float(z[1]))
    return out


def how_pinned(device, weights: list) -> dict:
    """{test: how its zero is pinned (PINNED's words)}."""
    return {t.name: PINNED[p.how] + ("" if p.drift or p.how == "one" else f" ({PINNED['short']})")
            for t, p in zip(device.tests, pins(device, weights)) if p is not None}
