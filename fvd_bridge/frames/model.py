"""A frame as OpenSees commands: ``frame_commands(building, damper)`` lists
the command tuples (ops function name, *args; kN, mm, s; mass kN s^2/mm) that
define the model, ``build_frame`` defines them in openseespy with the eigen
analysis of the bare frame, and ``fvd_bridge.opensees_commands.to_script``
writes them as a script that runs without fvd_bridge.

Model (2D, 3 DOF per node), from a ``buildings.Building``:

- tags: the frame's own materials and sections use tags 1..999 (the series
  brace material is 999); material tags >= 1000 are left to the dampers, whose
  commands the caller supplies with its own ``damper_tag``.  Nothing is shifted.
- one node per joint (tag 100 level + line + 1), extra nodes at column splices
  and, where a beam frames in with a simple connection (``pinned_lines``), a
  node of its own joined to the joint by a stiff zeroLength in x and y;
  base fixed or pinned; levels 1..ground_level held horizontally; the nodes of
  each above-grade level follow the left node horizontally (``equalDOF``), which
  carries the level's mass.
- members: ``forceBeamColumn`` with ``HingeRadau`` plastic-hinge zones (or
  ``elasticBeamColumn`` when ``building.yielding`` is False), linear geometry.
- dampers: a ``twoNodeLink`` along the diagonal of ``building.damper_bay`` in
  each above-grade story, direction 1 (axial) only, with the damper material;
  the link passes its axial deformation and deformation rate [mm, mm/s] to the
  material.  With ``building.brace_stiffness`` the damper sits in series with
  an elastic brace link (axial and, to hold the massless middle node, transverse
  stiffness K_b) from the lower joint to the diagonal's midpoint.
- no gravity loads (``buildings``: an assumption of the benchmark models here).

Inherent damping, Rayleigh on the bare frame (Chopra, Dynamics of Structures,
sec. 11.4): C = a0 M + a1 K_0 with

    a0 = 2 zeta w_i w_j / (w_i + w_j),   a1 = 2 zeta / (w_i + w_j)

(w_i, w_j the circular frequencies of ``building.damping_modes``; K_0 the
initial stiffness, so yielding does not change it).  The ``rayleigh`` command
comes after the frame members and before the damper and brace links:
OpenSees stores the factors on the nodes and elements present at that moment
(Domain::setRayleighDampingFactors), and a twoNodeLink adds Rayleigh damping
only when built with ``-doRayleigh`` -- so a link contributes nothing but its
own material force.  The command list is therefore ``structure_commands``
(wipe, model, nodes, masses, supports, sections, materials, members), the
eigen analysis of that bare frame (not a command: fvd_bridge runs it), then
``damping_commands`` (rayleigh, damper materials, braces, links).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import openseespy.opensees as ops

from ..errors import InputError
from ..opensees_commands import apply, listed
from .buildings import Building, Section

#: first material tag left to the dampers; the frame uses tags below it
DAMPER_TAGS_FROM = 1000
#: material tag of the series brace (frame side)
BRACE_MATERIAL = 999
#: material tag of the pins' stiff springs, and their stiffness [kN/mm]: 1e5 x
#: a beam's axial EA/L, so the pinned beam's periods are those of a moment
#: release to 7 digits
PIN_MATERIAL, PIN_STIFFNESS = 998, 1e8
#: element tags of the pins: this plus their pin node's tag
PIN_LINKS_FROM = 6000
#: geometric transformation tag of the members
GEOM_TRANSF = 1
#: element tags of the damper links and brace links, node tags of the brace
#: midpoints: these plus the story index (0 = bottom story)
DAMPER_LINKS_FROM, BRACE_LINKS_FROM, MID_NODES_FROM = 8000, 8100, 5000


@dataclass(frozen=True)
class FrameModel:
    """Tags and modal data of the model ``build_frame`` left in OpenSees.

    floor_nodes   node carrying the mass of each above-grade level (bottom up)
    damper_links  twoNodeLink tag of each story's damper (empty: bare frame)
    periods       [s] eigen periods of the bare frame, mode 1 first
    rayleigh      (a0 [1/s], a1 [s]) of C = a0 M + a1 K_0
    """

    floor_nodes: tuple[int, ...]
    damper_links: tuple[int, ...]
    periods: np.ndarray
    rayleigh: tuple[float, float]


def joint_node(level: int, line: int) -> int:
    """Tag of the joint of ``level`` on column ``line``."""
    return 100 * level + line + 1


def splice_node(story: int, line: int) -> int:
    """Tag of the splice node in ``story`` on column ``line``."""
    return 100 * story + 51 + line


def pin_node(level: int, line: int, end: int) -> int:
    """Tag of the node where a beam of ``level`` ends with a simple connection
    on column ``line``: its left end (``end`` 0, the beam starts there) or its
    right end (1); a beam on each side of the line has its own pin."""
    return 100 * level + (71 if end == 0 else 81) + line


def floor_nodes(b: Building) -> tuple[int, ...]:
    """The node carrying each above-grade level's mass (bottom up)."""
    return tuple(joint_node(level, 0) for level in range(b.ground_level + 1, b.levels + 1))


