"""The developer pages (docs/develop/new-effect.md, new-export-target.md)
follow the code: every file path they cite exists, every code name they cite
(``fvd_bridge.x.y``, ``model.EXPORT_TARGETS``, ``Model.exports``, a test
``path::name``) resolves, every excerpt marked ``# from PATH`` is still in
that file, line for line and in order, and both pages are in mkdocs.yml's
nav under "Developing", before the API reference."""

from __future__ import annotations

import dataclasses
import importlib
import pkgutil
import re
from pathlib import Path

import pytest
import yaml

import fvd_bridge

REPO = Path(__file__).resolve().parents[2]
PAGES = ("docs/develop/new-effect.md", "docs/develop/new-export-target.md")

#: short class names the pages use, and where they live
CLASSES = {"Model": "fvd_bridge.model.Model", "Effect": "fvd_bridge.effects.base.Effect",
           "Law": "fvd_bridge.laws.base.Law", "OpenSeesForm": "fvd_bridge.laws.base.OpenSeesForm",
           "Parameter": "fvd_bridge.laws.base.Parameter", "Size": "fvd_bridge.effects.base.Size",
           "Calibration": "fvd_bridge.calibration.Calibration", "Catalog": "fvd_bridge.catalog.Catalog",
           "Diagnosis": "fvd_bridge.diagnose.core.Diagnosis"}
#: a dotted token ending in one of these is a file name (`damper.json`, `effects.c`), not a code name
FILE_SUFFIXES = {"py", "c", "h", "md", "yml", "yaml", "csv", "json", "html", "xml", "fmu", "s2k", "e2k", "tcl",
                 "png", "txt", "toml"}
#: the top-level modules and subpackages of fvd_bridge (``model``, ``effects``, ``export``, ...)
TOP = {m.name for m in pkgutil.iter_modules(fvd_bridge.__path__)}

PATH = re.compile(r"^[\w.-]+(/[\w.$+-]+)*/?$")
DOTTED = re.compile(r"^[A-Za-z_]\w*(\.[A-Za-z_]\w*)+(\(\))?$")


def text(page: str) -> str:
    return (REPO / page).read_text()


def prose(page: str) -> str:
    """The page without its fenced code blocks."""
    return re.sub(r"^\s*```.*?^\s*```", "", text(page), flags=re.S | re.M)


def inline_code(page: str) -> list[str]:
    return re.findall(r"`([^`\n]+)`", prose(page))


def cited_paths(page: str) -> list[str]:
    """Repository paths in inline code: tokens with a '/' (placeholders such as
    `fvd_bridge/export/<target>.py`, a file still to be written, are not paths);
    a test may be named as `path::function`."""
    out = []
    for token in inline_code(page):
        path = token.split("::")[0]
        if "/" in path and PATH.match(path) and not path.startswith(("/", "http")):
            out.append(token)
    return out


def resolve(name: str):
    """The object a dotted code name names, or raise."""
    parts = name.removesuffix("()").split(".")
    if parts[0] in CLASSES:
        parts = CLASSES[parts[0]].split(".") + parts[1:]
    elif parts[0] != "fvd_bridge":
        parts = ["fvd_bridge"] + parts
    for cut in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except ModuleNotFoundError:
            continue
        for attr in parts[cut:]:
            if hasattr(obj, attr):
                obj = getattr(obj, attr)
            elif dataclasses.is_dataclass(obj) and attr in {f.name for f in dataclasses.fields(obj)}:
                obj = None  # a dataclass field without a default: no class attribute, but it exists
            else:
                raise AttributeError(f"{'.'.join(parts)}: no '{attr}'")
        return obj
    raise ModuleNotFoundError(name)


def cited_names(page: str) -> list[str]:
    """Dotted code names in inline code: those starting with fvd_bridge, one of
    its modules or a class in CLASSES (`friction.Ff`, a parameter, and
    `damper.json`, a file, are neither)."""
    out = []
    for token in inline_code(page):
        if not DOTTED.match(token):
            continue
        head, last = token.split(".")[0], token.removesuffix("()").split(".")[-1]
        if last in FILE_SUFFIXES:
            continue
        if head == "fvd_bridge" or head in TOP or head in CLASSES:
            out.append(token)
    return out


def excerpts(page: str) -> list[tuple[str, list[str]]]:
    """(path, lines) of each fenced block whose first line is `# from PATH` or
    `/* from PATH */`; lines stripped, blank ones and `...` left out."""
    out = []
    for block in re.findall(r"^[ \t]*```[^\n]*\n(.*?)^[ \t]*```", text(page), flags=re.S | re.M):
        lines = [line.strip() for line in block.splitlines()]
        head = re.fullmatch(r"(?:#|/\*) from (\S+?)(?: \*/)?", lines[0]) if lines else None
        if head:
            out.append((head.group(1), [line for line in lines[1:] if line and line != "..."]))
    return out


def in_order(lines: list[str], source: list[str]) -> str:
    """'' when ``lines`` occur in ``source`` in this order, else the first that does not."""
    k = 0
    for line in lines:
        try:
            k = source.index(line, k) + 1
        except ValueError:
            return line
    return ""


@pytest.mark.parametrize("page", PAGES)
def test_every_cited_path_exists(page):
    paths = cited_paths(page)
    assert len(paths) >= 15, paths  # the page names its files, and this finds them
    missing = [p for p in paths if not (REPO / p.split("::")[0]).exists()]
    assert not missing, f"{page} cites files that do not exist: {missing}"
    for token in (p for p in paths if "::" in p):
        path, function = token.split("::")
        assert re.search(rf"^def {function}\(", (REPO / path).read_text(), re.M), f"{page}: {token} is gone"


@pytest.mark.parametrize("page", PAGES)
def test_every_cited_code_name_exists(page):
    names = cited_names(page)
    assert len(names) >= 10, names
    gone = []
    for name in names:
        try:
            resolve(name)
        except (ImportError, AttributeError) as exc:
            gone.append(f"{name} ({exc})")
    assert not gone, f"{page} cites names that do not exist: {gone}"


@pytest.mark.parametrize("page", PAGES)
def test_every_excerpt_is_still_in_its_file(page):
    blocks = excerpts(page)
    assert len(blocks) >= 5
    for path, lines in blocks:
        source = [line.strip() for line in (REPO / path).read_text().splitlines()]
        stale = in_order(lines, source)
        assert not stale, f"{page}: the excerpt of {path} has a line no longer there (in this order): {stale!r}"


def test_the_checks_find_what_they_look_for():
    """The helpers on a made-up page: a path, a placeholder, names, a stale excerpt."""
    assert resolve("model.EXPORT_TARGETS") is importlib.import_module("fvd_bridge.model").EXPORT_TARGETS
    assert resolve("Effect.name") is None and callable(resolve("Model.exports()"))
    with pytest.raises(AttributeError):
        resolve("fvd_bridge.model.NO_SUCH_NAME")
    assert in_order(["a", "c"], ["a", "b", "c"]) == "" and in_order(["c", "a"], ["a", "b", "c"]) == "a"


def test_both_pages_are_in_the_nav_before_the_api_reference():
    nav = yaml.safe_load((REPO / "mkdocs.yml").read_text())["nav"]
    titles = [next(iter(item)) for item in nav]
    assert "Developing" in titles and titles.index("Developing") < titles.index("API reference")
    section = nav[titles.index("Developing")]["Developing"]
    assert sorted(next(iter(item.values())) for item in section) == sorted(p.removeprefix("docs/") for p in PAGES)
