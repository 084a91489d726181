"""A virtual fluid-viscous damper: its true physical parameters, and series of them.

Parameters (kN, mm, s; mass in kg), each checked on construction:

=========== ================= ==================================================
name        unit              meaning
=========== ================= ==================================================
C           kN/(mm/s)^alpha   orifice coefficient: F_o = C sign(v_o)|v_o|^alpha
alpha       -                 orifice exponent, 0 < alpha <= 2
Ks          kN/mm             series stiffness (fluid compressibility, rod,
                              clevises, frame); None = rigid
friction    kN                seal friction Ff: + Ff tanh(v_o / v_friction)
v_friction  mm/s              friction smoothing velocity v_f
heating     1/MJ              theta: orifice force x exp(-theta E), E [MJ] the
                              energy the orifice has dissipated so far
gap         mm                total pin clearance g (play of half-width g/2)
asymmetry   -                 r: orifice force x (1 + r) in tension, (1 - r)
                              in compression, |r| < 1
Kp          kN/mm             accumulator (parallel) stiffness
preload     kN                accumulator preload F0
mass        kg                moving mass m: + m a 1e-6 [kN]
arrangement                   where Ks sits: 'connection' (a flexible connection
                              outside the damper: seal friction and accumulator
                              behind it) or 'oil_column' (the compressible oil
                              inside it: seal and accumulator on the rod's full
                              stroke, beside the spring and orifice)
=========== ================= ==================================================
"""

from __future__ import annotations

import math
import re
from dataclasses import asdict, dataclass, fields, replace

import numpy as np

from ..errors import InputError, option

#: name -> (unit, description)
PARAMETERS = {
    "C": ("kN/(mm/s)^alpha", "orifice damping coefficient"),
    "alpha": ("-", "orifice velocity exponent"),
    "Ks": ("kN/mm", "series stiffness (fluid compressibility + connections); null = rigid"),
    "friction": ("kN", "seal friction force Ff"),
    "v_friction": ("mm/s", "friction smoothing velocity v_f"),
    "heating": ("1/MJ", "heating coefficient theta (orifice force x exp(-theta E))"),
    "gap": ("mm", "total pin clearance g (play operator of half-width g/2)"),
    "asymmetry": ("-", "tension/compression asymmetry r (orifice x (1 +- r))"),
    "Kp": ("kN/mm", "accumulator (parallel) stiffness"),
    "preload": ("kN", "accumulator preload F0"),
    "mass": ("kg", "moving mass m"),
}
#: where the series spring sits (the models' series_stiffness and oil_column); not a drawn parameter
ARRANGEMENTS = ("connection", "oil_column")

#: parameters drawn lognormally (positive), the others normally (see production_series)
LOGNORMAL = ("C", "Ks", "friction", "v_friction", "heating", "gap", "Kp", "mass")
NORMAL = ("alpha", "asymmetry", "preload")

_NAME = re.compile(r"^[A-Za-z0-9_.-]+$")


def _bad(name, value, rule):
    unit, desc = PARAMETERS.get(name, ("-", "where the series spring sits"))
    return InputError(f"rig parameter {name} = {value}: must be {rule} ({desc}, {unit})")


@dataclass(frozen=True)
class VirtualDamper:
    """True parameters of one virtual damper (see the module table for units).

    Measured force [kN], positive in tension (y the displacement after the
    pin gap, F_s the force through the series spring Ks, rig/simulate.py):
      connection:  F = F_s + m a_y 1e-6 + noise, F_s = orifice + friction +
                   Kp x_o + F0 (the whole damper behind the spring)
      oil_column:  F = F_s + friction(v_y) + Kp y + F0 + m a_y 1e-6 + noise,
                   F_s = orifice (the seal and accumulator on the rod)
    Rigid (Ks None) both are F = orifice + friction + Kp y + F0 + m a_y 1e-6.
    """

    C: float = 45.4
    alpha: float = 0.3
    Ks: float | None = None
    friction: float = 0.0
    v_friction: float = 1.0
    heating: float = 0.0
    gap: float = 0.0
    asymmetry: float = 0.0
    Kp: float = 0.0
    preload: float = 0.0
    mass: float = 0.0
    arrangement: str = "connection"
    name: str = "device"

    def __post_init__(self):
        if self.arrangement not in ARRANGEMENTS:
            raise _bad("arrangement", repr(self.arrangement), f"one of {', '.join(ARRANGEMENTS)}")
        for f in fields(self):
            if f.name in ("name", "arrangement"):
                continue
            value = getattr(self, f.name)
            if f.name == "Ks" and value is None:
                continue
            try:
                x = float(value)
            except (TypeError, ValueError):
                raise _bad(f.name, repr(value), "a number") from None
            if f.name == "Ks" and x == math.inf:
                object.__setattr__(self, "Ks", None)
                continue
            if not math.isfinite(x):
                raise _bad(f.name, x, "finite")
            object.__setattr__(self, f.name, x)
        checks = {
            "C": (self.C > 0.0, "> 0"),
            "alpha": (0.0 < self.alpha <= 2.0, "in (0, 2]"),
            "Ks": (self.Ks is None or self.Ks > 0.0, "> 0 (or none/inf for rigid)"),
            "friction": (self.friction >= 0.0, ">= 0"),
            "v_friction": (self.v_friction > 0.0, "> 0"),
            "heating": (self.heating >= 0.0, ">= 0"),
            "gap": (self.gap >= 0.0, ">= 0"),
            "asymmetry": (-1.0 < self.asymmetry < 1.0, "in (-1, 1)"),
            "Kp": (self.Kp >= 0.0, ">= 0"),
            "mass": (self.mass >= 0.0, ">= 0"),
        }
        for name, (ok, rule) in checks.items():
            if not ok:
                raise _bad(name, f"{getattr(self, name):g}", rule)
        if not isinstance(self.name, str) or not _NAME.match(self.name):
            raise InputError(f"rig device name '{self.name}': use letters, digits, '_', '-' or '.' only")

    @property
    def rigid(self) -> bool:
        """True when there is no series flexibility."""
        return self.Ks is None

    def parameters(self) -> dict:
        """Physical parameters (no name) as plain floats (the arrangement a
        word); Ks None = rigid."""
        d = asdict(self)
        d.pop("name")
        return d

    def to_dict(self) -> dict:
        return {"name": self.name, **self.parameters()}

    @classmethod
    def from_dict(cls, data: dict, where: str = "device") -> "VirtualDamper":
        unknown = set(data) - set(PARAMETERS) - {"name", "arrangement"}
        if unknown:
            raise InputError(f"{where}: unknown rig parameter '{sorted(unknown)[0]}' "
                             f"(known: {', '.join(PARAMETERS)})")
        return cls(**data)

    def with_(self, **changes) -> "VirtualDamper":
        """A copy with some parameters changed (checked again)."""
        return replace(self, **changes)


