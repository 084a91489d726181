"""Calls read without the signature: no function outside the numba kernels
takes more than MAX_POSITIONAL positional parameters (the rest are
keyword-only, after ``*``), and no numba kernel more than MAX_KERNEL
parameters (it takes its values packed: arrays and tuples read by named
indices, as ``laws/differential.py`` and ``effects/connection.py`` do).
Read from the source with ``ast``, so a new long signature anywhere in the
package fails here."""

from __future__ import annotations

import ast
from pathlib import Path

import fvd_bridge

MAX_POSITIONAL = 8
MAX_KERNEL = 12
#: decorators of the numba kernels and their scalar step forms
KERNEL_DECORATORS = ("njit", "jit", "scalar", "vectorize", "parallel_driver")


def _functions():
    """(path relative to the package, function node, is a kernel) of every function in the package."""
    root = Path(fvd_bridge.__file__).parent
    for path in sorted(root.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                kernel = any(k in ast.unparse(d) for d in node.decorator_list for k in KERNEL_DECORATORS)
                yield path.relative_to(root), node, kernel


def _long_signatures() -> list[str]:
    found = []
    for path, node, kernel in _functions():
        positional = [a for a in node.args.posonlyargs + node.args.args if a.arg not in ("self", "cls")]
        if not kernel and len(positional) > MAX_POSITIONAL:
            found.append(f"{path}:{node.lineno} {node.name} ({len(positional)})")
    return found


def _long_kernels() -> list[str]:
    found = []
    for path, node, kernel in _functions():
        n = len(node.args.posonlyargs + node.args.args + node.args.kwonlyargs)
        if kernel and n > MAX_KERNEL:
            found.append(f"{path}:{node.lineno} {node.name} ({n})")
    return found


def _package(tmp_path, monkeypatch, source: str) -> None:
    """Point the checks at a package of one module, ``source``."""
    package = tmp_path / "pkg"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "m.py").write_text(source)
    monkeypatch.setattr(fvd_bridge, "__file__", str(package / "__init__.py"))


def test_no_function_takes_more_than_eight_positional_parameters():
    assert _long_signatures() == []


def test_the_check_sees_a_long_signature(tmp_path, monkeypatch):
    """The check itself: a module with a nine-parameter function is found, a kernel is not."""
    _package(tmp_path, monkeypatch, "from numba import njit\n\n"
                                    "def long(a, b, c, d, e, f, g, h, i):\n    pass\n\n"
                                    "@njit\ndef kernel(a, b, c, d, e, f, g, h, i):\n    pass\n\n"
                                    "def fine(a, b, *, c, d, e, f, g, h, i):\n    pass\n")
    assert [s.split(" ")[1] for s in _long_signatures()] == ["long"]


def test_no_numba_kernel_takes_more_than_twelve_parameters():
    assert _long_kernels() == []


def test_the_check_sees_a_kernel_with_many_parameters(tmp_path, monkeypatch):
    """The check itself: a thirteen-parameter kernel is found, one of twelve
    and a plain function of thirteen (keyword-only) are not."""
    args = ", ".join(f"a{k}" for k in range(13))
    _package(tmp_path, monkeypatch, "from numba import njit, prange\n\n"
                                    f"@njit(parallel=True, cache=True)\ndef packed_not({args}):\n    pass\n\n"
                                    f"@njit\ndef packed({args[:args.rindex(',')]}):\n    pass\n\n"
                                    f"def plain(*, {args}):\n    pass\n")
    assert [s.split(" ")[1] for s in _long_kernels()] == ["packed_not"]
