"""The documentation: the site builds with warnings as errors, every public
name has a docstring, the entry points document every parameter
(numpydoc), and the README stays a newcomer's page."""

from __future__ import annotations

import inspect
import re
import subprocess
import sys
from pathlib import Path

import pytest

import fvd_bridge as fb

REPO = Path(__file__).resolve().parents[2]


def public_names():
    """Every public name of ``fvd_bridge`` and the public members of its classes."""
    for name in fb.__all__:
        if name.startswith("__"):
            continue
        obj = getattr(fb, name)
        yield name, obj
        if inspect.isclass(obj):
            for member, value in vars(obj).items():
                if member.startswith("_"):
                    continue
                if isinstance(value, property):
                    yield f"{name}.{member}", value.fget
                elif callable(value) or isinstance(value, (classmethod, staticmethod)):
                    yield f"{name}.{member}", getattr(value, "__func__", value)


def test_every_public_name_has_a_docstring():
    lacking = [name for name, obj in public_names() if not inspect.getdoc(obj)]
    assert not lacking, f"no docstring: {', '.join(lacking)}"


def reference_functions():
    """The callables the API reference (docs/api.md) documents: each ``::: NAME``
    and the members listed under it."""
    import importlib
    import re

    text = (REPO / "docs" / "api.md").read_text()
    for block in re.split(r"\n(?=::: )", text)[1:]:
        path = block.split()[1]
        module, _, attr = path.rpartition(".")
        obj = getattr(importlib.import_module(module), attr)
        members = re.search(r"members: \[(.*?)\]", block)
        if inspect.isfunction(obj):
            yield path, obj
        for m in members.group(1).split(", ") if members else []:
            value = inspect.getattr_static(obj, m, None)  # a dataclass field: no function
            func = getattr(value, "__func__", value)
            if inspect.isfunction(func):
                yield f"{path}.{m}", func


def numpydoc_gaps(func) -> list:
    """What a numpydoc docstring of ``func`` lacks: a Parameters section naming every parameter."""
    names = [n for n in inspect.signature(func).parameters if n not in ("self", "cls")]
    doc = inspect.getdoc(func) or ""
    if not names:
        return [] if doc else ["a docstring"]
    if "Parameters\n----------" not in doc:
        return ["a Parameters section"]
    listed = "\n" + doc.split("Parameters\n----------", 1)[1].split("\n\n", 1)[0] + doc
    return [n for n in names if f"\n{n}" not in listed and f", {n}" not in listed]


def test_every_public_callable_documents_every_parameter():
    """The API reference's callables and every public function and method of ``dir(fb)``."""
    functions = dict(reference_functions())
    functions.update((name, obj) for name, obj in public_names() if inspect.isfunction(obj))
    gaps = {name: gap for name, func in functions.items() for gap in [numpydoc_gaps(func)] if gap}
    assert len(functions) >= 40
    assert not gaps, f"numpydoc docstrings lack: {gaps}"


def test_the_readme_is_a_newcomers_page():
    lines = (REPO / "README.md").read_text().splitlines()
    assert len(lines) <= 200
    assert "make demo" in "\n".join(lines) and "make test" in "\n".join(lines)


def test_the_site_builds_with_warnings_as_errors(tmp_path):
    pytest.importorskip("mkdocs")
    res = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")],
                         cwd=REPO, capture_output=True, text=True, timeout=300,
                         env={**__import__("os").environ, "NO_MKDOCS_2_WARNING": "1"})
    assert res.returncode == 0, res.stderr[-3000:]
    api = (tmp_path / "site" / "api" / "index.html").read_text()
    for name in ("calibrate", "diagnose", "from_arrays", "to_opensees", "to_fmu"):
        assert name in api
    index = (tmp_path / "site" / "index.html").read_text()
    assert "fonts.googleapis" not in index  # readable offline


def glued_lists(text: str) -> list[int]:
    """Line numbers of list items glued to the paragraph above them (no
    blank line between, outside code): the site's Markdown then prints the
    list as running text."""
    out, prev, code = [], "", False
    for k, line in enumerate(text.splitlines(), 1):
        if line.startswith("```"):
            code = not code
        item = re.match(r"([-*]|\d+\.) ", line)
        if item and not code and prev.strip() and not re.match(r"\s*([-*]|\d+\.) |\s", prev):
            out.append(k)
        prev = line
    return out


def test_glued_lists_are_found_and_no_page_has_one():
    assert glued_lists("**Optimizers.**\n- `ga`: the GA\n- `de`\n\ntext\n\n- item\n") == [2]
    pages = sorted((REPO / "docs").rglob("*.md"))
    glued = {str(p.relative_to(REPO)): glued_lists(p.read_text()) for p in pages}
    assert pages and not {p: lines for p, lines in glued.items() if lines}
