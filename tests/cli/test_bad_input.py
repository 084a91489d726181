"""Bad input to ``fvd-bridge inspect``: exit code 2, one stderr line naming file, row and column.

The cases the issue lists run the real CLI in a subprocess (all of them
concurrently, once per module; each test checks its own result); the further
cases run ``cli.main`` in-process, which is the same code without the start-up.
"""

from __future__ import annotations

import os
import subprocess
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest
import scipy.io

from conftest import CLI, REPO, cli_env, csv_text, sine
from fvd_bridge import cli

S = sine()  # 3 cycles, dt 0.01 s, 301 samples: sample i is on line i + 2 of a CSV with a bare header
N = S["t"].size


def cols(**changes) -> list:
    """t, d, F columns as lists of cell strings, with some cells replaced."""
    out = {k: [f"{x:.10g}" for x in S[k]] for k in ("t", "d", "F")}
    for key, (i, text) in changes.items():
        out[key][i] = text
    return [out["t"], out["d"], out["F"]]


def rows_text(header: str, columns: list, comments: tuple = ()) -> str:
    lines = [f"# {c}" for c in comments] + [header] + [",".join(r) for r in zip(*columns)]
    return "\n".join(lines) + "\n"


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(text)
    return path


def case_missing_column(f):
    return write(f, "missing.csv", rows_text("t,d,G", cols())), [], ["row 1", "column 'F'"]


def case_missing_column_after_comments(f):
    return (write(f, "missing2.csv", rows_text("t,d,G", cols(), comments=("rig", "test 4"))), [],
            ["row 3", "column 'F'"])


def case_non_numeric(f):
    return write(f, "text.csv", rows_text("t,d,F", cols(d=(5, "abc")))), [], ["row 7", "column 'd'", "'abc'"]


def case_empty_cell(f):
    return write(f, "empty_cell.csv", rows_text("t,d,F", cols(F=(10, "")))), [], ["row 12", "column 'F'", "empty"]


def case_nan(f):
    return write(f, "nan.csv", rows_text("t,d,F", cols(F=(7, "nan")))), [], ["row 9", "column 'F'", "not finite"]


def case_inf(f):
    return write(f, "inf.csv", rows_text("t,d,F", cols(d=(13, "inf")))), [], ["row 15", "column 'd'", "not finite"]


def case_time_not_increasing(f):
    c = cols()
    c[0][18] = c[0][17]
    return write(f, "time_back.csv", rows_text("t,d,F", c)), [], ["row 20", "column 't'", "does not increase"]


def case_irregular_time(f):
    t = S["t"].copy()
    t[100:] += 0.5 * 0.01  # one step of 1.5 dt, between samples 99 and 100
    text = csv_text("t,d,F", [t, S["d"], S["F"]])
    return write(f, "irregular.csv", text), [], ["row 102", "column 't'", "tolerance"]


def case_less_than_one_cycle(f):
    s = sine(n_cycles=0.6)
    return write(f, "short.csv", csv_text("t,d,F", [s["t"], s["d"], s["F"]])), [], ["column 'd'", "cycle"]


def case_constant_displacement(f):
    text = csv_text("t,disp,F", [S["t"], np.full(N, 3.0), S["F"]])
    return write(f, "const_d.csv", text), ["--columns", "d=disp"], ["column 'disp'", "constant"]


def case_constant_force(f):
    return write(f, "const_F.csv", csv_text("t,d,F", [S["t"], S["d"], np.zeros(N)])), [], ["column 'F'", "constant"]


def case_unequal_length(f):
    c = cols()
    c[2] = c[2][:-10]
    lines = ["t,d,F"] + [",".join(r) for r in zip(c[0], c[1], c[2] + [""] * 10)]
    lines = [ln.rstrip(",") for ln in lines]
    return write(f, "unequal.csv", "\n".join(lines) + "\n"), [], [f"row {N - 10 + 2}", "column 'F'", "unequal"]


def case_unequal_length_mat(f):
    path = f / "unequal.mat"
    scipy.io.savemat(path, {"dist": S["d"], "forc": S["F"][:-5], "Ts": 0.01})
    return path, ["--columns", "d=dist,F=forc"], [f"row {N - 4}", "column 'forc'", "unequal"]


def case_absurd_force(f):
    F = S["F"] * 1e3  # written in N, said to be kN (without units: tests/records/test_units_plausible.py)
    row = int(np.argmax(np.abs(F))) + 2
    return (write(f, "absurd.csv", csv_text("t,d,F", [S["t"], S["d"], F])), ["--units", "F=kN"],
            [f"row {row}", "column 'F'", "absurd"])


