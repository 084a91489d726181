"""The columns of a text table, shared by the reports that print one."""

from __future__ import annotations


def columns(head: list, rows: list, right_from: int = 1) -> list[str]:
    """Lines of a text table: the head, a rule as long as it, then the rows;
    columns as wide as their widest cell, two spaces apart, the first
    ``right_from`` left-aligned (names) and the others right-aligned (numbers)."""
    width = [max(len(str(r[k])) for r in [head, *rows]) for k in range(len(head))]

    def line(r):
        return "  ".join(f"{r[k]:<{width[k]}}" if k < right_from else f"{r[k]:>{width[k]}}"
                         for k in range(len(r))).rstrip()
    top = line(head)
    return [top, "-" * len(top), *[line(r) for r in rows]]
