"""OpenSees models as data: lists of command tuples (ops function name, *args).

The damper export (``export.opensees``) and the frames (``frames.model``)
produce such lists; two thin layers use them: ``apply`` defines them in an
OpenSees module (openseespy: ops.<name>(*args)), ``to_script`` writes them as
an OpenSeesPy or Tcl script that runs without fvd_bridge.
"""

from __future__ import annotations

import numbers

from .errors import InputError

#: materials of OpenSeesPy's table that classic Tcl OpenSees lacks
NOT_IN_TCL = ("TensionOnly",)


def listed(commands) -> list:
    """The command tuples: the given list of them, or those an object holds
    in ``commands`` (an ``export.opensees.Export``)."""
    held = getattr(commands, "commands", None)
    return list(commands if held is None else held)


def apply(commands, ops) -> None:
    """Define the commands in an OpenSees module: ops.<name>(*args)."""
    for name, *args in listed(commands):
        getattr(ops, name)(*args)


def _literal(arg, lang: str) -> str:
    """An argument as script text; numbers (numpy's too) to full precision."""
    if isinstance(arg, str):
        return repr(arg) if lang == "py" else arg
    if isinstance(arg, numbers.Integral):
        return repr(int(arg))
    return repr(float(arg))


def to_script(commands, lang: str = "py", comments=()) -> str:
    """The commands as an OpenSeesPy ('py') or Tcl ('tcl') script, after the
    ``comments`` lines (each starting with '#'); a Tcl script names the
    materials classic Tcl OpenSees lacks (NOT_IN_TCL)."""
    commands = listed(commands)
    head = list(comments)
    missing = sorted({c[1] for c in commands if len(c) > 1 and c[1] in NOT_IN_TCL})
    if lang == "tcl" and missing:
        head.append(f"# needs {', '.join(missing)}: in OpenSeesPy and OpenSees built on its material table, "
                    f"not in classic Tcl OpenSees")
    if lang == "py":
        lines = head + ["import openseespy.opensees as ops", ""]
        lines += [f"ops.{name}({', '.join(_literal(a, lang) for a in args)})" for name, *args in commands]
    elif lang == "tcl":
        lines = head + [" ".join([name] + [_literal(a, lang) for a in args]) for name, *args in commands]
    else:
        raise InputError(f"script language '{lang}': expected 'py' or 'tcl'")
    return "\n".join(lines) + "\n"
