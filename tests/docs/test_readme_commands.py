"""The README's shell block, pasted into a shell as a newcomer would after
``make test``: every line runs (exit 0) from a folder of its own, with the
activation line it gives first (the commands need no file the package does
not ship)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


def shell_block() -> list[str]:
    """The README's 'In the shell' block, a command per line (continuations joined, comments cut)."""
    text = (REPO / "README.md").read_text()
    section = text.split("## In the shell", 1)[1].split("\n## ", 1)[0]
    block = re.search(r"\n\n((?:    .*\n)+)", section).group(1)
    joined = re.sub(r"\\\n\s*", " ", block)
    return [line.strip().split("  #")[0].strip() for line in joined.splitlines() if line.strip()]


def test_the_shell_block_starts_by_activating_the_environment():
    lines = shell_block()
    assert lines[0] == "source .venv/bin/activate"
    assert all(line.startswith("fvd-bridge ") for line in lines[1:])


@pytest.mark.slow
def test_every_readme_command_runs(tmp_path):
    """Each line in turn, in one shell, in a fresh folder: the activation
    line points at the environment running the tests (the clone's .venv)."""
    lines = shell_block()
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH",)}
    activate = Path(sys.prefix) / "bin" / "activate"
    script = [f"source {activate}"] + [f"{line} || {{ echo 'FAILED: {line}' >&2; exit 1; }}" for line in lines[1:]]
    res = subprocess.run(["bash", "-c", "\n".join(script)], cwd=tmp_path, env=env, capture_output=True, text=True,
                         timeout=1800)
    assert res.returncode == 0, res.stderr[-3000:]
    assert "Traceback" not in res.stderr
    assert (tmp_path / "damper.py").is_file() and (tmp_path / "damper.fmu").is_file()
    assert (tmp_path / "fr" / "report.html").is_file() or any((tmp_path / "fr").iterdir())
