"""A calibrated damper as a CSI (SAP2000, ETABS) damper link: its nonlinear
properties and the linear ones it carries into linear load cases.

``csi_link(model, params, ...)`` gives a ``CsiLink``; ``csi_files`` writes
it as SAP2000's $2k tables or an ETABS .e2k file.  Which link a law is (its
``Law.csi``) and what no link expresses (``Model.csi_refusal``) are the
registry's; this module maps the parameters.

Links (CSI's two damper links, a spring k in series with a dashpot; d_k the
spring's and d_c the dashpot's deformation, f the force):

================================  ==============================================  =========================
model                             link                                            k
================================  ==============================================  =========================
1, 2 (+ series_stiffness)         Damper - Exponential: f = k d_k                 Ks (series_stiffness or
                                  = c sign(d_c')|d_c'|^cexp; c = C, cexp = alpha  oil_column); without one
                                  (law 1: cexp = 1)                               a stiff spring (below)
7 with beta = 1 (+ series_stif.)  Damper - Exponential, c = C, cexp = alpha       K, or K Ks / (K + Ks)
10 bilinear oil damper            Damper - Bilinear: c up to the force limit      K
                                  Fr, cy = p C beyond it
================================  ==============================================  =========================

A law-1 or law-2 model calibrated without a series spring has none, where a
CSI damper link needs its k: the link gets a stiff spring that deflects
SOLVING_DEFLECTION (0.5%) of the tested stroke d under the dashpot's force
at the tested velocity v, k = C v^alpha / (SOLVING_DEFLECTION d), the rule
``export.opensees.solving_springs`` puts behind such a dashpot for a frame
analysis; the file says so, and the exported link then differs from the
calibrated dashpot by that spring (``link_force`` measures it on a record).

Units: kN, mm, s inside; a link is written in the unit set named
(``units.unit_system``), each value from its declared unit (a dashpot's c
with its exponent: kN/(mm/s)^cexp).  CSI programs work in seconds.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from ..catalog import parse_model
from ..errors import InputError, command, option, words
from ..model import Model
from ..units import in_system, unit_system
from .opensees import SOLVING_DEFLECTION, stiff_spring

#: the link names a law's ``csi`` declares
EXPONENTIAL, BILINEAR = "Damper - Exponential", "Damper - Bilinear"
#: what a CSI damper link expresses, in a refusal's words
EXPRESSIBLE = "laws 1 and 2 (alone or with series_stiffness), law 7 with beta = 1 and law 10"
#: CSI's unit sets: force and length names as SAP2000's CurrUnits writes them ('KN, m, C' in a
#: SAP2000 20.1 $2k file; the sixteen sets of CSI's eUnits), by the package's unit names
CSI_FORCE = {"kN": "KN", "N": "N", "tf": "Ton", "kip": "kip", "lbf": "lb"}
CSI_LENGTH = {"mm": "mm", "cm": "cm", "m": "m", "in": "in"}
#: a link property's name: letters, digits, - _ . (it goes unquoted into a $2k row)
NAME_LENGTH = 32
NAME = re.compile(rf"[A-Za-z0-9_.-]{{1,{NAME_LENGTH}}}")
#: US forces go with inches (and feet), metric forces with mm, cm, m; temperature F or C
US_FORCES = ("kip", "lbf")


def energy_factor(alpha: float) -> float:
    """lambda(alpha) = 2^(2+alpha) Gamma^2(1 + alpha/2) / Gamma(2 + alpha) [-]:
    a dashpot C sign(v)|v|^alpha driven by u = u0 sin(omega t) dissipates
    W = lambda C omega^alpha u0^(1+alpha) a cycle (the energy FEMA 356 and
    ASCE 41 take for a nonlinear viscous device; Soong and Dargush 1997,
    Ramirez et al. 2001, MCEER-00-0010).  lambda(1) = pi."""
    return 2.0 ** (2.0 + alpha) * math.gamma(1.0 + alpha / 2.0) ** 2 / math.gamma(2.0 + alpha)


def power_energy(C: float, alpha: float, omega: float, u0: float) -> float:
    """W = lambda(alpha) C omega^alpha u0^(1+alpha) [kN mm]: the energy a cycle
    of a dashpot C [kN/(mm/s)^alpha] under u0 sin(omega t) [mm, rad/s]
    (``energy_factor``)."""
    return energy_factor(alpha) * C * omega ** alpha * u0 ** (1.0 + alpha)


def bilinear_energy(C: float, Fr: float, cy: float, omega: float, u0: float) -> float:
    """W [kN mm] a cycle of the bilinear dashpot (f = C v up to the force
    limit Fr, Fr + cy (|v| - Fr/C) beyond) under u0 sin(omega t):
    W = 4/omega integral_0^(pi/2) f(v0 cos t) v0 cos t dt, v0 = omega u0; with
    t_r = arccos(v_r/v0), v_r = Fr/C, and S(a, b) = [t/2 + sin(2t)/4]_a^b:
    W = 4/omega (C v0^2 S(t_r, pi/2) + (Fr - cy v_r) v0 sin t_r + cy v0^2 S(0, t_r)),
    t_r = 0 (the linear pi C omega u0^2) when v0 <= v_r."""
    v0, vr = omega * u0, Fr / C
    tr = math.acos(vr / v0) if v0 > vr else 0.0

    def S(a, b):
        return (b - a) / 2.0 + (math.sin(2.0 * b) - math.sin(2.0 * a)) / 4.0

    return 4.0 / omega * (C * v0 ** 2 * S(tr, math.pi / 2.0) + (Fr - cy * vr) * v0 * math.sin(tr)
                          + cy * v0 ** 2 * S(0.0, tr))


def maxwell_linear(k: float, c: float, omega: float) -> tuple[float, float]:
    """K' [kN/mm], C' [kN/(mm/s)]: the Maxwell model's complex stiffness,
    a spring k in series with a linear dashpot c at omega [rad/s],
    K* = k i omega c / (k + i omega c) = K' + i omega C':
    K' = k (omega c)^2 / (k^2 + (omega c)^2), C' = c k^2 / (k^2 + (omega c)^2)
    (Constantinou and Symans 1992, NCEER-92-0032)."""
    wc = omega * c
    den = k * k + wc * wc
    return k * wc * wc / den, c * k * k / den


@dataclass(frozen=True)
class Effective:
    """The link's linear properties at a design motion: amplitude ``u0`` [mm]
    and ``frequency`` [Hz]; ``ke`` [kN/mm], ``ce`` [kN/(mm/s)] (CSI's
    effective stiffness and damping, in parallel, for linear load cases);
    ``c_dashpot`` the energy-equivalent linear dashpot [kN/(mm/s)] at the
    dashpot's own amplitude ``u_dashpot`` [mm]; ``source``: where u0 and f
    came from (two texts)."""

    u0: float
    frequency: float
    ke: float
    ce: float
    c_dashpot: float
    u_dashpot: float
    source: tuple = ("given", "given")


def effective(kind: str, p: dict, u0: float, frequency: float, source=("given", "given")) -> Effective:
    """The linear properties of the link ``kind`` with ``p`` {k, c, cexp} or
    {k, c, cy, force_limit} [kN, mm, s] under u0 sin(2 pi f t) [mm].

    The dashpot becomes the linear one that dissipates the same energy a
    cycle at its own amplitude u_c (FEMA 356 / ASCE 41's energy equivalence):
    c_eq(u_c) = W(u_c) / (pi omega u_c^2), W of ``power_energy`` or
    ``bilinear_energy``; the spring takes the rest of the motion, u_c = u0 k
    / sqrt(k^2 + (omega c_eq)^2) (the Maxwell force amplitude over omega
    c_eq), solved for u_c by Brent's method; then K', C' = ``maxwell_linear``(k,
    c_eq, omega).  C' dissipates at u0 what the dashpot does at u_c:
    pi omega C' u0^2 = pi omega c_eq u_c^2."""
    if not (u0 > 0.0 and frequency > 0.0 and math.isfinite(u0) and math.isfinite(frequency)):
        raise InputError(f"the design motion must have a positive amplitude and frequency "
                         f"(got {u0} mm, {frequency} Hz)")
    omega, k = 2.0 * math.pi * frequency, p["k"]

    def c_eq(uc):
        if kind == EXPONENTIAL:
            W = power_energy(p["c"], p["cexp"], omega, uc)
        else:
            W = bilinear_energy(p["c"], p["force_limit"], p["cy"], omega, uc)
        return W / (math.pi * omega * uc * uc)

    def gap(uc):
        return uc - u0 * k / math.hypot(k, omega * c_eq(uc))

    uc = u0 if gap(u0) <= 0.0 else brentq(gap, u0 * 1e-12, u0, xtol=u0 * 1e-14, rtol=1e-14)
    c = c_eq(uc)
    ke, ce = maxwell_linear(k, c, omega)
    return Effective(u0, frequency, ke, ce, c, uc, tuple(source))


