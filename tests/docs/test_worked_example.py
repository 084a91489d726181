"""The worked guide page (docs/guide/worked-example.md) runs as printed and
its reading holds: its commands, taken from the page, on its series file,
taken from the page, give what the page reads from them."""

from __future__ import annotations

import json
import re
import shlex
import subprocess

import pytest

from conftest import CLI, REPO, cli_env

PAGE = REPO / "docs" / "guide" / "worked-example.md"
RECORD = "elcentro_1940_NS_2688pts_g_dt0.02.dat"


def page_commands(text: str) -> list[str]:
    """The page's shell commands (indented 'fvd-bridge ...' lines, their
    backslash continuations joined), in order."""
    commands, current = [], None
    for line in text.splitlines():
        stripped = line.strip()
        if current is not None:
            current += " " + stripped.rstrip("\\").strip()
            if not stripped.endswith("\\"):
                commands.append(current)
                current = None
        elif line.startswith("    fvd-bridge "):
            if stripped.endswith("\\"):
                current = stripped.rstrip("\\").strip()
            else:
                commands.append(stripped)
    return commands


def run(command: str, cwd, shared) -> subprocess.CompletedProcess:
    args = [str(shared / "records" / RECORD) if a == RECORD else a for a in shlex.split(command)[1:]]
    res = subprocess.run([*CLI, *args], cwd=cwd, capture_output=True, text=True, env=cli_env())
    assert res.returncode == 0, f"{command}\n{res.stderr[-2000:]}"
    return res


@pytest.mark.slow
def test_the_worked_example_runs_as_printed_and_reads_true(shared_dir, tmp_path):
    text = PAGE.read_text()
    series = re.search(r"```yaml\n(.*?)```", text, re.S).group(1)
    (tmp_path / "series.yaml").write_text(series)
    commands = page_commands(text)
    assert [c.split()[1] for c in commands] == ["campaign", "diagnose", "campaign", "frame", "frame", "export",
                                                "export"][:len(commands)]
    run(commands[0], tmp_path, shared_dir)  # 1-2. the series
    diag = run(commands[1], tmp_path, shared_dir).stdout  # 3. what law 2 misses
    assert "add series_stiffness" in diag.split("suggestion:")[1].splitlines()[0]
    # 4. the series again with the model found, as the page says
    (tmp_path / "series.yaml").write_text(series.replace("models: 2,9", "models: 2,2+series_stiffness")
                                          .replace("out: series_out", "out: series2_out"))
    again = run(commands[2], tmp_path, shared_dir).stdout
    assert "law 2+series_stiffness: 5/5 pass" in again
    bounds = json.loads((tmp_path / "series2_out" / "bounds.json").read_text())["models"]["2+series_stiffness"]
    force = next(r for r in bounds["rows"] if r["quantity"] == "F(V)")
    assert force["lambda_min"] < 1.0 < force["lambda_max"]
    as_tested = run(commands[3], tmp_path, shared_dir).stdout  # 5. as tested: a few percent of damping
    assert re.search(r"the dampers add (\d+\.?\d*)% of critical damping", as_tested)
    run(commands[4], tmp_path, shared_dir)  # 6. sized and bounded
    summary = json.loads((tmp_path / "fr_sized" / "frame_summary.json").read_text())
    achieved = {c["bound"]: c["supplemental_damping"]["achieved"] for c in summary["cases"] if c.get("bound")}
    assert achieved["nominal"] == pytest.approx(0.20, rel=0.2)
    assert achieved["lower"] < achieved["nominal"] < achieved["upper"]
    envelope = summary["bounds"]["envelope"]["2+series_stiffness"]
    assert envelope["drift"]["governing"] == "lower" and envelope["force"]["governing"] == "upper"  # as the page reads
