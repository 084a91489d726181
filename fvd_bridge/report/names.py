"""Names for people: a lab's long names cut to the part that tells them apart.

A series' devices are often named alike ('ARTS-BRFD-series-2026-unit-0042-lab-B',
'...-unit-0043-lab-B'); a table that repeats the whole name in every row runs
past the page.  ``distinct`` keeps the part that differs (cut at separators,
'…' where a common part was left out) and ``common_form`` names the common
part once ('ARTS-BRFD-series-2026-unit-…-lab-B').
"""

from __future__ import annotations

import os

#: where a name may be cut
SEPARATORS = "-_. /|+"
#: shorten only when it saves at least this many characters
SAVES = 8
#: the mark of a part left out
ELLIPSIS = "…"


def _common_ends(names: list[str]) -> tuple[str, str]:
    """The common prefix and suffix of ``names``, each ending (starting) at a separator."""
    prefix = os.path.commonprefix(names)
    prefix = prefix[:max(prefix.rfind(c) for c in SEPARATORS) + 1]
    if any(len(n) == len(prefix) for n in names):  # a name is the common part itself: nothing to cut
        prefix = ""
    rest = [n[len(prefix):] for n in names]
    suffix = os.path.commonprefix([r[::-1] for r in rest])[::-1]
    cut = min((suffix.find(c) for c in SEPARATORS if c in suffix), default=len(suffix))
    suffix = suffix[cut:]
    if any(len(r) == len(suffix) for r in rest):
        suffix = ""
    return prefix, suffix


def distinct(names) -> dict:
    """{name: the part of it that differs from the others}: the common prefix
    and suffix (cut at separators) left out and marked '…'; the names as they
    are when they are alike, single, or shortening saves little."""
    names = list(dict.fromkeys(n for n in names if n))
    if len(names) < 2:
        return {n: n for n in names}
    prefix, suffix = _common_ends(names)
    if len(prefix) + len(suffix) < SAVES:
        return {n: n for n in names}
    return {n: (ELLIPSIS if prefix else "") + n[len(prefix):len(n) - len(suffix)] + (ELLIPSIS if suffix else "")
            for n in names}


def common_form(names) -> str:
    """'ARTS-BRFD-series-2026-unit-…-lab-B': the names' common part with '…'
    for the part that differs (``distinct``); the name itself for one."""
    names = list(dict.fromkeys(n for n in names if n))
    if len(names) == 1:
        return names[0]
    prefix, suffix = _common_ends(names)
    if len(prefix) + len(suffix) < SAVES:
        return ", ".join(names)
    return f"{prefix}{ELLIPSIS}{suffix}"
