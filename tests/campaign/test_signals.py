"""SIGTERM (a batch system's time limit) ends a run cleanly: every worker
process it started ends with it, nothing partial is written, nothing leaks."""

from __future__ import annotations

import os
import signal
import subprocess
import time

import pytest

from conftest import CLI, cli_env


def _children(pid: int) -> set[int]:
    """Every live descendant of ``pid`` (from /proc)."""
    parent = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as fh:
                    parent[int(entry)] = int(fh.read().rsplit(")", 1)[1].split()[1])
            except OSError:
                continue
    out, todo = set(), [pid]
    while todo:
        p = todo.pop()
        kids = {c for c, pp in parent.items() if pp == p}
        out |= kids
        todo += list(kids)
    return out


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


@pytest.mark.skipif(not os.path.isdir("/proc"), reason="reads the process tree from /proc")
def test_sigterm_stops_every_worker_and_writes_nothing(tmp_path):
    rig = subprocess.run([*CLI, "rig", "--out", str(tmp_path / "rec"), "--demo", "--devices", "2"],
                         capture_output=True, text=True, env=cli_env())
    assert rig.returncode == 0, rig.stderr
    out = tmp_path / "cal"
    records = sorted(str(p) for p in (tmp_path / "rec").glob("*.csv"))
    proc = subprocess.Popen([*CLI, "calibrate", *records, "--laws", "6,7,9", "--runs", "20",
                             "--jobs", "2", "--intervals", "0", "--no-figures", "--out", str(out)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=cli_env())
    workers: set[int] = set()
    deadline = time.time() + 120
    while time.time() < deadline and len(workers) < 3:  # the forkserver and two workers
        workers |= _children(proc.pid)
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.2)
    assert len(workers) >= 3, "the pool did not start"
    time.sleep(1.0)  # tasks running
    proc.send_signal(signal.SIGTERM)
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 143, stderr[-2000:]
    assert "terminated (SIGTERM)" in stderr and "Traceback" not in stderr
    assert "leaked semaphore" not in stderr
    time.sleep(0.5)
    assert not [pid for pid in workers if _alive(pid)]
    assert not out.exists() or not any(out.iterdir())


@pytest.mark.slow
@pytest.mark.skipif(not os.path.isdir("/proc"), reason="reads the process tree from /proc")
def test_sigterm_stops_a_dask_campaign(tmp_path):
    """The same with a Dask LocalCluster the campaign started: its worker
    processes end with the run; the unit store keeps what finished."""
    pytest.importorskip("distributed")
    (tmp_path / "c.yaml").write_text(
        "rig: {devices: 2, nominal: {C: 45.4, alpha: 0.3, Ks: 150}, protocol: {name: paper, cycles: 3}, seed: 0}\n"
        "models: 6,7,9\nruns: 20\nout: out\njobs: 2\nintervals: 0\nno_figures: true\nexecutor: dask\n")
    proc = subprocess.Popen([*CLI, "campaign", str(tmp_path / "c.yaml")], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=cli_env(), cwd=tmp_path)
    workers: set[int] = set()
    deadline = time.time() + 180
    while time.time() < deadline and not (tmp_path / "out" / ".units").is_dir():
        workers |= _children(proc.pid)
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.5)
    time.sleep(3.0)  # units running on the workers
    workers |= _children(proc.pid)
    assert len(workers) >= 2, "the cluster did not start"
    proc.send_signal(signal.SIGTERM)
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 143, stderr[-2000:]
    assert "terminated (SIGTERM)" in stderr and "Traceback" not in stderr
    time.sleep(1.0)
    assert not [pid for pid in workers if _alive(pid)]