def damper_diagonals(b: Building) -> list[tuple[int, int]]:
    """(lower-left joint, upper-right joint) of each above-grade story's
    damper diagonal in ``b.damper_bay``, bottom up."""
    return [(joint_node(story, b.damper_bay), joint_node(story + 1, b.damper_bay + 1))
            for story in range(b.ground_level, b.levels)]


def damper_links(b: Building) -> tuple[int, ...]:
    """Element tags of the damper links, bottom up."""
    return tuple(DAMPER_LINKS_FROM + story for story in range(b.ground_level, b.levels))


# --------------------------------------------------------------- commands


def _node_commands(b: Building) -> list:
    """Joints, splice nodes, supports, rigid-floor constraints and masses."""
    z, x = b.elevations, b.column_lines
    out = []
    for level in range(b.levels + 1):
        for line, xj in enumerate(x):
            out.append(("node", joint_node(level, line), xj, z[level]))
    for story in b.splice_stories:
        for line, xj in enumerate(x):
            out.append(("node", splice_node(story, line), xj, z[story] + b.splice_height))
    for line in range(len(x)):
        out.append(("fix", joint_node(0, line), 1, 1, 1 if b.base == "fixed" else 0))
        for level in range(1, b.ground_level + 1):
            out.append(("fix", joint_node(level, line), 1, 0, 0))
    for level in range(b.ground_level + 1, b.levels + 1):
        for line in range(1, len(x)):
            out.append(("equalDOF", joint_node(level, 0), joint_node(level, line), 1))
        out.append(("mass", joint_node(level, 0), b.floor_masses[level - 1], 0.0, 0.0))
    return out


class _Members:
    """Beam-column element commands; each section's OpenSees section,
    materials and hinge integration defined once, before its first element
    (tags 1..998)."""

    def __init__(self, b: Building):
        self.b, self.defined, self.next_tag, self.commands = b, {}, 1, [("geomTransf", "Linear", GEOM_TRANSF)]

    def _tag(self) -> int:
        """The next free frame tag (materials, sections, integrations: 1..998)."""
        tag, self.next_tag = self.next_tag, self.next_tag + 1
        if tag >= PIN_MATERIAL:
            raise InputError(f"building {self.b.name}: too many section types for frame tags 1..{PIN_MATERIAL - 1}")
        return tag

    def _integration(self, s: Section, fy: float) -> int:
        """HingeRadau integration tag: hinge zones of length ratio x depth with a
        bilinear moment-curvature (M_y = F_y Z, E I, post-yield ratio), elastic between."""
        key = (s.name, fy)
        if key not in self.defined:
            b = self.b
            axial, moment, hinge, elastic, integ = (self._tag() for _ in range(5))
            lp = b.hinge_length_ratio * s.depth
            self.commands += [
                ("uniaxialMaterial", "Elastic", axial, b.E * s.area),
                ("uniaxialMaterial", "Steel01", moment, fy * s.plastic_modulus, b.E * s.inertia, b.hardening),
                ("section", "Aggregator", hinge, axial, "P", moment, "Mz"),
                ("section", "Elastic", elastic, b.E, s.area, s.inertia),
                ("beamIntegration", "HingeRadau", integ, hinge, lp, hinge, lp, elastic)]
            self.defined[key] = integ
        return self.defined[key]

    def add(self, tag: int, i: int, j: int, s: Section, fy: float) -> None:
        """Element ``tag`` from node i to node j with section s, yield strength fy [kN/mm^2]."""
        if self.b.yielding:
            integ = self._integration(s, fy)
            self.commands.append(("element", "forceBeamColumn", tag, i, j, GEOM_TRANSF, integ))
        else:
            self.commands.append(("element", "elasticBeamColumn", tag, i, j, s.area, self.b.E, s.inertia,
                                  GEOM_TRANSF))


