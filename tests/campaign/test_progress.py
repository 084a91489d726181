"""Progress in a log: whole lines, no carriage returns."""

from __future__ import annotations

import io
import subprocess

import numpy as np

from conftest import CLI, cli_env
from fvd_bridge import progress


def test_a_log_gets_whole_lines_at_most_every_interval(monkeypatch):
    """100 updates within one interval give one line (the last); with the
    interval at 0 every update gives a line and the close adds no copy of
    the last; none holds a carriage return."""
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
    lines = out.getvalue().splitlines()  # a line per update; the close repeats none of them
    assert len(lines) == 5 and len(set(lines)) == 5 and "\r" not in out.getvalue()


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


def _report_and_fail(label):
    """A worker's task: one progress report, then bad input in the caller's words."""
    import time

    from fvd_bridge.calibration import news
    from fvd_bridge.errors import InputError, option

    report = news.reporter(label)
    assert report is not None, "the worker has no news queue"
    report(7, 0.25)
    # the queue's feeder thread sends the news a moment later; a failed task
    # ends the pool at once (executors.stop), which may drop news not yet
    # sent (it is progress, best effort): give the feeder time to send it
    time.sleep(0.5)
    raise InputError(f"{option('--plugin', 'x.py')}: no such file")


def test_workers_report_progress_and_speak_the_callers_words():
    """A Processes worker sends its fit's news to the campaign's Listener,
    and an InputError raised in it names the command line's option under
    the CLI, the Python argument otherwise."""
    import contextlib
    import time

    import pytest
    from fvd_bridge.campaign.executors import Processes
    from fvd_bridge.calibration.news import Listener
    from fvd_bridge.errors import InputError, command_line_words

    for words, expected in ((command_line_words, "--plugin x.py: no such file"),
                            (contextlib.nullcontext, "plugins=['x.py']: no such file")):
        shown, ex = [], Processes(2)
        with words(), Listener(ex.news, shown.append):
            with pytest.raises(InputError) as err:
                list(ex.run(_report_and_fail, [("a",), ("b",)]))
            deadline = time.monotonic() + 10.0
            while not shown and time.monotonic() < deadline:
                time.sleep(0.05)
        assert str(err.value) == expected
        assert shown and shown[0] in ("a: step 7, OF 0.25", "b: step 7, OF 0.25"), shown


def test_news_between_updates_reaches_a_log(monkeypatch):
    """A fit's news (set_postfix_str) gives a log line of its own, with the last description."""
    monkeypatch.setattr(progress, "LOG_EVERY_S", 0.0)
    out = io.StringIO()
    bar = progress.bar(2, stream=out, desc="fits")
    bar.set_postfix_str("device_01/law9+gap/run0000: step 40, OF 0.0973")
    assert out.getvalue().splitlines() == ["fits: 0/2 fits, 0 s | device_01/law9+gap/run0000: step 40, OF 0.0973"]


def _flood(label):
    """A worker's task that reports far more than a pipe holds (64 kB), with no one reading."""
    from fvd_bridge.calibration import news

    news.EVERY_S = 0.0
    report = news.reporter(label)
    for step in range(20000):
        report(step, 0.5)
    return label


def test_a_pool_whose_news_nobody_reads_still_ends():
    """Workers given a news queue that no Listener drains exit at the pool's
    end: the run returns instead of waiting on a full pipe forever."""
    import threading

    from fvd_bridge.campaign.executors import Processes

    ex = Processes(2)
    ex.news  # a queue the workers get, which nobody reads
    done = []
    worker = threading.Thread(target=lambda: done.extend(r for _, r in ex.run(_flood, [("a",), ("b",)])),
                              daemon=True)
    worker.start()
    worker.join(timeout=120)
    assert not worker.is_alive(), "the pool hung on its unread news"
    assert sorted(done) == ["a", "b"]
