"""Simulate a virtual device under a protocol: the truth of the rig.

Physics (positive force = tension; d the imposed displacement [mm]):

1. Pin gap g: the damper body sees y, the play (backlash) operator of d with
   half-width g/2: y stays put until |d - y| reaches g/2, then follows d
   (y = d - s g/2 in contact on side s = +-1; v_y = v, a_y = a in contact,
   0 otherwise). y(t0) = d(t0), out of contact. The velocity jump at contact
   is not an acceleration impulse in the output (a_y stays finite).
2. Internal element: F_int(v_o) = hf C A sign(v_o)|v_o|^alpha + Ff tanh(v_o/v_f),
   A = 1 + r in tension (F_o > 0) and 1 - r in compression, hf = exp(-theta E),
   E [MJ] = 1e-6 integral F_o v_o dt (F_o the orifice part, with A and hf).
3. Series spring Ks, where the device's ``arrangement`` puts it:
   'connection' (outside the damper): Ks (y - x_o) = F_int(v_o) + Kp x_o + F0,
   the seal and the accumulator behind the spring; 'oil_column' (the
   compressible oil inside the damper): Ks (y - x_o) = F_o(v_o) only, the
   seal Ff tanh(v_y / v_f) and the accumulator Kp y + F0 on the rod beside
   it.  x_o the piston displacement, starting at rest (the spring holding
   the accumulator's force).  Rigid (Ks None): v_o = v_y and
   F_s = F_int(v_y); then E has the closed form
   exp(theta E) = 1 + theta W0, W0 = 1e-6 integral C A |v_y|^(1+alpha) dt.
4. Measured force F = the spring's force (plus, beside an oil column or
   without a spring, the seal and Kp y + F0) + m a_y 1e-6 + force noise;
   measured displacement d + displacement noise (default 0.005 mm).

Accuracy: the motion is the protocol's analytic d, v, a (never samples);
integration nodes split every sample step in ``substeps`` and include every
reversal of d, contact event of the gap and protocol breakpoint. The Maxwell
equation is integrated by an L-stable SDIRK3 (kernel.py); the rigid energy
integral by 3-point Gauss-Legendre per node interval.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..records import Record
from .device import VirtualDamper
from .integrator import STAGE_C, device_constants, integrate_maxwell
from .protocols import Protocol

#: target of h * (largest rate of the Maxwell equation) per integration step
STIFF_TARGET = 0.25
#: bounds of the automatic number of integration steps per sample step
SUBSTEPS_MIN, SUBSTEPS_MAX = 8, 256
#: integration steps per sample step for a rigid device (quadrature, event search)
SUBSTEPS_RIGID = 4
_GL_X = np.array([-math.sqrt(0.6), 0.0, math.sqrt(0.6)])
_GL_W = np.array([5.0, 8.0, 5.0]) / 9.0


#: default displacement noise std [mm]: a good lab displacement transducer
#: (LVDT or the actuator's encoder through its conditioning) on a +-40 mm stroke
DISPLACEMENT_NOISE = 0.005


@dataclass(frozen=True)
class Noise:
    """Measurement noise: white, Gaussian, standard deviations force [kN] and
    displacement [mm] (default DISPLACEMENT_NOISE, as a lab record has;
    Noise(force, 0.0) for an exact displacement)."""

    force: float = 0.0
    displacement: float = DISPLACEMENT_NOISE

    def __post_init__(self):
        for key, unit in (("force", "kN"), ("displacement", "mm")):
            x = getattr(self, key)
            try:
                x = float(x)
            except (TypeError, ValueError):
                raise InputError(f"noise {key} '{x}': not a number") from None
            if not (math.isfinite(x) and x >= 0.0):
                raise InputError(f"noise {key} = {x:g}: must be a standard deviation >= 0 {unit}")
            object.__setattr__(self, key, x)

    def describe(self) -> dict:
        return {"force_kN": self.force, "displacement_mm": self.displacement}


# --------------------------------------------------------------------- events

def _bisect(f, a: np.ndarray, b: np.ndarray, iters: int = 64) -> np.ndarray:
    """Vectorized bisection of f(t) = 0 on brackets [a, b] (f(a) f(b) <= 0)."""
    a, b = a.astype(float).copy(), b.astype(float).copy()
    if a.size == 0:
        return a
    fa = f(a)
    for _ in range(iters):
        m = 0.5 * (a + b)
        if np.all((m <= a) | (m >= b)):
            break
        fm = f(m)
        left = np.sign(fm) * np.sign(fa) <= 0
        b = np.where(left, m, b)
        a = np.where(left, a, m)
        fa = np.where(left, fa, fm)
    return 0.5 * (a + b)


def _reversals(protocol: Protocol, t: np.ndarray, v: np.ndarray):
    """Times [s] where v changes sign (zeros ignored) and the new direction."""
    nz = np.flatnonzero(v != 0.0)
    if nz.size < 2:
        return np.empty(0), np.empty(0)
    s = np.sign(v[nz])
    k = np.flatnonzero(s[1:] != s[:-1])
    a, b = t[nz[k + 1] - 1], t[nz[k + 1]]
    tr = _bisect(lambda x: protocol.motion(x)[1], a, b)
    return tr, s[k + 1]


@dataclass
class Play:
    """Piecewise play state: from starts[i] on, side[i] (0 free, +-1 contact)
    and, when free, the held position ystar[i] [mm]."""

    r: float
    starts: np.ndarray
    side: np.ndarray
    ystar: np.ndarray

    def events(self) -> np.ndarray:
        return self.starts[1:]

    def piece(self, t: np.ndarray) -> np.ndarray:
        return np.clip(np.searchsorted(self.starts, t, side="right") - 1, 0, self.starts.size - 1)

    def apply(self, t, d, v, a, piece=None):
        """y, v_y, a_y, contact at times t with motion d, v, a."""
        i = self.piece(t) if piece is None else piece
        s = self.side[i]
        contact = s != 0
        y = np.where(contact, d - s * self.r, self.ystar[i])
        return y, np.where(contact, v, 0.0), np.where(contact, a, 0.0), contact


def play(protocol: Protocol, gap: float, t: np.ndarray, d: np.ndarray, v: np.ndarray) -> Play:
    """The play operator of the analytic d with half-width gap/2 [mm].

    t, d, v: a fine grid (used to bracket the events, which are then found
    to machine precision on the analytic motion). Contact on side s ends at
    each reversal of d (y holds d(t_rev) - s g/2); free play ends when
    |d - y| reaches g/2 again.
    """
    r = 0.5 * gap
    if r == 0.0:
        return Play(0.0, np.array([t[0]]), np.array([1]), np.array([np.nan]))
    t_rev, direction = _reversals(protocol, t, v)
    d_rev = protocol.motion(t_rev)[0] if t_rev.size else t_rev
    tol = 1e-12 * (r + float(np.max(np.abs(d))))
    starts, side, ystar = [t[0]], [0], [float(d[0])]
    brackets, targets = [], []
    s, ys, i0 = 0, float(d[0]), 0
    bounds = np.concatenate([t_rev, [np.inf]])
    for k in range(bounds.size):
        # stretch from the previous reversal to bounds[k]: d monotone
        i1 = int(np.searchsorted(t, bounds[k], side="left"))  # first grid index at/after the reversal
        if s == 0:
            seg = d[i0:i1]
            hit = np.flatnonzero(np.abs(seg - ys) > r + tol)
            if hit.size:
                j = i0 + int(hit[0])
                sigma = 1 if d[j] > ys else -1
                lo = t[j - 1] if j > 0 else t[0]
                if len(starts) > 0:
                    lo = max(lo, starts[-1])
                brackets.append((lo, t[j]))
                targets.append(ys + sigma * r)
                starts.append(np.nan)  # engagement time, refined below
                side.append(sigma)
                ystar.append(np.nan)
                s = sigma
        if k < t_rev.size and s != 0:
            if direction[k] != s:  # the reversal turns d away from contact
                ys = float(d_rev[k] - s * r)
                starts.append(float(t_rev[k]))
                side.append(0)
                ystar.append(ys)
                s = 0
        i0 = max(i1, 1)
    starts = np.asarray(starts, dtype=float)
    if brackets:
        br = np.asarray(brackets)
        tg = np.asarray(targets)
        tc = _bisect(lambda x, tg=tg: protocol.motion(x)[0] - tg, br[:, 0], br[:, 1])
        starts[np.isnan(starts)] = tc
    return Play(r, starts, np.asarray(side, dtype=int), np.asarray(ystar, dtype=float))


# ----------------------------------------------------------------------- grid

def _grid(protocol: Protocol, n_sub: int, events: np.ndarray):
    """Integration nodes: every sample time, n_sub steps per sample step and
    the events. Returns nodes and the indices of the sample times in them."""
    ts = protocol.times()
    n = ts.size
    base = protocol.t0 + protocol.dt * (np.arange((n - 1) * n_sub + 1) / n_sub)
    ev = np.asarray(events, dtype=float)
    ev = ev[(ev > base[0]) & (ev < base[-1])]
    if ev.size:
        tol = 1e-9 * protocol.dt / n_sub
        k = np.clip(np.searchsorted(base, ev), 1, base.size - 1)
        near = np.minimum(np.abs(base[k] - ev), np.abs(ev - base[k - 1])) <= tol
        base = np.union1d(base, ev[~near])
    idx = np.searchsorted(base, ts)
    return base, idx, ts


def _auto_substeps(device: VirtualDamper, vpeak: float, dt: float) -> int:
    """Steps per sample step so that h Ks dv_o/dS stays near STIFF_TARGET."""
    if device.rigid:
        return SUBSTEPS_RIGID
    a = device.alpha
    v = max(vpeak if a <= 1.0 else 0.05 * vpeak, 1e-9)
    slope = device.C * (1.0 - abs(device.asymmetry)) * a * v ** (a - 1.0)
    slope = max(slope, 1e-300)
    lam = device.Ks / slope
    return int(min(max(math.ceil(dt * lam / STIFF_TARGET), SUBSTEPS_MIN), SUBSTEPS_MAX))


# ------------------------------------------------------------------ simulate

def orifice_force(v_o: np.ndarray, device: VirtualDamper, hf) -> np.ndarray:
    """F_o = hf C A sign(v_o)|v_o|^alpha [kN], A = 1 +- r (tension/compression)."""
    F = device.C * np.sign(v_o) * np.abs(v_o) ** device.alpha
    if device.asymmetry != 0.0:
        F = F * np.where(F > 0.0, 1.0 + device.asymmetry, 1.0 - device.asymmetry)
    if device.heating != 0.0:
        F = F * hf
    return F


def trace(device: VirtualDamper, protocol: Protocol, substeps: int | None = None) -> dict:
    """Noise-free simulation with every internal quantity, at the sample times.

    Keys (arrays): t [s], d, v, a (imposed, exact) [mm, mm/s, mm/s^2];
    y, v_y, a_y (after the gap), contact (bool), v_o (orifice velocity)
    [mm/s], x_o (piston displacement) [mm], E (orifice energy) [MJ],
    heat_factor hf [-], F_orifice, F_friction, F_series (the element behind
    Ks: F_orifice + F_friction, or F_orifice alone beside an oil column),
    F_parallel (Kp x + F0, x = x_o behind a connection's spring, else y),
    F_inertia (m a_y 1e-6), F (the measured force) [kN]; 'substeps' (int)
    and 'nodes' (number of integration nodes).
    """
    if not isinstance(device, VirtualDamper):
        raise TypeError("device must be a fvd_bridge.rig.VirtualDamper")
    ts = protocol.times()
    if ts.size < 2:
        raise InputError(f"protocol {protocol.name}: fewer than 2 samples")
    _, v_s, _ = protocol.motion(ts)
    vpeak = float(np.max(np.abs(v_s))) if v_s.size else 0.0
    n_sub = int(substeps) if substeps is not None else _auto_substeps(device, vpeak, protocol.dt)
    if n_sub < 1:
        raise InputError(f"substeps = {n_sub}: must be >= 1")
    # fine grid for event search
    fine = protocol.t0 + protocol.dt * (np.arange((ts.size - 1) * n_sub + 1) / n_sub)
    d_f, v_f, _ = protocol.motion(fine)
    pl = play(protocol, device.gap, fine, d_f, v_f)
    t_rev, _ = _reversals(protocol, fine, v_f)
    events = np.concatenate([pl.events(), t_rev, protocol.breakpoints()])
    T, idx, ts = _grid(protocol, n_sub, events)
    H = np.diff(T)
    piece_step = pl.piece(T[:-1] + 0.5 * H)  # play state is constant over each step

    d, v, a = protocol.motion(ts)
    y, v_y, a_y, contact = pl.apply(ts, d, v, a)
    th, r = device.heating, device.asymmetry
    if device.rigid:
        # E from the closed form: exp(theta E) = 1 + theta W0
        tq = T[:-1, None] + 0.5 * H[:, None] * (1.0 + _GL_X[None, :])
        _, vq, _ = protocol.motion(tq.ravel())
        vq = vq.reshape(tq.shape) * (pl.side[piece_step] != 0)[:, None]
        P0 = device.C * np.abs(vq) ** (1.0 + device.alpha) * np.where(vq > 0, 1.0 + r, 1.0 - r) * 1e-6
        W0 = np.concatenate([[0.0], np.cumsum(0.5 * H * (P0 @ _GL_W))])[idx]
        E = np.log1p(th * W0) / th if th > 0.0 else W0
        hf = 1.0 / (1.0 + th * W0)
        v_o = v_y
        F_o = orifice_force(v_o, device, hf)
        F_f = device.friction * np.tanh(v_o / device.v_friction) if device.friction else np.zeros_like(v_o)
        F_s = F_o + F_f
        x_o = y
        F_p = device.Kp * y + device.preload
        F_beside = 0.0
    else:
        tq = T[:-1, None] + STAGE_C[None, :] * H[:, None]
        dq, vq, aq = (m.ravel() for m in protocol.motion(tq.ravel()))
        yq, vyq, _, _ = pl.apply(tq.ravel(), dq, vq, aq, np.repeat(piece_step, STAGE_C.size))
        VY, YQ = vyq.reshape(tq.shape), yq.reshape(tq.shape)
        behind = device.arrangement == "connection"  # the seal and the accumulator behind the spring
        Ff, Kp, F0 = (device.friction, device.Kp, device.preload) if behind else (0.0, 0.0, 0.0)
        S0 = Kp * y[0] + F0  # at rest: the spring holds the accumulator's force
        c = device_constants(C=device.C, alpha=device.alpha, r=r, theta=th, Ff=Ff, vf=device.v_friction,
                             Ks=device.Ks, Kp=Kp, F0=F0)
        S, En, U = integrate_maxwell(H, np.ascontiguousarray(VY), np.ascontiguousarray(YQ), c, S0, 0.0)
        S, E, v_o = S[idx], En[idx], U[idx]
        hf = np.exp(-th * E)
        F_o = orifice_force(v_o, device, hf)
        x_o = y - S / device.Ks
        if behind:
            F_f = device.friction * np.tanh(v_o / device.v_friction)
            F_p = device.Kp * x_o + device.preload
            F_s, F_beside = S - F_p, 0.0
        else:  # the seal on the rod's velocity, the accumulator on its displacement
            F_f = device.friction * np.tanh(v_y / device.v_friction)
            F_p = device.Kp * y + device.preload
            F_s, F_beside = S, F_f
    F_m = device.mass * a_y * 1e-6
    F = F_s + F_beside + F_p + F_m
    return {"t": ts, "d": d, "v": v, "a": a, "y": y, "v_y": v_y, "a_y": a_y, "contact": contact,
            "v_o": v_o, "x_o": x_o, "E": E, "heat_factor": np.broadcast_to(hf, ts.shape).copy(),
            "F_orifice": F_o, "F_friction": F_f, "F_series": F_s, "F_parallel": F_p,
            "F_inertia": F_m, "F": F, "substeps": n_sub, "nodes": int(T.size)}


def simulate(device: VirtualDamper, protocol: Protocol, noise: Noise | None = None, seed=None,
             name: str | None = None, substeps: int | None = None) -> Record:
    """A lab-like record of ``device`` under ``protocol``.

    Record.d is the measured displacement (imposed d + displacement noise),
    F the measured force (+ force noise); v and a are the exact imposed
    velocity and acceleration (v_noise = a_noise = 0; d_noise is the true
    displacement noise). ``noise`` None: no noise at all (the exact truth;
    Noise() is the lab-like default). Noise from
    numpy.random.default_rng(seed): force noise first, then displacement
    noise. provenance['rig'] holds the true parameters,
    provenance['protocol'] and ['noise'] the settings. A record whose
    velocity the tool derives from d, as from a lab, comes from writing this
    one as CSV and reading it back (write_series; tests/lab.py).
    """
    noise = noise or Noise(0.0, 0.0)
    tr = trace(device, protocol, substeps)
    rng = np.random.default_rng(seed)
    F = tr["F"] + (noise.force * rng.standard_normal(tr["F"].size) if noise.force else 0.0)
    d = tr["d"] + (noise.displacement * rng.standard_normal(tr["d"].size) if noise.displacement else 0.0)
    seed_info = int(seed) if isinstance(seed, (int, np.integer)) else (None if seed is None else str(seed))
    prov = {"source": "fvd_bridge.rig", "rig": device.to_dict(), "protocol": protocol.describe(),
            "noise": noise.describe(), "seed": seed_info,
            "units": {"t": "s", "d": "mm", "F": "kN", "v": "mm/s"},
            "velocity": {"method": "exact (rig protocol)"},
            "integration": {"substeps": tr["substeps"], "nodes": tr["nodes"],
                            "scheme": "rigid: closed form + Gauss-Legendre" if device.rigid
                            else "SDIRK3 (Alexander), L-stable"}}
    zero = np.zeros(tr["t"].size)
    return Record(tr["t"].copy(), d, F, tr["v"].copy(), tr["a"].copy(),
                  name=name or device.name, provenance=prov, d_noise=noise.displacement,
                  v_noise=zero, a_noise=zero)