def _member_commands(b: Building) -> list:
    """Columns (split at splices) and moment-connected beams."""
    members = _Members(b)
    lines = len(b.column_lines)
    for story in range(b.levels):
        for line in range(lines):
            bottom, top = joint_node(story, line), joint_node(story + 1, line)
            section = b.columns[story][line]
            if story in b.splice_stories:
                splice = splice_node(story, line)
                members.add(100 * story + 1 + line, bottom, splice, section, b.fy_columns)
                members.add(100 * story + 51 + line, splice, top, b.columns[story + 1][line], b.fy_columns)
            else:
                members.add(100 * story + 1 + line, bottom, top, section, b.fy_columns)
    pins = []
    for level in range(1, b.levels + 1):
        for bay, section in enumerate(b.beams[level - 1]):
            if section is not None:
                ends = [(line, end) for end, line in enumerate((bay, bay + 1))]
                members.add(2000 + 100 * level + bay, *[pin_node(level, line, end) if line in b.pinned_lines
                                                        else joint_node(level, line) for line, end in ends],
                            section, b.fy_beams)
                pins += [(level, line, end) for line, end in ends if line in b.pinned_lines]
    return _pin_commands(b, pins) + members.commands


def _pin_commands(b: Building, pins: list) -> list:
    """A simple (shear) connection at each (level, line, end): the beam's end
    node joined to the joint by a zeroLength of PIN_STIFFNESS in x and y, free
    in rotation (no Rayleigh damping: a zeroLength adds it only with -doRayleigh)."""
    if not pins:
        return []
    x, z = b.column_lines, b.elevations
    out = [("uniaxialMaterial", "Elastic", PIN_MATERIAL, PIN_STIFFNESS)]
    for level, line, end in pins:
        pin = pin_node(level, line, end)
        out += [("node", pin, x[line], z[level]),
                ("element", "zeroLength", PIN_LINKS_FROM + pin, joint_node(level, line), pin,
                 "-mat", PIN_MATERIAL, PIN_MATERIAL, "-dir", 1, 2)]
    return out


def structure_commands(b: Building) -> list:
    """The bare frame without damping: wipe, model, nodes, supports,
    rigid floors, masses, sections, materials and members."""
    return [("wipe",), ("model", "basic", "-ndm", 2, "-ndf", 3)] + _node_commands(b) + _member_commands(b)


def _link_commands(b: Building, damper: list, damper_tag: int) -> list:
    """Damper material commands (a list, or an ``export.opensees.Export``),
    then one damper link per above-grade story (behind a brace link with
    ``b.brace_stiffness``)."""
    out = listed(damper)
    if b.brace_stiffness is not None:
        out.append(("uniaxialMaterial", "Elastic", BRACE_MATERIAL, b.brace_stiffness))
    x, z = b.column_lines, b.elevations
    for story, (bottom, top), link in zip(range(b.ground_level, b.levels), damper_diagonals(b), damper_links(b)):
        if b.brace_stiffness is not None:
            mid = MID_NODES_FROM + story
            x0, z0, x1, z1 = x[b.damper_bay], z[story], x[b.damper_bay + 1], z[story + 1]
            out += [("node", mid, 0.5 * (x0 + x1), 0.5 * (z0 + z1)),
                    ("fix", mid, 0, 0, 1),
                    ("element", "twoNodeLink", BRACE_LINKS_FROM + story, bottom, mid,
                     "-mat", BRACE_MATERIAL, BRACE_MATERIAL, "-dir", 1, 2)]
            bottom = mid
        out.append(("element", "twoNodeLink", link, bottom, top, "-mat", damper_tag, "-dir", 1))
    return out


def damping_commands(b: Building, rayleigh: tuple[float, float], damper: list | None = None,
                     damper_tag: int = DAMPER_TAGS_FROM) -> list:
    """Rayleigh damping (a0, a1) of the frame, then, when ``damper`` is given,
    the damper materials, braces and links (see the module docstring)."""
    a0, a1 = rayleigh
    return [("rayleigh", float(a0), 0.0, float(a1), 0.0)] + (_link_commands(b, damper, damper_tag) if damper else [])


