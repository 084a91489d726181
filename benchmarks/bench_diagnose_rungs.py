"""The ``next:`` ladder as a user climbs it: one ``fvd-bridge diagnose`` per rung.

From ``--law`` on ``--record`` (default the shared friction damper's 1 Hz
test, 10,241 samples, law 9), run the diagnosis, then the ``next:
fvd-bridge diagnose ...`` line it prints (the model with the effect it
suggests), and again, ``--rungs`` times: each rung a whole command (start-up,
reading, the diagnosis and its calibration files with their intervals,
figures), timed from outside in wall seconds and in CPU seconds (user +
system of the command; the CPU figure moves less with the machine's load).
The target is 3 minutes a rung.

``--vs TREE`` runs the same rungs with the package of another source tree
(e.g. a ``git worktree`` of the commit before) in turn with this one, rung
by rung (A B, A B, ...): the ratio of the two is taken on a machine in one
state.  Each command's output, with its ``--profile`` table (the time of
each stage), goes to a log beside its results (``--out``).

    python benchmarks/bench_diagnose_rungs.py [--rungs 3] [--law 9] [--vs ../before]
"""

from __future__ import annotations

import argparse
import os
import re
import resource
import shlex
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import fvd_bridge

HERE = Path(fvd_bridge.__file__).resolve().parents[1]
RECORD = HERE / ".." / "shared" / "devices" / "arts_brfd_1Hz_35lb.csv"
TARGET_S = 180.0
NEXT = re.compile(r"^next: fvd-bridge diagnose (.+)$", re.M)
OF = re.compile(r"with model (\S+): OF ([0-9.eE+-]+)")


def run(tree: Path, args: list[str], log: Path) -> tuple[float, float, str]:
    """(wall s, CPU s, stdout) of ``fvd-bridge ARGS`` with the package of ``tree``."""
    env = dict(os.environ, PYTHONPATH=str(tree))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", "from fvd_bridge.cli import entry; entry()", *args],
                         env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    log.write_text(f"$ fvd-bridge {shlex.join(args)}\n{out.stdout}\n{out.stderr}")
    if out.returncode:
        raise SystemExit(f"fvd-bridge {shlex.join(args)} (tree {tree}) exited {out.returncode}: see {log}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, out.stdout


def next_args(stdout: str, out: Path) -> list[str] | None:
    """The arguments of the ``next: fvd-bridge diagnose`` line, its --out replaced by ``out``."""
    found = NEXT.search(stdout)
    if found is None:
        return None
    words = shlex.split(found.group(1))
    if "--out" in words:
        k = words.index("--out")
        del words[k:k + 2]
    return ["diagnose", *words, "--out", str(out), "--profile"]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--record", default=str(RECORD))
    ap.add_argument("--law", default="9")
    ap.add_argument("--rungs", type=int, default=3)
    ap.add_argument("--vs", metavar="TREE", help="another source tree, timed in turn with this one")
    ap.add_argument("--out", help="folder of the rungs' results and logs (default: a new temporary one)")
    args = ap.parse_args()
    out = Path(args.out or tempfile.mkdtemp(prefix="fvd_rungs_"))
    trees = {"this": HERE} | ({"vs": Path(args.vs).resolve()} if args.vs else {})
    print(f"{Path(args.record).name}, from law {args.law}, {args.rungs} rungs; {os.cpu_count()} cores; "
          f"trees: {', '.join(f'{k} {v}' for k, v in trees.items())}; results in {out}\n")
    print(f"{'rung':>4} {'tree':>5} {'model':>22} {'OF':>8} {'wall s':>8} {'CPU s':>8}  next")
    todo = {name: ["diagnose", args.record, "--law", args.law, "--out", str(out / name / "rung1"), "--profile"]
            for name in trees}
    walls: dict = {name: [] for name in trees}
    for rung in range(1, args.rungs + 1):
        for name, tree in trees.items():
            if todo[name] is None:
                continue
            folder = out / name / f"rung{rung}"
            folder.mkdir(parents=True, exist_ok=True)
            wall, cpu, stdout = run(tree, todo[name], folder / "log.txt")
            model, of = OF.search(stdout).groups() if OF.search(stdout) else ("?", "nan")
            todo[name] = next_args(stdout, out / name / f"rung{rung + 1}")
            walls[name].append(wall)
            nxt = " ".join(todo[name][3:4]) if todo[name] else "(none)"
            print(f"{rung:4d} {name:>5} {model:>22} {float(of):8.4f} {wall:8.1f} {cpu:8.1f}  "
                  f"{'--law ' + nxt if todo[name] else nxt}", flush=True)
    for name in trees:
        w = walls[name]
        print(f"\n{name}: {len(w)} rungs, {sum(w):.0f} s wall; slowest rung {max(w):.0f} s "
              f"(target {TARGET_S:.0f} s a rung)")
    if args.vs:
        pairs = list(zip(walls["this"], walls["vs"]))
        print("this / vs, rung by rung: " + ", ".join(f"{a / b:.2f}" for a, b in pairs))


if __name__ == "__main__":
    main()
