"""What a law is, declared as data (the registry's types): parameters with
units and bounds, an equation, a vectorized kernel, the state it carries, the
kind of device it describes, and its export targets (``OpenSeesForm``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..errors import InputError, option
from ..kernel_cache import kernel_array
from .scalar import members

BOUND_MODES = ("auto", "paper")


@dataclass(frozen=True)
class Parameter:
    """One parameter of a law or effect.

    ``paper``: the bounds of the paper's Table 4 (or a literature default);
    ``auto(scales)``: bounds derived from the record's peak force F [kN],
    velocity v [mm/s] and displacement d [mm]; ``log``: searched on a log
    scale by the default optimizer (parameters spanning decades); ``limit``:
    the physical range an automatic bound may widen to when a fit ends on it
    (``fit.nested.wider_bounds``); ``rigid_upper``: a stiffness whose
    automatic upper bound already means rigid (its elastic range a
    thousandth of the stroke): it does not widen upwards.
    """

    name: str
    unit: str
    paper: tuple[float, float]
    auto: Callable[[dict], tuple[float, float]]
    description: str
    log: bool = False
    limit: tuple[float, float] = (0.0, float("inf"))
    rigid_upper: bool = False


@dataclass(frozen=True)
class Derived:
    """A quantity computed from a law's parameters, reported beside them
    (law 8's identifiable slip force mu*N [kN]); ``value(p)`` takes the law's
    parameter vector (law order); ``factors``: the parameters it combines,
    which alone may be non-identifiable."""

    name: str
    unit: str
    value: Callable
    description: str
    factors: tuple = ()


@dataclass(frozen=True)
class OpenSeesForm:
    """How OpenSees expresses a law or an effect (a registry target).

    ``materials``: the OpenSees materials, as the docs' table shows them
    ("Viscous C alpha"); ``build(s, p)`` adds them to the script builder s
    (``s.mat(kind, *args) -> tag``, ``s.parallel(tags, factors)``,
    ``s.notes``) from the parameters p {name: value} (kN, mm, s) and returns
    the tag of the law's material (an output effect: ``build(s, tag, p)``,
    wrapping the element ``tag``; a parallel effect: a term added beside it);
    ``series(s, p, Ks, g)``: the law behind a series spring Ks [kN/mm] and a
    pin clearance g [mm] (0: none; None: not expressible); ``refuse(p)``: why these parameter values cannot be
    expressed ('' when they can); ``accuracy``: 'exact' (OpenSees solves the
    model's equations), 'hysteretic' (BoucWen's first-order z, bound
    proportional to the step), 'table' (a tabulated curve), 'gap'
    (ViscousDamper's LGap, bound proportional to the clearance); ``stateless``:
    the material keeps no history; ``needs_stateless``: an output effect
    that can wrap a stateless law's material only (asymmetry); ``exponent``:
    the parameter that is the exponent of its ``Viscous`` dashpot ('' for
    a linear one or none)."""

    materials: str
    build: Callable
    accuracy: str = "exact"
    series: Callable | None = None
    refuse: Callable | None = None
    stateless: bool = False
    needs_stateless: bool = False
    exponent: str = ""


@dataclass(frozen=True)
class Law:
    """A damper law: ``population(d, v, dt, P, substeps) -> F`` evaluates a whole
    population, P of shape (pop, n_par), F of shape (pop, n_t) [kN]; d [mm],
    v [mm/s], dt [s] (None: its scalar step form per member,
    ``scalar.members``).  ``derived``: quantities reported beside the parameters.

    Capabilities (read by every consumer; nobody switches on the number):
    ``state``: the internal variables it carries (none for an algebraic
    law); ``device``: 'fluid' (an orifice, a Maxwell dashpot) or
    'hysteretic' (friction and hysteretic devices), the wording diagnose
    uses; ``velocity_only``: the force depends on the velocity alone and
    vanishes at rest; ``connection``: its step form can sit behind a series
    spring or a contact gap (``effects/connection.py``); ``reference``: a
    realistic parameter set (the golden files, benchmarks); ``opensees``:
    its OpenSees form (None: none); ``fmu``: the FMU's C code carries it;
    ``paper``: one of the paper's nine laws (its protocol, ``demo``);
    ``start(d, v, F) -> [parameters, ...]``: its data-driven starts, one
    or more candidate sets (``starts.py``; None: the local search starts
    from a sample alone);
    ``global_search``: its objective has basins that a local solve from a
    sample does not always leave, so the default optimizer checks its local
    optimum globally (``LocalSettings.always_check``); ``csi``: the CSI
    (SAP2000, ETABS) damper link it is ('Damper - Exponential': a spring in
    series with C sign(v)|v|^alpha; 'Damper - Bilinear': the oil damper; ''
    none), its parameter values refused as its OpenSees form refuses them."""

    number: int
    name: str
    kind: str  # "algebraic" or "differential"
    equation: str
    source: str
    parameters: tuple[Parameter, ...]
    population: Callable | None
    note: str = ""
    derived: tuple = ()
    state: tuple = ()
    device: str = "fluid"
    velocity_only: bool = False
    connection: bool = True
    reference: tuple = ()
    opensees: OpenSeesForm | None = None
    fmu: bool = True
    paper: bool = True
    global_search: bool = False
    start: Callable | None = None
    csi: str = ""

    @property
    def key(self) -> str:
        return str(self.number)

    @property
    def names(self) -> list[str]:
        return [p.name for p in self.parameters]

    def bounds(self, mode: str, scales: dict) -> np.ndarray:
        """(n_par, 2) bounds: 'paper' (Table 4) or 'auto' (from the record's scales)."""
        if mode not in BOUND_MODES:
            raise InputError(f"{option('--bounds', mode)}: expected one of {', '.join(BOUND_MODES)}")
        rows = [p.paper if mode == "paper" else p.auto(scales) for p in self.parameters]
        return np.asarray(rows, dtype=float)

    def force(self, d: np.ndarray, v: np.ndarray, dt: float, P: np.ndarray, substeps: int = 1) -> np.ndarray:
        """Force [kN] for each parameter row of P: (pop, n_par) -> (pop, n_t)."""
        P = np.atleast_2d(np.asarray(P, dtype=float))
        if P.shape[1] != len(self.parameters):
            raise InputError(f"law {self.number}: expected {len(self.parameters)} parameters "
                             f"({', '.join(self.names)}), got {P.shape[1]}")
        d, v, P = (kernel_array(x) for x in (d, v, P))  # one compiled signature (kernel_cache)
        if self.population is None:
            return members(self.number, d, v, float(dt), P, int(substeps))
        return self.population(d, v, float(dt), P, int(substeps))

    def compile_kernel(self, members: int) -> None:
        """Compile, or load from numba's cache, the kernel this law runs on a
        population of ``members`` (``catalog.kernel_tasks``): its force on 16
        samples of a sine at its reference parameters, as a fit calls it."""
        t = np.arange(16) * 0.01
        self.force(10.0 * np.sin(2 * np.pi * t), 20 * np.pi * np.cos(2 * np.pi * t), 0.01,
                   np.tile(np.asarray(self.reference, dtype=float), (members, 1)))