@dataclass(frozen=True)
class CsiLink:
    """One calibrated damper as a CSI damper link.

    ``kind``: EXPONENTIAL or BILINEAR; ``model``: the calibrated model's
    spec; ``native``: the link's values in kN, mm, s ({k, c, cexp} or {k, c,
    cy, force_limit}); ``values``: the same in ``units`` ({F, d, t}); ``spring``:
    where k comes from; ``linear``: the ``Effective`` properties (kN, mm, s)
    and ``ke``, ``ce`` in ``units``; ``name``: the link property's name.
    """

    name: str
    kind: str
    model: str
    native: dict
    values: dict
    units: dict
    spring: str
    linear: Effective
    ke: float
    ce: float

    @property
    def unit_text(self) -> dict:
        """{quantity: unit text in the link's units} of k, c, cy, force_limit, ke, ce."""
        F, d, t = (self.units[q] for q in "Fdt")
        cexp = self.native.get("cexp", 1.0)
        return {"k": f"{F}/{d}", "c": f"{F}/({d}/{t})" + (f"^{cexp:.4g}" if cexp != 1.0 else ""),
                "cy": f"{F}/({d}/{t})", "force_limit": F, "ke": f"{F}/{d}", "ce": f"{F}/({d}/{t})"}


def csi_units(units) -> dict:
    """{F, d, t} of ``units`` (``units.unit_system``) checked for a CSI unit
    set: seconds, a force and length of CSI's (US forces with inches, metric
    ones with mm, cm or m).  InputError in one line otherwise."""
    system = unit_system(units)
    given = option("--units", units if isinstance(units, str) else ",".join(system[k] for k in "Fdt"))
    if system["t"] != "s":
        raise InputError(f"{given}: SAP2000 and ETABS work in seconds")
    F, d = system["F"], system["d"]
    if F not in CSI_FORCE or d not in CSI_LENGTH or (F in US_FORCES) != (d == "in"):
        raise InputError(f"{given}: not a SAP2000/ETABS unit set; use kN, N or tf with mm, cm or m, "
                         f"or kip or lbf with in (e.g. kN,m,s or kip,in,s)")
    return system