def case_absurd_velocity(f):
    text = csv_text("t,d,F,v", [S["t"], S["d"], S["F"], S["v"] / 1e3])  # m/s read as mm/s
    return write(f, "slow_v.csv", text), [], ["column 'v'", "units"]


def case_unknown_unit(f):
    path = write(f, "unit.csv", csv_text("t,d,F", [S["t"], S["d"], S["F"]]))
    return path, ["--units", "F=furlong"], ["F=furlong", "unknown unit 'furlong'"]


def case_malformed_sidecar(f):
    write(f, "side.yaml", "columns: {t: time, d: disp\nunits: F: N\n")
    path = write(f, "side.csv", csv_text("time,disp,F", [S["t"], S["d"], S["F"]]))
    return path, [], ["side.yaml", "row 2", "not valid YAML"]


def case_sidecar_unknown_key(f):
    write(f, "side2.yaml", "columns: {t: time, d: disp}\ncolums: {F: load}\n")
    path = write(f, "side2.csv", csv_text("time,disp,F", [S["t"], S["d"], S["F"]]))
    return path, [], ["side2.yaml", "row 2", "key 'colums'"]


def case_sidecar_bad_unit(f):
    write(f, "side3.yaml", "columns: {t: time, d: disp}\nunits:\n  F: Nm\n")
    path = write(f, "side3.csv", csv_text("time,disp,F", [S["t"], S["d"], S["F"]]))
    return path, [], ["side3.yaml", "row 3", "unknown unit 'Nm'"]


def _mat(f, name="rig.mat"):
    path = f / name
    scipy.io.savemat(path, {"x_F": np.column_stack([S["d"], S["v"], S["F"] * 1e3]), "Ts": 0.01})
    return path


def case_mat_missing_variable(f):
    return _mat(f, "nov.mat"), ["--mat-var", "xF", "--columns", "d=0,F=2"], ["variable 'xF' not found", "x_F"]


def case_mat_missing_column(f):
    return _mat(f, "nocol.mat"), ["--mat-var", "x_F", "--columns", "d=0,F=7"], ["column 7", "columns 0..2"]


def case_mat_no_mapping(f):
    return _mat(f, "nomap.mat"), [], ["say which column holds d", "--mat-var"]


def case_mat_corrupt(f):
    return write(f, "corrupt.mat", "not a matlab file\n" * 20), [], ["not a readable MATLAB file"]


def case_nonexistent(f):
    return f / "nowhere.csv", [], ["no such file"]


def case_empty_file(f):
    return write(f, "blank.csv", "\n\n"), [], ["empty file"]


def case_header_only(f):
    return write(f, "header.csv", "# c\nt,d,F\n"), [], ["row 2", "no data rows"]


def case_no_header(f):
    return write(f, "noheader.csv", csv_text("0,0,0", [S["t"], S["d"], S["F"]])), [], ["row 1", "header"]


def case_blank_and_comment_lines(f):
    lines = ["# rig A", "t,d,F", ""] + [",".join(r) for r in zip(*cols())]
    lines.insert(8, "")
    lines.insert(9, "# operator note")
    lines[30] = lines[30].split(",")[0] + ",x1," + lines[30].split(",")[2]
    return write(f, "gaps.csv", "\n".join(lines) + "\n"), [], ["row 31", "column 'd'", "'x1'"]


def case_too_few_rows(f):
    return write(f, "tiny.csv", rows_text("t,d,F", [c[:3] for c in cols()])), [], ["rows 2..4", "3 samples"]


def case_bad_sg_window(f):
    path = write(f, "sg.csv", csv_text("t,d,F", [S["t"], S["d"], S["F"]]))
    return path, ["--sg-window", "4"], ["--sg-window 4", "odd"]


def case_sg_window_too_long(f):
    path = write(f, "sg_long.csv", csv_text("t,d,F", [S["t"], S["d"], S["F"]]))
    return path, ["--sg-window", "401"], ["--sg-window 401", f"{N} samples"]


def case_plot_folder_missing(f):
    path = write(f, "plot.csv", csv_text("t,d,F", [S["t"], S["d"], S["F"]]))
    return path, ["--plot", str(f / "nowhere" / "x.png")], ["x.png", "does not exist"]


def case_plot_unknown_format(f):
    path = write(f, "plot2.csv", csv_text("t,d,F", [S["t"], S["d"], S["F"]]))
    return path, ["--plot", str(f / "x.foo")], ["x.foo", "unknown image format"]


