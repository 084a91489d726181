"""A ``CsiLink`` (``export.csi``) as the text files SAP2000 and ETABS import.

Every table, key and keyword written here is copied from a public file,
none invented (docs/guide/csi.md lists them):

* SAP2000 ($2k / .s2k database tables): the file SAP2000 20.1.0 wrote,
  MPT/CSI/API/MPT.CSI.Serialize.SAP2000/model/test.s2k in
  github.com/MarkPThomas/MPT.Net (commit 03dd160): tables "PROGRAM CONTROL"
  (ProgramName, Version, CurrUnits="KN, m, C"), "LINK PROPERTY DEFINITIONS
  01 - GENERAL" (Link, LinkType="Damper - Exponential" or "Damper -
  Bilinear", Mass, Weight, RotInert1-3, DefLength, DefArea, PDM2I ... PDM3J,
  Color, Notes), "LINK PROPERTY DEFINITIONS 04 - DAMPER" (Link, DOF, Fixed,
  NonLinear, TransKE, TransCE, TransK, TransC, CExp), "LINK PROPERTY
  DEFINITIONS 14 - BILINEAR DAMPER" (... TransK, TransC, TransCy,
  ForceLimit) and the closing "END TABLE DATA"; CurrUnits' other sets as
  that repository's eUnits reads them ('kip, in, F', 'N, mm, C', ...).
* ETABS (.e2k): the files ETABS 20.2.0 wrote, models/Ejemplo.e2k in
  github.com/jgomezc1/RDC_PERFORM (commit c2e3c0f): the blocks "$ PROGRAM
  INFORMATION" (PROGRAM "ETABS" VERSION), "$ CONTROLS" (UNITS "KGF" "M"
  "C"), "$ LINK PROPERTIES" (LINKPROP "NLPR1" TYPE "DAMPER - EXPONENTIAL";
  LINKPROP "NLPR1" DOF "U1"), "$ LOG" (STARTCOMMENTS ... ENDCOMMENTS), END
  and "$ END OF MODEL FILE".  Not found in any public .e2k: the keywords
  of a DOF's values (ETABS_DOF_KEYS, spelled as ETABS' keyword table lists
  them, C excepted) and the bilinear TYPE string (SAP2000's LinkType in
  capitals, as the exponential one is): unverified, and said in the file.

Neither program was run here: that they import these files is not checked.
"""

from __future__ import annotations

from .._version import __version__
from .csi import BILINEAR, CSI_FORCE, CSI_LENGTH, US_FORCES, CsiLink

#: the SAP2000 version whose export the $2k tables follow
SAP2000_VERSION = "20.1.0"
#: the ETABS version whose export the .e2k blocks follow
ETABS_VERSION = "20.2.0"
#: SAP2000's damper tables and the columns of one DOF's row, by link kind
S2K_TABLES = {"Damper - Exponential": ("LINK PROPERTY DEFINITIONS 04 - DAMPER",
                                       (("TransK", "k"), ("TransC", "c"), ("CExp", "cexp"))),
              "Damper - Bilinear": ("LINK PROPERTY DEFINITIONS 14 - BILINEAR DAMPER",
                                    (("TransK", "k"), ("TransC", "c"), ("TransCy", "cy"),
                                     ("ForceLimit", "force_limit")))}
#: the .e2k keywords of one DOF's values, by link kind (unverified: module docstring)
ETABS_DOF_KEYS = {"Damper - Exponential": (("K", "k"), ("C", "c"), ("EXP", "cexp")),
                  "Damper - Bilinear": (("K", "k"), ("INITIALDAMPINGCOEFF", "c"), ("YIELDEDDAMPINGCOEFF", "cy"),
                                        ("FORCELIMIT", "force_limit"))}
#: the link deforms along its axis: local DOF U1
DOF = "U1"


def num(x: float) -> str:
    """A number as the files write it: 15 significant digits."""
    return f"{float(x):.15g}"


def _temperature(link: CsiLink) -> str:
    return "F" if link.units["F"] in US_FORCES else "C"


def sap2000_units(link: CsiLink) -> str:
    """CurrUnits of the link's unit set: 'KN, m, C', 'kip, in, F'."""
    return f"{CSI_FORCE[link.units['F']]}, {CSI_LENGTH[link.units['d']]}, {_temperature(link)}"


def etabs_units(link: CsiLink) -> str:
    """The .e2k UNITS line's values: '"KN"  "M"  "C"' (as ETABS writes '"KGF"  "M"  "C"')."""
    return "  ".join(f'"{u.upper()}"' for u in (CSI_FORCE[link.units["F"]], CSI_LENGTH[link.units["d"]],
                                                _temperature(link)))


