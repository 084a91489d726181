"""Calls read without the signature: no function outside the numba kernels
takes more than MAX_POSITIONAL positional parameters (the rest are
keyword-only, after ``*``).  Read from the source with ``ast``, so a new
long positional signature anywhere in the package fails here."""

from __future__ import annotations

import ast
from pathlib import Path

import fvd_bridge

MAX_POSITIONAL = 8
#: decorators of the numba kernels and their scalar step forms (packed arrays are their own matter)
KERNEL_DECORATORS = ("njit", "jit", "scalar", "vectorize", "parallel_driver")


def _long_signatures() -> list[str]:
    root = Path(fvd_bridge.__file__).parent
    found = []
    for path in sorted(root.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            if any(k in ast.unparse(d) for d in node.decorator_list for k in KERNEL_DECORATORS):
                continue
            positional = [a for a in node.args.posonlyargs + node.args.args if a.arg not in ("self", "cls")]
            if len(positional) > MAX_POSITIONAL:
                found.append(f"{path.relative_to(root)}:{node.lineno} {node.name} ({len(positional)})")
    return found


def test_no_function_takes_more_than_eight_positional_parameters():
    assert _long_signatures() == []


def test_the_check_sees_a_long_signature(tmp_path, monkeypatch):
    """The check itself: a module with a nine-parameter function is found, a kernel is not."""
    package = tmp_path / "pkg"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "m.py").write_text("from numba import njit\n\n"
                                  "def long(a, b, c, d, e, f, g, h, i):\n    pass\n\n"
                                  "@njit\ndef kernel(a, b, c, d, e, f, g, h, i):\n    pass\n\n"
                                  "def fine(a, b, *, c, d, e, f, g, h, i):\n    pass\n")
    monkeypatch.setattr(fvd_bridge, "__file__", str(package / "__init__.py"))
    assert [s.split(" ")[1] for s in _long_signatures()] == ["long"]