def design_motion(tested: dict, amplitude: float | None, frequency: float | None) -> tuple[float, float]:
    """The design motion u0 [mm], f [Hz] of the linear properties: the
    options given, else the tested peak stroke d and the frequency
    v / (2 pi d) of the sine that reaches the tested peak velocity v at
    that stroke."""
    for flag, value in (("--amplitude", amplitude), ("--frequency", frequency)):
        if value is not None and not (math.isfinite(value) and value > 0.0):
            raise InputError(f"{option(flag, value)}: must be a positive number")
    d, v = tested.get("d"), tested.get("v")
    u0 = amplitude if amplitude is not None else d
    if not u0:
        raise InputError(f"the calibration records no tested stroke: give {option('--amplitude')} (mm)")
    if frequency is None:
        if not v or not d:
            raise InputError(f"the calibration records no tested velocity: give {option('--frequency')} (Hz)")
        frequency = v / (2.0 * math.pi * d)
    return float(u0), float(frequency)


def _native(model: Model, p: dict, tested: dict, deflection: float) -> tuple[dict, str]:
    """The link's values {k, c, cexp} or {k, c, cy, force_limit} [kN, mm, s]
    and where k comes from (module docstring: Links)."""
    law = model.law
    series = [e for e in model.active_effects(p) if e.stage == "series"]
    Ks = p[f"{series[0].name}.Ks"] if series else None
    if law.csi == BILINEAR:
        return {"k": p["K"], "c": p["C"], "cy": p["p"] * p["C"], "force_limit": p["Fr"]}, "the law's spring K"
    c, cexp = p["C"], p.get("alpha", 1.0)
    if "K" in p:  # law 7 with beta 1: the Maxwell model's own spring
        k = p["K"] if Ks is None else p["K"] * Ks / (p["K"] + Ks)
        return {"k": k, "c": c, "cexp": cexp}, ("the law's spring K" if Ks is None else
                                                f"the law's spring K in series with {series[0].name}'s Ks")
    if Ks is not None:
        return {"k": Ks, "c": c, "cexp": cexp}, f"the calibrated series spring ({series[0].name}.Ks)"
    d, v = tested.get("d"), tested.get("v")
    if not d or not v:
        raise InputError(f"model {model.spec}: no series spring and no tested stroke and velocity to size the "
                         f"stiff spring a CSI damper link needs")
    k = stiff_spring(c * v ** cexp, d, deflection)
    rule = ", as export.opensees.solving_springs" if deflection == SOLVING_DEFLECTION else ""
    return {"k": k, "c": c, "cexp": cexp}, (
        f"the model has no series spring (or a rigid one): a stiff spring that deflects {100 * deflection:g}% of "
        f"the tested stroke {d:.4g} mm under the dashpot's force at the tested velocity {v:.4g} mm/s "
        f"(k = C v^alpha / ({deflection:g} d){rule})")