def _check_scatter(scatter: dict) -> dict:
    out = {}
    for key, s in (scatter or {}).items():
        if key not in PARAMETERS:
            raise InputError(f"scatter: unknown rig parameter '{key}' (known: {', '.join(PARAMETERS)})")
        try:
            s = float(s)
        except (TypeError, ValueError):
            raise InputError(f"scatter of {key} '{s}': not a number") from None
        if not (math.isfinite(s) and 0.0 <= s < 1.0):
            raise InputError(f"scatter of {key} = {s:g}: relative standard deviation must be in [0, 1)")
        out[key] = s
    return out


def production_series(n: int, nominal: VirtualDamper, scatter: dict | None = None, seed: int | None = 0,
                      prefix: str = "device") -> list[VirtualDamper]:
    """``n`` devices with manufacturing scatter around ``nominal``.

    ``scatter`` maps a parameter to its relative standard deviation s:
    C, Ks, friction, v_friction, heating, gap, Kp, mass are lognormal with
    median at the nominal value, x = x0 exp(s z); alpha, asymmetry and preload
    are normal, x = x0 (1 + s z) (alpha clipped to [0.01, 2], asymmetry to
    [-0.95, 0.95]); z standard normal from ``numpy.random.default_rng(seed)``,
    drawn device by device in the order of PARAMETERS (same seed, same series).
    A rigid Ks stays rigid; a zero parameter stays zero.
    """
    try:
        n = int(n)
    except (TypeError, ValueError):
        raise InputError(f"{option('--devices', n)}: not a whole number") from None
    if n < 1:
        raise InputError(f"{option('--devices', n)}: at least 1 device")
    scatter = _check_scatter(scatter)
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        z = rng.standard_normal(len(PARAMETERS))
        p = nominal.parameters()
        for zi, key in zip(z, PARAMETERS):
            s = scatter.get(key, 0.0)
            if s == 0.0 or p[key] is None:
                continue
            if key in LOGNORMAL:
                p[key] = p[key] * math.exp(s * zi)
            else:
                p[key] = p[key] * (1.0 + s * zi)
        p["alpha"] = min(max(p["alpha"], 0.01), 2.0)
        p["asymmetry"] = min(max(p["asymmetry"], -0.95), 0.95)
        out.append(VirtualDamper(**p, name=f"{prefix}_{i + 1:02d}"))
    return out


#: nominal effects of the demo series (a 300 kN class device, paper section 3)
DEMO_NOMINAL = VirtualDamper(C=292.0 / 500.0 ** 0.3, alpha=0.3, Ks=150.0, friction=3.0, v_friction=1.0,
                      heating=0.10, gap=0.10, asymmetry=0.015, Kp=0.10, preload=1.5, mass=40.0)
#: manufacturing scatter of the demo series (relative standard deviations)
DEMO_SCATTER = {"alpha": 0.02, "Ks": 0.20, "friction": 0.15, "heating": 0.20, "gap": 0.20,
                "asymmetry": 0.20, "Kp": 0.20, "preload": 0.20, "mass": 0.10}
#: noise of the demo records: force [kN], displacement [mm]
DEMO_NOISE = {"force": 1.0, "displacement": 0.005}


def demo_series(seed: int | None = 0, n: int = 5) -> list[VirtualDamper]:
    """Five devices like the paper's Tables 1-2: 300 kN class, alpha about 0.3,
    orifice forces at 500 mm/s spread evenly over 265..325 kN (C set per device
    from its drawn alpha), Ks about 150 kN/mm, friction about 3 kN, heating
    about 0.1 /MJ (a few % force drop over 10 cycles), 1.5% asymmetry, a small
    accumulator stiffness and preload, a 0.1 mm pin gap; scatter DEMO_SCATTER."""
    base = production_series(n, DEMO_NOMINAL, DEMO_SCATTER, seed)
    targets = np.linspace(265.0, 325.0, n) if n > 1 else np.array([292.0])
    return [dev.with_(C=float(F / 500.0 ** dev.alpha)) for dev, F in zip(base, targets)]
