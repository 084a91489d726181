"""Progress in a log: whole lines, no carriage returns."""

from __future__ import annotations

import io
import subprocess

import numpy as np

from conftest import CLI, cli_env
from fvd_bridge import progress


def test_a_log_gets_whole_lines_at_most_every_interval(monkeypatch):
    """100 updates within one interval give one line (the last); with the
    interval at 0 every update gives a line; none holds a carriage return."""
    out = io.StringIO()
    bar = progress.bar(100, unit="fit", desc="runs", stream=out)
    for k in range(100):
        bar.set_description(f"best OF {1.0 / (k + 1):.3f}")
        bar.update()
    bar.close()
    assert out.getvalue().splitlines() == [out.getvalue().strip()] and "runs: 100/100 fits" in out.getvalue()
    monkeypatch.setattr(progress, "LOG_EVERY_S", 0.0)
    out = io.StringIO()
    bar = progress.bar(5, stream=out)
    for _ in range(5):
        bar.update()
    bar.close()
    assert len(out.getvalue().splitlines()) == 6 and "\r" not in out.getvalue()


def test_calibrate_into_a_log_file_writes_no_carriage_return(tmp_path):
    t = np.arange(0.0, 4.0, 0.01)
    path = tmp_path / "r.csv"
    np.savetxt(path, np.column_stack([t, 10.0 * np.sin(3.0 * t), 20.0 * np.cos(3.0 * t)]), delimiter=",",
               header="t,d,F", comments="")
    with open(tmp_path / "log.txt", "w") as log:
        rc = subprocess.run([*CLI, "calibrate", str(path), "--laws", "1", "--runs", "3", "--intervals", "4",
                             "--out", str(tmp_path / "o")], stdout=log, stderr=log, env=cli_env()).returncode
    text = (tmp_path / "log.txt").read_text()
    assert rc == 0 and "\r" not in text and "2/2 fits" in text, text  # the first 2 runs agree: 2 of 3 made