def comment_lines(link: CsiLink, provenance=()) -> list[str]:
    """What a file says of its link, in plain lines: the model and where it
    holds, the units, the mapping, the spring, the linear properties and
    their design motion, the equations with their sources, what was checked."""
    u, v, lin = link.unit_text, link.values, link.linear
    F, d = link.units["F"], link.units["d"]
    if link.kind == BILINEAR:
        law = (f"{link.kind}: f = k d_k = c d_c' up to the force limit, then the force limit + cy (|d_c'| - "
               f"limit/c): k {num(v['k'])} {u['k']}, c {num(v['c'])} {u['c']}, cy {num(v['cy'])} {u['cy']} "
               f"(p C), force limit {num(v['force_limit'])} {F} (Fr)")
        energy = "W of the bilinear dashpot integrated over a sine cycle (export.csi.bilinear_energy)"
    else:
        law = (f"{link.kind}: f = k d_k = c sign(d_c')|d_c'|^cexp, the spring in series with the dashpot: "
               f"k {num(v['k'])} {u['k']}, c {num(v['c'])} {u['c']}, cexp {num(v['cexp'])}")
        energy = ("W = lambda c omega^cexp u^(1+cexp), lambda = 2^(2+cexp) Gamma^2(1+cexp/2)/Gamma(2+cexp) "
                  "(as FEMA 356 and ASCE 41; Soong and Dargush 1997)")
    in_units = (f" = {lin.u0 / _mm(link):.6g} {d}" if d != "mm" else "")
    return [f"fvd_bridge {__version__}: calibrated model {link.model} as the {link.kind} link {link.name}",
            *provenance,
            f"units: force {F}, length {d}, time s (the model's must be these; c with its exponent)",
            law, f"k: {link.spring}",
            f"linear load cases: effective stiffness {num(link.ke)} {u['ke']} and damping {num(link.ce)} {u['ce']} "
            f"at the design motion u0 {lin.u0:.6g} mm{in_units} ({lin.source[0]}), f {lin.frequency:.6g} Hz "
            f"({lin.source[1]})",
            f"  dashpot: the linear c_eq = W / (pi omega u_c^2) dissipating a cycle's energy at its own amplitude "
            f"u_c {lin.u_dashpot:.6g} mm, {energy}; with the spring, the Maxwell complex stiffness K' = k (omega "
            f"c_eq)^2 / (k^2 + (omega c_eq)^2), C' = c_eq k^2 / (k^2 + (omega c_eq)^2) (Constantinou and Symans 1992)",
            "not run in SAP2000 or ETABS here: import it and check the link's properties"]


def _mm(link: CsiLink) -> float:
    """1 unit of the link's length in mm."""
    from ..units import factor

    return factor("d", link.units["d"])


def _quote(text: str) -> str:
    return '"' + text.replace('"', "'") + '"'


def to_s2k(link: CsiLink, provenance=()) -> str:
    """SAP2000 $2k tables (File > Import > SAP2000 .s2k): the unit set, the
    link's general row and its DOF's row; the comments as free lines before
    the first table (where SAP2000's own file has its 'File ... was saved'
    line).  Lines end CRLF as SAP2000 writes them."""
    table, columns = S2K_TABLES[link.kind]
    values = "   ".join(f"{key}={num(link.values[q])}" for key, q in columns)
    notes = f"fvd_bridge {__version__}: model {link.model}; {link.spring.split(':')[0]}"
    lines = [*comment_lines(link, provenance), " ",
             'TABLE:  "PROGRAM CONTROL"',
             f'   ProgramName=SAP2000   Version={SAP2000_VERSION}   CurrUnits="{sap2000_units(link)}"', " ",
             'TABLE:  "LINK PROPERTY DEFINITIONS 01 - GENERAL"',
             f"   Link={link.name}   LinkType={_quote(link.kind)}   Mass=0   Weight=0   RotInert1=0   RotInert2=0"
             f"   RotInert3=0   DefLength=1   DefArea=1   PDM2I=0   PDM2J=0   PDM3I=0   PDM3J=0   Color=Green"
             f"   Notes={_quote(notes)}", " ",
             f'TABLE:  "{table}"',
             f"   Link={link.name}   DOF={DOF}   Fixed=No   NonLinear=Yes   TransKE={num(link.ke)}"
             f"   TransCE={num(link.ce)}   {values}", " ",
             "END TABLE DATA"]
    return "\r\n".join(lines) + "\r\n"


def to_e2k(link: CsiLink, provenance=()) -> str:
    """An ETABS .e2k file (File > Import > ETABS .e2k text file): the units,
    the link property (its TYPE and its U1 values) and the comments in the
    log block.  The DOF line's keywords are unverified (module docstring)."""
    values = "  ".join(f"{key} {num(link.values[q])}" for key, q in ETABS_DOF_KEYS[link.kind])
    unverified = ("the DOF line's keywords (NONLIN, KE, CE, " + ", ".join(k for k, _ in ETABS_DOF_KEYS[link.kind])
                  + ")" + (" and the TYPE string" if link.kind == BILINEAR else ""))
    comments = [*comment_lines(link, provenance),
                f"{unverified} are from no public .e2k file: if ETABS refuses one, enter the values above in "
                "Define > Section Properties > Link/Support Properties"]
    lines = [f"$ File written by fvd_bridge {__version__} (not by ETABS): link property {link.name}", " ",
             "$ PROGRAM INFORMATION", f'  PROGRAM  "ETABS"  VERSION "{ETABS_VERSION}"  ', "",
             "$ CONTROLS", f"  UNITS  {etabs_units(link)}  ", "",
             "$ LINK PROPERTIES",
             f'  LINKPROP  "{link.name}"  TYPE "{link.kind.upper()}"  ',
             f'  LINKPROP  "{link.name}"  DOF "{DOF}"  NONLIN "Yes"  KE {num(link.ke)}  CE {num(link.ce)}  '
             f"{values}  ", "",
             "$ LOG", "  STARTCOMMENTS  ", *comments, "  ENDCOMMENTS  ", "",
             "  END", "$ END OF MODEL FILE"]
    return "\r\n".join(lines) + "\r\n"


#: the suffixes of the files each program imports (SAP2000: .s2k, or .$2k)
SUFFIXES = {"sap2000": (".s2k", ".$2k"), "etabs": (".e2k",)}
#: each target's writer
WRITERS = {"sap2000": to_s2k, "etabs": to_e2k}


def to_text(link: CsiLink, target: str, provenance=()) -> str:
    """The file of ``target`` ('sap2000' or 'etabs') with the link, its
    header the ``provenance`` lines (``Calibration.provenance_lines``)."""
    return WRITERS[target](link, provenance)
