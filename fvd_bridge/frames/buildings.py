"""Frame structures for damper comparisons, as data: the SAC Los Angeles 3- and
9-story steel moment frames of the nonlinear benchmark buildings.

Source: Y. Ohtori, R.E. Christenson, B.F. Spencer Jr., S.J. Dyke (2004),
"Benchmark control problems for seismically excited nonlinear buildings",
J. Eng. Mech. 130(4), 366-385 (geometry, seismic masses, member sizes,
steel grades, periods, damping); member sizes as in FEMA-355C (2000) for the
pre-Northridge LA designs; section properties from the AISC shape tables.

One 2D north-south moment-resisting frame (MRF) of each building, which
carries half the building's seismic mass.  Units: kN, mm, s; mass in
kN s^2/mm: 1 t = 1e-3 kN s^2/mm (1 t x 1 mm/s^2 = 1 N = 1e-3 kN).

=========================  ============================  ============================
                           ``three_story()``             ``nine_story()``
=========================  ============================  ============================
story heights [mm]         3 x 3960                      basement 3650, 5490, 8 x 3960
bays [mm]                  4 x 9150 (bay 4 simple)       5 x 9150
base                       fixed                         pinned; ground level held
                                                         horizontally (soil, walls)
floor masses per frame [t] 478.5, 478.5, 520             (ground 482.5,) 505,
                                                         7 x 494.5, 535
total mass above grade [t] 1477                          4501.5
benchmark periods [s]      1.01, 0.33, 0.17              2.26, 0.85, 0.49
(frequencies [Hz])         (0.99, 3.06, 5.83)            (0.443, 1.18, 2.05)
periods of this model [s]  1.011, 0.327, 0.171           2.259, 0.848, 0.488
inherent damping           2% Rayleigh, anchored at      2% Rayleigh, anchored at
                           modes 1 and 2                 modes 1 and 3
columns / beams            A572 Gr.50, 345 MPa / A36,    same
                           248 MPa
=========================  ============================  ============================

Model (simplifications, each an assumption of this module, not of the paper):
centre-line geometry, no panel zones, no gravity frames, no P-Delta and no
gravity loads; rigid floor diaphragm (equal horizontal displacement of a
level's nodes); the mass acts horizontally only.  With ``yielding=True`` each
beam and column is a force-based element with plastic-hinge zones of length
``hinge_length_ratio x depth`` at its ends (bilinear moment-curvature,
M_p = F_y Z, post-yield ratio ``hardening``, no axial-moment interaction) and
an elastic middle; ``yielding=False`` gives elastic members (both have the
same periods).  In the 9-story frame the columns change section at the
splices 1830 mm above levels 2, 4, 6 and 8 (level 1 = ground; the paper's
levels 1, 3, 5, 7), and the beams of bay 5 end on the corner column (line 6)
with simple connections (``pinned_lines``: the column's strong axis belongs
to the perpendicular frame).  The 3-story frame's fourth bay has simple
beam connections, which carry no lateral load and are left out; its end
column (line 5) is the W14X68 gravity column bent about its weak axis, and
line 4 (the moment frame's end) is a W14X257 like line 1.  The
2% damping ratio is the benchmark's; the modes it is anchored at are this
module's choice (``damping_modes``).
Both frames reproduce the benchmark's first three frequencies within 0.2%
(``fvd-bridge frame --periods``; tests/frames/test_frames.py).  Without the pinned
bay-5 connections the 9-story frame is 7% stiffer; a leaning column carrying
the gravity load (P-Delta) would make it 2.6% softer, so the benchmark's
frequencies are those of frames without it.

Dampers: one per above-grade story, in a diagonal of bay ``damper_bay`` from
the lower-left to the upper-right joint, optionally in series with an elastic
brace of axial stiffness ``brace_stiffness`` [kN/mm] (None: a rigid brace,
the damper spans the whole diagonal).  A steel brace of area A and length L
has EA/L, e.g. A = 10000 mm^2, L = 9970 mm (9150 x 3960 diagonal): 200 kN/mm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from ..errors import InputError

#: mass of one tonne [kN s^2/mm]
TONNE = 1e-3
#: steel Young's modulus [kN/mm^2] (200 GPa)
E_STEEL = 200.0
#: nominal yield strength of A572 Grade 50 columns [kN/mm^2] (345 MPa)
FY_COLUMNS = 0.345
#: nominal yield strength of A36 beams [kN/mm^2] (248 MPa)
FY_BEAMS = 0.248

_IN = 25.4  # mm per inch


@dataclass(frozen=True)
class Section:
    """A member section bending about one axis: area [mm^2], second moment
    [mm^4], plastic modulus [mm^3] and depth in the bending plane [mm]."""

    name: str
    area: float
    inertia: float
    plastic_modulus: float
    depth: float


@dataclass(frozen=True)
class WShape:
    """An AISC W-shape (inch table values converted to mm)."""

    name: str
    strong: Section
    weak: Section


def _w(name, A, d, bf, Ix, Zx, Iy, Zy) -> WShape:
    """W-shape from AISC values: A [in^2], d, bf [in], Ix, Iy [in^4], Zx, Zy [in^3]."""
    return WShape(name,
                  Section(name, A * _IN ** 2, Ix * _IN ** 4, Zx * _IN ** 3, d * _IN),
                  Section(f"{name} (weak axis)", A * _IN ** 2, Iy * _IN ** 4, Zy * _IN ** 3, bf * _IN))


#: the W-shapes of the two benchmark frames (AISC Manual; A, d, bf, Ix, Zx, Iy, Zy)
W_SHAPES = {s.name: s for s in (
    _w("W14X500", 147.0, 19.6, 17.0, 8210, 1050, 2880, 522),
    _w("W14X455", 134.0, 19.0, 16.8, 7190, 936, 2560, 468),
    _w("W14X370", 109.0, 17.9, 16.5, 5440, 736, 1990, 370),
    _w("W14X311", 91.4, 17.1, 16.2, 4330, 603, 1610, 304),
    _w("W14X283", 83.3, 16.7, 16.1, 3840, 542, 1440, 274),
    _w("W14X257", 75.6, 16.4, 16.0, 3400, 487, 1290, 246),
    _w("W14X233", 68.5, 16.0, 15.9, 3010, 436, 1150, 221),
    _w("W36X160", 47.0, 36.0, 12.0, 9760, 624, 295, 77.3),
    _w("W36X135", 39.9, 35.6, 12.0, 7800, 509, 225, 59.7),
    _w("W33X118", 34.7, 32.9, 11.5, 5900, 415, 187, 51.3),
    _w("W30X116", 34.2, 30.0, 10.5, 4930, 378, 164, 49.2),
    _w("W30X99", 29.0, 29.7, 10.5, 3990, 312, 128, 38.6),
    _w("W27X84", 24.7, 26.7, 10.0, 2850, 244, 106, 33.2),
    _w("W24X68", 20.1, 23.7, 8.97, 1830, 177, 70.4, 24.5),
    _w("W14X68", 20.0, 14.0, 10.0, 722, 115, 121, 36.9),
)}


def _strong(name: str) -> Section:
    return W_SHAPES[name].strong


@dataclass(frozen=True)
class Building:
    """A 2D moment frame as data (kN, mm, s).

    Levels are numbered 0 (base) to N (roof); story k spans levels k and k+1.
    Levels 1..``ground_level`` are held horizontally (a basement); the
    stories above them are the ones with drifts and dampers.

    story_heights  [mm] per story, from the base up (N values)
    bay_widths     [mm] per bay, from the left
    floor_masses   [kN s^2/mm] horizontal seismic mass of levels 1..N (per frame)
    columns        per story, per column line: the column Section
    beams          per level 1..N, per bay: the beam Section, or None for a
                   simple (pinned) connection that carries no lateral load
    pinned_lines   column lines whose beams frame in with simple (shear)
                   connections: the beams' ends there are pinned
    splice_stories stories whose columns change, ``splice_height`` [mm] above
                   their lower level, to the next story's sections
    base           "fixed" or "pinned" column bases
    E, fy_beams, fy_columns   [kN/mm^2]; hardening: post-yield ratio [-]
    hinge_length_ratio  plastic-hinge length / section depth [-]
    yielding       False: elastic members
    damping_ratio  Rayleigh damping ratio [-] at the two ``damping_modes``
    damper_bay     bay holding the damper diagonals (0 = leftmost)
    brace_stiffness  [kN/mm] axial stiffness of the brace in series with each
                   damper; None = rigid
    reference_periods  [s] the benchmark's first periods, for comparison
    """

    name: str
    story_heights: tuple[float, ...]
    bay_widths: tuple[float, ...]
    floor_masses: tuple[float, ...]
    columns: tuple[tuple[Section, ...], ...]
    beams: tuple[tuple[Section | None, ...], ...]
    pinned_lines: tuple[int, ...] = ()
    splice_stories: tuple[int, ...] = ()
    splice_height: float = 0.0
    ground_level: int = 0
    base: str = "fixed"
    E: float = E_STEEL
    fy_beams: float = FY_BEAMS
    fy_columns: float = FY_COLUMNS
    hardening: float = 0.03
    hinge_length_ratio: float = 1.0
    yielding: bool = True
    damping_ratio: float = 0.02
    damping_modes: tuple[int, int] = (1, 2)
    damper_bay: int = 0
    brace_stiffness: float | None = None
    reference_periods: tuple[float, ...] = ()
    source: str = field(default="", compare=False)

    def __post_init__(self):
        n, lines = len(self.story_heights), len(self.bay_widths) + 1
        where = f"building {self.name}: "
        if n < 1 or not self.bay_widths:
            raise InputError(f"{where}needs at least one story and one bay")
        if any(h <= 0 for h in self.story_heights) or any(b <= 0 for b in self.bay_widths):
            raise InputError(f"{where}story heights and bay widths must be > 0 mm")
        for label, count in (("floor_masses", len(self.floor_masses)), ("columns", len(self.columns)),
                             ("beams", len(self.beams))):
            if count != n:
                raise InputError(f"{where}{label} needs {n} entries (one per story/level), got {count}")
        if any(len(row) != lines for row in self.columns):
            raise InputError(f"{where}each story needs {lines} columns (bays + 1)")
        if any(len(row) != lines - 1 for row in self.beams):
            raise InputError(f"{where}each level needs {lines - 1} beams (one per bay, None = simple)")
        if not 0 <= self.ground_level < n:
            raise InputError(f"{where}ground_level must be in 0..{n - 1}")
        if self.base not in ("fixed", "pinned"):
            raise InputError(f"{where}base must be 'fixed' or 'pinned', got {self.base!r}")
        if any(not 0 <= s < n - 1 for s in self.splice_stories):
            raise InputError(f"{where}splice_stories must be in 0..{n - 2} (the story above gives the sections)")
        if self.splice_stories and not 0 < self.splice_height < min(self.story_heights[s] for s in self.splice_stories):
            raise InputError(f"{where}splice_height must lie inside the spliced stories")
        if any(not 0 <= line < lines for line in self.pinned_lines):
            raise InputError(f"{where}pinned_lines must be column lines 0..{lines - 1}")
        if not 0 <= self.damper_bay < lines - 1:
            raise InputError(f"{where}damper_bay must be in 0..{lines - 2}")
        if self.brace_stiffness is not None and not self.brace_stiffness > 0:
            raise InputError(f"{where}brace_stiffness must be > 0 kN/mm or None (rigid)")
        if not 0 <= self.damping_ratio < 1 or len(self.damping_modes) != 2 or min(self.damping_modes) < 1:
            raise InputError(f"{where}damping_ratio in [0, 1) and two damping_modes (1-based) expected")
        if any(m <= 0 for m in self.floor_masses[self.ground_level:]):
            raise InputError(f"{where}floor masses above grade must be > 0 kN s^2/mm")

    @property
    def levels(self) -> int:
        """Number of levels above the base, N."""
        return len(self.story_heights)

    @property
    def stories(self) -> int:
        """Number of stories above grade (with drifts and dampers)."""
        return self.levels - self.ground_level

    @property
    def elevations(self) -> tuple[float, ...]:
        """Level elevations above the base [mm], levels 0..N."""
        z = [0.0]
        for h in self.story_heights:
            z.append(z[-1] + h)
        return tuple(z)

    @property
    def column_lines(self) -> tuple[float, ...]:
        """Column-line abscissae [mm], from the left."""
        x = [0.0]
        for b in self.bay_widths:
            x.append(x[-1] + b)
        return tuple(x)

    @property
    def mass_above_grade(self) -> float:
        """Seismic mass of the levels above grade [kN s^2/mm]."""
        return float(sum(self.floor_masses[self.ground_level:]))

    @property
    def damper_angle(self) -> tuple[float, ...]:
        """Angle of each above-grade damper diagonal to the horizontal [rad]."""
        b = self.bay_widths[self.damper_bay]
        return tuple(math.atan2(h, b) for h in self.story_heights[self.ground_level:])

    def with_(self, **changes) -> "Building":
        """A copy with some fields changed (e.g. ``yielding=False``), checked again."""
        return replace(self, **changes)


def three_story() -> Building:
    """The SAC LA 3-story benchmark frame (Ohtori et al. 2004), one N-S MRF.

    Columns W14X257 (lines 1 and 4, the moment frame's ends) and W14X311
    (lines 2, 3); at the end of the simple bay (line 5) the W14X68 gravity
    column, bent about its weak axis; beams W33X118, W30X116, W24X68 in
    bays 1-3, bay 4 simple.  Masses per frame 478.5, 478.5, 520 t (half of
    9.57e5, 9.57e5, 1.04e6 kg).  T1 = 1.01 s (0.99 Hz).
    """
    c1, c2 = _strong("W14X257"), _strong("W14X311")
    story = (c1, c2, c2, c1, W_SHAPES["W14X68"].weak)
    beams = tuple((_strong(b),) * 3 + (None,) for b in ("W33X118", "W30X116", "W24X68"))
    return Building(
        name="SAC LA 3-story",
        story_heights=(3960.0,) * 3,
        bay_widths=(9150.0,) * 4,
        floor_masses=tuple(m * TONNE for m in (478.5, 478.5, 520.0)),
        columns=(story,) * 3,
        beams=beams,
        base="fixed",
        damping_modes=(1, 2),
        reference_periods=(1 / 0.99, 1 / 3.06, 1 / 5.83),
        source="Ohtori et al. (2004) J. Eng. Mech. 130(4), 3-story N-S MRF",
    )


def nine_story() -> Building:
    """The SAC LA 9-story benchmark frame (Ohtori et al. 2004), one N-S MRF.

    Five moment bays; a 3650 mm basement (pinned bases, ground level held
    horizontally), a 5490 mm first story and eight 3960 mm stories.  Column
    pieces (exterior / interior) W14X370/W14X500, W14X370/W14X455,
    W14X283/W14X370, W14X257/W14X283, W14X233/W14X257 with splices 1830 mm
    above levels 2, 4, 6, 8 (level 1 = ground); beams W36X160 (levels 1-3),
    W36X135 (levels 4-7), W30X99, W27X84, W24X68 (roof, level 10), those of
    bay 5 pinned at line 6 (a simple connection to the corner column, whose
    strong axis belongs to the perpendicular frame).  Masses
    per frame: half of the paper's 9.65e5 (ground), 1.01e6, 7 x 9.89e5,
    1.07e6 kg.  T1 = 2.26 s (0.443 Hz).
    """
    pieces = [("W14X370", "W14X500")] * 3 + [("W14X370", "W14X455")] * 2 + [("W14X283", "W14X370")] * 2 \
        + [("W14X257", "W14X283")] * 2 + [("W14X233", "W14X257")]
    columns = tuple((_strong(e),) + (_strong(i),) * 4 + (_strong(e),) for e, i in pieces)
    girders = ["W36X160"] * 3 + ["W36X135"] * 4 + ["W30X99", "W27X84", "W24X68"]
    return Building(
        name="SAC LA 9-story",
        story_heights=(3650.0, 5490.0) + (3960.0,) * 8,
        bay_widths=(9150.0,) * 5,
        floor_masses=tuple(m * TONNE for m in (482.5, 505.0) + (494.5,) * 7 + (535.0,)),
        columns=columns,
        beams=tuple((_strong(g),) * 5 for g in girders),
        pinned_lines=(5,),
        splice_stories=(2, 4, 6, 8),
        splice_height=1830.0,
        ground_level=1,
        base="pinned",
        damping_modes=(1, 3),
        reference_periods=(1 / 0.443, 1 / 1.18, 1 / 2.05),
        source="Ohtori et al. (2004) J. Eng. Mech. 130(4), 9-story N-S MRF",
    )