def frame_commands(building: Building, damper: list | None = None, damper_tag: int = DAMPER_TAGS_FROM,
                   rayleigh: tuple[float, float] | None = None) -> list:
    """The frame's OpenSees commands: ``apply(frame_commands(b, damper, tag,
    build_frame(b, damper, tag).rayleigh), ops)`` builds what ``build_frame``
    builds.  ``damper``: command tuples defining uniaxial material
    ``damper_tag`` (kN, mm); ``rayleigh`` (a0, a1): default from the eigen
    analysis of the bare frame (``build_frame``, which wipes OpenSees)."""
    _check_damper_tag(damper, damper_tag)
    if rayleigh is None:
        rayleigh = build_frame(building).rayleigh
        ops.wipe()
    return structure_commands(building) + damping_commands(building, rayleigh, damper, damper_tag)


# ---------------------------------------------------------------- OpenSees


def _check_damper_tag(damper, damper_tag: int) -> None:
    if damper is not None and damper_tag < DAMPER_TAGS_FROM:
        raise InputError(f"damper_tag {damper_tag}: damper materials need tags >= {DAMPER_TAGS_FROM} "
                         f"(the frame uses 1..{DAMPER_TAGS_FROM - 1})")


def eigen_periods(b: Building, n_modes: int) -> np.ndarray:
    """Eigen periods [s] of the first ``n_modes`` modes of the model in
    OpenSees: ARPACK when the mass DOFs outnumber twice the modes (it fails
    otherwise), else the dense solver."""
    if 2 * n_modes < b.stories:
        lam = ops.eigen("-genBandArpack", n_modes)
    else:
        lam = ops.eigen("-fullGenLapack", n_modes)
    lam = np.asarray(lam, dtype=float)
    if lam.size != n_modes or np.any(~np.isfinite(lam)) or np.any(lam <= 0):
        raise RuntimeError(f"eigen analysis of {b.name} failed: eigenvalues {lam}")
    return 2 * np.pi / np.sqrt(lam)


def rayleigh_coefficients(zeta: float, omega_i: float, omega_j: float) -> tuple[float, float]:
    """(a0 [1/s], a1 [s]) giving damping ratio zeta at omega_i and omega_j
    [rad/s]: a0 = 2 zeta w_i w_j / (w_i + w_j), a1 = 2 zeta / (w_i + w_j)."""
    return 2 * zeta * omega_i * omega_j / (omega_i + omega_j), 2 * zeta / (omega_i + omega_j)


def build_frame(building: Building, damper: list[tuple] | None = None, damper_tag: int = DAMPER_TAGS_FROM,
                n_modes: int | None = None) -> FrameModel:
    """Wipe OpenSees and build ``building`` with Rayleigh damping and, when
    ``damper`` (OpenSees command tuples defining uniaxial material
    ``damper_tag`` in kN and mm) is given, one damper per above-grade story:
    ``structure_commands``, the eigen analysis, ``damping_commands``.
    ``n_modes``: eigen periods to compute (default min(3, stories), at least
    the Rayleigh modes)."""
    b = building
    _check_damper_tag(damper, damper_tag)
    wanted = max(min(3, b.stories) if n_modes is None else n_modes, *b.damping_modes)
    if wanted > b.stories:
        raise InputError(f"building {b.name}: {wanted} modes asked (damping_modes {b.damping_modes}) "
                         f"but only {b.stories} stories have mass")
    apply(structure_commands(b), ops)
    periods = eigen_periods(b, wanted)
    omega = 2 * np.pi / periods
    a0, a1 = rayleigh_coefficients(b.damping_ratio, omega[b.damping_modes[0] - 1], omega[b.damping_modes[1] - 1])
    apply(damping_commands(b, (a0, a1), damper, damper_tag), ops)
    return FrameModel(floor_nodes(b), damper_links(b) if damper else (), periods, (float(a0), float(a1)))


def frame_periods(building: Building, n_modes: int | None = None) -> np.ndarray:
    """Eigen periods [s] of the first ``n_modes`` modes of the bare frame
    (default min(3, stories)), mode 1 first."""
    periods = build_frame(building, n_modes=n_modes).periods
    return periods if n_modes is None else periods[:n_modes]
