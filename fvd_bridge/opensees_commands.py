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


class Tag(int):
    """A material tag ``offset`` above a definition's own (0: its own): an int
    to OpenSees, 'tag + offset' in a definition function (``define``)."""

    def __new__(cls, value: int, offset: int):
        obj = super().__new__(cls, value)
        obj.offset = int(offset)
        return obj


def _literal(arg, lang: str, relative: bool = False) -> str:
    """An argument as script text; numbers (numpy's too) to full precision; a
    Tag relative to the variable ``tag`` when ``relative``."""
    if isinstance(arg, str):
        return repr(arg) if lang == "py" else arg
    if relative and isinstance(arg, Tag):
        if lang == "py":
            return "tag" if arg.offset == 0 else f"tag + {arg.offset}"
        return "$tag" if arg.offset == 0 else f"[expr {{$tag + {arg.offset}}}]"
    if isinstance(arg, numbers.Integral):
        return repr(int(arg))
    return repr(float(arg))


def _tcl_missing(commands) -> list:
    missing = sorted({c[1] for c in commands if len(c) > 1 and c[1] in NOT_IN_TCL})
    return [f"# needs {', '.join(missing)}: in OpenSeesPy and OpenSees built on its material table, "
            f"not in classic Tcl OpenSees"] if missing else []


def to_script(commands, lang: str = "py", comments=()) -> str:
    """The commands as an OpenSeesPy ('py') or Tcl ('tcl') script, after the
    ``comments`` lines (each starting with '#'); a Tcl script names the
    materials classic Tcl OpenSees lacks (NOT_IN_TCL)."""
    commands = listed(commands)
    head = list(comments)
    if lang == "py":
        lines = head + ["import openseespy.opensees as ops", ""]
        lines += [f"ops.{name}({', '.join(_literal(a, lang) for a in args)})" for name, *args in commands]
    elif lang == "tcl":
        lines = head + _tcl_missing(commands) + [" ".join([name] + [_literal(a, lang) for a in args])
                                                 for name, *args in commands]
    else:
        raise InputError(f"script language '{lang}': expected 'py' or 'tcl'")
    return "\n".join(lines) + "\n"


def define(commands, lang: str, name: str, tag: int, comments=(), doc: str = "") -> str:
    """The commands as a definition function ``name`` of the material tag
    (its helpers tag + 1 ... tag + n: the commands' Tag arguments),
    which a script run as it is calls with ``tag``.  Python: ``def
    name(ops, tag=TAG)``, called under ``if __name__ == "__main__"`` (so an
    import defines nothing until the caller calls it, after any
    ``ops.wipe()``, once per damper); Tcl: ``proc name {tag}``, called at
    the end unless ``fvd_bridge_define_only`` is set before ``source``."""
    commands = listed(commands)
    head = list(comments)
    helpers = max((a.offset for c in commands for a in c if isinstance(a, Tag)), default=0)
    taken = f"tag + 1 ... tag + {helpers}" if helpers else "none"
    if lang == "py":
        body = [f"    ops.{c}({', '.join(_literal(a, lang, True) for a in args)})" for c, *args in commands]
        lines = head + ["import openseespy.opensees as ops", "",
                        f"#: material tags the damper takes beyond its own: {taken}",
                        f"HELPER_TAGS = {helpers}", "", "",
                        f"def {name}(ops, tag={int(tag)}):",
                        f'    """{doc or "Define the damper"} as uniaxial material tag (helpers tag + 1 ... '
                        f'tag + HELPER_TAGS); returns tag."""',
                        *body, "    return tag", "", "",
                        'if __name__ == "__main__":', f"    {name}(ops)"]
    elif lang == "tcl":
        body = ["    " + " ".join([c] + [_literal(a, lang, True) for a in args]) for c, *args in commands]
        lines = head + _tcl_missing(commands) + [
            f"# material tags the damper takes beyond its own: {taken}",
            f"proc {name} {{tag}} {{", *body, "    return $tag", "}",
            f"if {{![info exists fvd_bridge_define_only]}} {{ {name} {int(tag)} }}"]
    else:
        raise InputError(f"script language '{lang}': expected 'py' or 'tcl'")
    return "\n".join(lines) + "\n"