CASES = {name[5:]: fn for name, fn in sorted(globals().items()) if name.startswith("case_")}
#: the issue's list, run as real subprocesses; the rest run in-process
SUBPROCESS = {"missing_column", "non_numeric", "nan", "time_not_increasing", "irregular_time",
              "less_than_one_cycle", "constant_displacement", "constant_force", "unequal_length",
              "absurd_force", "unknown_unit", "malformed_sidecar", "mat_missing_variable",
              "mat_missing_column", "nonexistent"}


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """Run the SUBPROCESS cases' CLI calls concurrently; {case: (path, expected, rc, stderr)}."""
    folder = tmp_path_factory.mktemp("bad_input")
    built = {name: CASES[name](folder) for name in SUBPROCESS}

    def run(item):
        name, (path, args, expected) = item
        proc = subprocess.run(CLI + ["inspect", str(path), *args], capture_output=True, text=True,
                              cwd=REPO, env=cli_env(), timeout=120)
        return name, (path, expected, proc.returncode, proc.stderr)

    with ThreadPoolExecutor(max_workers=max(2, os.cpu_count() or 2)) as pool:
        return dict(pool.map(run, built.items()))


def check(case, path, expected, rc, stderr):
    err = stderr.strip()
    assert rc == 2, (rc, err)
    assert "Traceback" not in stderr
    assert err and "\n" not in err, err
    assert err.startswith("fvd-bridge: ")
    if case != "bad_sg_window":  # the others name a file: the record, its sidecar or the figure
        named = expected[0] if "sidecar" in case or "plot" in case else Path(path).name
        assert named in err, err
    for fragment in expected:
        assert fragment in err, err


@pytest.mark.parametrize("case", sorted(SUBPROCESS))
def test_bad_input_subprocess(results, case):
    check(case, *results[case])


@pytest.mark.parametrize("case", sorted(set(CASES) - SUBPROCESS))
def test_bad_input_in_process(case, tmp_path, capsys):
    path, args, expected = CASES[case](tmp_path)
    rc = cli.main(["inspect", str(path), *args])
    captured = capsys.readouterr()
    assert captured.out == ""
    check(case, path, expected, rc, captured.err)


@pytest.mark.parametrize("verb", cli.VERBS)
def test_every_verb_prints_its_help(verb, capsys):
    """argparse formats help strings with %: a literal percent sign in one
    (say '50% of the energy') breaks ``VERB --help`` with a traceback."""
    with pytest.raises(SystemExit) as stop:
        cli.main([verb, "--help"])
    assert stop.value.code == 0
    assert f"fvd-bridge {verb}" in capsys.readouterr().out


def test_profile_lists_each_stage_inside_the_one_it_belongs_to():
    """timing: a stage is listed where it starts (an outer stage before the
    stages inside it), its seconds and runs add up, and the report's shares
    are of the total given."""
    import time as clock

    from fvd_bridge import timing

    timing.reset()
    with timing.stage("outer"):
        for _ in range(2):
            with timing.stage("  inner"):
                clock.sleep(0.01)
    timing.add("  booked", 0.5, 3)
    st = timing.stages()
    assert list(st) == ["outer", "  inner", "  booked"]
    assert st["  inner"][1] == 2 and 0.02 <= st["  inner"][0] <= st["outer"][0]
    assert st["  booked"] == (0.5, 3)
    assert "50.0%" in timing.report(1.0) and "total" in timing.report(1.0)
    timing.reset()
    assert timing.stages() == {}


def test_calibrate_profile_shows_where_the_time_went(tmp_path, capsys):
    """calibrate --profile: reading, the fits with each model's own time,
    the intervals and the outputs, after the results."""
    s = sine(n_cycles=4.0, dt=0.005)
    rng = np.random.default_rng(0)
    path = write(tmp_path, "dev.csv", csv_text("t,d,F", [s["t"], s["d"] + 0.005 * rng.standard_normal(s["t"].size),
                                                        s["F"] + 0.05 * rng.standard_normal(s["t"].size)]))
    rc = cli.main(["calibrate", str(path), "--laws", "1,2", "--runs", "2", "--intervals", "0", "--jobs", "1",
                   "--out", str(tmp_path / "out"), "--quiet", "--no-figures", "--profile"])
    assert rc == 0
    err = capsys.readouterr().err
    profile = err[err.index("profile ("):]
    for stage in ("read records, derive velocity", "fits", "law 1 (summed over workers)",
                  "law 2 (summed over workers)", "intervals", "outputs, figures", "total"):
        assert stage in profile, profile