def refusal(model: Model, p: dict) -> str:
    """The one-line refusal of a model no CSI damper link expresses ('' when
    one does): why (``Model.csi_refusal``), what the links express and the
    calibration that gives one."""
    why = model.csi_refusal(p)
    if not why:
        return ""
    way = ("fvd-bridge calibrate RECORD --laws 2+series_stiffness" if words() == "cli" else
           "fvd_bridge.calibrate(record, '2+series_stiffness')")
    return (f"model {model.spec}: no SAP2000/ETABS damper link expresses {why}; the links express {EXPRESSIBLE}: "
            f"calibrate one ({way}), or use {command('export fmu')}")


def csi_link(model, params: dict, units=None, tested: dict | None = None, amplitude: float | None = None,
             frequency: float | None = None, name: str = "FVD1",
             deflection: float = SOLVING_DEFLECTION) -> CsiLink:
    """The damper as a CSI damper link.

    Parameters
    ----------
    model : Model or str
        The calibrated model (``Calibration.model``) or its spec.
    params : dict
        {name: value} in the model's units (``Calibration.named()``).
    units : str, tuple or dict, optional
        The CSI model's FORCE,LENGTH,TIME ('kN,m,s', 'kip,in,s'; default kN, mm, s).
    tested : dict, optional
        The tested range {d [mm], v [mm/s]} (``Calibration.tested``): the stiff
        spring of a model without one, and the default design motion.
    amplitude, frequency : float, optional
        The design motion of the linear properties [mm], [Hz] (``design_motion``).
    name : str
        The link property's name.
    deflection : float
        A model without a series spring: the share of the tested stroke its
        stiff spring deflects under the force at the tested velocity
        (default SOLVING_DEFLECTION, 0.005; smaller: stiffer, closer to the
        calibrated dashpot).

    Returns
    -------
    CsiLink
        InputError (one line) for a model no CSI damper link expresses, a
        unit set CSI has not, a bad design motion.
    """
    model = model if isinstance(model, Model) else parse_model(model)
    if not NAME.fullmatch(str(name)):
        raise InputError(f"{option('--name', name)}: a link property's name takes 1-{NAME_LENGTH} letters, digits "
                         f"and - _ . only")
    system = csi_units(units)
    p = {n: float(params[n]) for n in model.names}
    why = refusal(model, p)
    if why:
        raise InputError(why)
    if not (math.isfinite(deflection) and 0.0 < deflection < 1.0):
        raise InputError(f"{option('--spring-deflection', deflection)}: must lie between 0 and 1 (a share of the "
                         f"tested stroke, e.g. 0.005)")
    tested = tested or {}
    native, spring = _native(model, p, tested, deflection)
    u0, f = design_motion(tested, amplitude, frequency)
    source = ("given" if amplitude is not None else "the tested peak stroke",
              "given" if frequency is not None else "the sine reaching the tested peak velocity at that stroke")
    lin = effective(model.law.csi, native, u0, f, source)
    exps = {"cexp": native.get("cexp", 1.0)}
    unit = {"k": "kN/mm", "c": "kN/(mm/s)^cexp", "cexp": "-", "cy": "kN/(mm/s)", "force_limit": "kN"}
    values = {q: in_system(v, unit[q], system, exps) for q, v in native.items()}
    return CsiLink(name, model.law.csi, model.spec, native, values, system, spring, lin,
                   in_system(lin.ke, "kN/mm", system), in_system(lin.ce, "kN/(mm/s)", system))


def link_model(link: CsiLink) -> tuple[Model, np.ndarray]:
    """The link as fvd_bridge's own model and parameter vector [kN, mm, s]:
    Damper - Exponential is law 2 + series_stiffness (C, alpha, Ks), Damper -
    Bilinear law 10 (K, C, Fr, p = cy / c)."""
    n = link.native
    if link.kind == BILINEAR:
        return parse_model("10"), np.array([n["k"], n["c"], n["force_limit"], n["cy"] / n["c"]])
    return parse_model("2+series_stiffness"), np.array([n["c"], n["cexp"], n["k"]])


def link_force(link: CsiLink, record) -> np.ndarray:
    """The link's force [kN] on a record (``link_model``, four sub-steps a sample)."""
    model, P = link_model(link)
    return model.force(record, P[None, :], 4)[0]
