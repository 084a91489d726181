"""Records: readers (CSV, sidecar, .mat), units, velocity, cycles, noise, resampling, inspect."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import scipy.io

from conftest import sine
from fvd_bridge import cli
from fvd_bridge.errors import InputError
from fvd_bridge.records import ReadOptions, Record, RecordWarning, read_record, summarize
from fvd_bridge.records.cycles import count_cycles, force_noise
from fvd_bridge.records.velocity import differentiate
from fvd_bridge.units import factor


def read_quiet(path, opts=None):
    """read_record with RecordWarnings turned into errors: the record must be clean."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", RecordWarning)
        return read_record(str(path), opts)


# --- CSV ------------------------------------------------------------------

def test_csv_canonical(write_csv):
    s = sine()
    path = write_csv("run.csv", "t,d,F", [s["t"], s["d"], s["F"]], comments=("rig A", "300 kN"))
    rec = read_quiet(path)
    assert rec.name == "run" and rec.n == s["t"].size
    assert rec.dt == pytest.approx(0.01)
    np.testing.assert_allclose(rec.d, s["d"], atol=1e-8)
    np.testing.assert_allclose(rec.F, s["F"], atol=1e-8)
    assert rec.provenance["units"] == {"t": "s", "d": "mm", "F": "kN"}
    assert rec.provenance["rows"] == [4, 3 + rec.n]  # 2 comments + header, then data from line 4
    vel = rec.provenance["velocity"]
    assert vel["method"] == "savgol" and vel["window"] % 2 == 1 and vel["polyorder"] == 3
    assert rec.warnings == []


def test_csv_measured_velocity(write_csv):
    s = sine()
    path = write_csv("run.csv", "t,d,F,v", [s["t"], s["d"], s["F"], s["v"]])
    rec = read_quiet(path)
    assert rec.provenance["velocity"]["method"] == "measured"
    np.testing.assert_allclose(rec.v, s["v"], atol=1e-8)


def test_csv_other_names_and_units_by_options(write_csv):
    s = sine()
    path = write_csv("lab.csv", "time,disp,load",
                     [s["t"] * 1e3, s["d"] * 1e-3, s["F"] * 1e3])  # ms, m, N
    rec = read_quiet(path, ReadOptions(columns={"t": "time", "d": "disp", "F": "load"},
                                       units={"t": "ms", "d": "m", "F": "N"}))
    np.testing.assert_allclose(rec.t, s["t"], atol=1e-12)
    np.testing.assert_allclose(rec.d, s["d"], atol=1e-8)
    np.testing.assert_allclose(rec.F, s["F"], atol=1e-7)
    assert rec.provenance["columns"]["F"] == "load"
    assert rec.provenance["factors"]["F"] == pytest.approx(1e-3)


def test_csv_other_names_and_units_by_sidecar(tmp_path, write_csv):
    s = sine()
    path = write_csv("lab.csv", "time,disp,load", [s["t"] * 1e3, s["d"] * 0.1, s["F"] / 4.4482216])
    (tmp_path / "lab.yaml").write_text("columns: {t: time, d: disp, F: load}\n"
                                       "units:\n  t: ms\n  d: cm\n  F: kip\n")
    rec = read_quiet(path)
    np.testing.assert_allclose(rec.t, s["t"], atol=1e-12)
    np.testing.assert_allclose(rec.d, s["d"], atol=1e-8)
    np.testing.assert_allclose(rec.F, s["F"], rtol=1e-8)
    assert rec.provenance["sidecar"].endswith("lab.yaml")
    # an explicit option wins over the sidecar, key by key
    rec2 = read_quiet(path, ReadOptions(units={"F": "kN"}))
    np.testing.assert_allclose(rec2.F, s["F"] / 4.4482216, rtol=1e-8)
    np.testing.assert_allclose(rec2.d, s["d"], atol=1e-8)


def test_unit_conversion_hand_values(write_csv):
    assert factor("t", "ms") == 1e-3 and factor("d", "m") == 1e3 and factor("d", "in") == 25.4
    assert factor("F", "N") == 1e-3 and factor("F", "kip") == pytest.approx(4.4482216)
    assert factor("v", "m/s") == 1e3
    # one row by hand: 250 ms, 0.0125 m, 1500 N -> 0.25 s, 12.5 mm, 1.5 kN
    s = sine()
    path = write_csv("u.csv", "t,d,F", [s["t"] * 1e3, s["d"] / 1e3, s["F"] * 1e3])
    rec = read_quiet(path, ReadOptions(units={"t": "ms", "d": "m", "F": "N"}))
    i = 25
    assert rec.t[i] == pytest.approx(s["t"][i] * 1e3 * 1e-3)
    assert rec.t[i] == pytest.approx(0.25)
    assert rec.d[i] == pytest.approx(20.0)  # sin(pi/2)
    assert rec.F[i] == pytest.approx(s["F"][i], abs=1e-9)


def test_csv_semicolons_blanks_and_row_numbers(tmp_path):
    s = sine()
    lines = ["# exported", "t;d;F", ""] + [f"{a:.10g};{b:.10g};{c:.10g}" for a, b, c in zip(s["t"], s["d"], s["F"])]
    lines.insert(10, "")  # a blank line in the data
    lines[20] = lines[20].split(";")[0] + ";nan;" + lines[20].split(";")[2]
    path = tmp_path / "semi.csv"
    path.write_text("\r\n".join(lines) + "\r\n")
    with pytest.raises(InputError, match=r"semi\.csv: row 21, column 'd': value nan is not finite"):
        read_record(str(path))


def test_csv_time_from_dt(write_csv):
    s = sine()
    path = write_csv("nodt.csv", "d,F", [s["d"], s["F"]])
    rec = read_quiet(path, ReadOptions(dt=0.01))
    np.testing.assert_allclose(rec.t, s["t"], atol=1e-12)


# --- .mat -----------------------------------------------------------------

def test_mat_written_by_test_matrix_and_vectors(tmp_path):
    s = sine(n_cycles=4)
    path = tmp_path / "rig.mat"
    scipy.io.savemat(path, {"x_F": np.column_stack([s["d"], s["v"], s["F"] * 1e3]), "Ts": 0.01,
                            "tout": s["t"], "dist": s["d"], "forc": s["F"]})
    rec = read_quiet(path, ReadOptions(mat_var="x_F", columns={"d": "0", "F": "2"}, units={"F": "N"}))
    assert rec.n == s["t"].size and rec.dt == pytest.approx(0.01)
    np.testing.assert_allclose(rec.F, s["F"], atol=1e-9)
    assert "Ts" in rec.provenance["columns"]["t"]
    rec = read_quiet(path, ReadOptions(columns={"t": "tout", "d": "dist", "F": "forc"}))
    np.testing.assert_allclose(rec.d, s["d"])
    # a matrix stored one signal per row is transposed; --dt wins over Ts
    scipy.io.savemat(path, {"x_F": np.vstack([s["d"], s["F"]])})
    rec = read_quiet(path, ReadOptions(mat_var="x_F", columns={"d": "0", "F": "1"}, dt=0.01))
    np.testing.assert_allclose(rec.F, s["F"])


def test_mat_sidecar(tmp_path):
    s = sine()
    scipy.io.savemat(tmp_path / "m.mat", {"x_F": np.column_stack([s["d"], s["F"] * 1e3])})
    (tmp_path / "m.yaml").write_text("mat_var: x_F\ncolumns: {d: 0, F: 1}\nunits: {F: N}\ndt: 0.01\n")
    rec = read_quiet(tmp_path / "m.mat")
    np.testing.assert_allclose(rec.F, s["F"], atol=1e-9)


@pytest.mark.parametrize("index", [0, 1])
def test_mat_shared_devices(device_files, index):
    path = device_files[index]
    dt = (None, 0.01)[index]  # the time step from the file's Ts, or given as --dt
    rec = read_quiet(path, ReadOptions(mat_var="x_F", columns={"d": "0", "F": "2"}, units={"F": "N"}, dt=dt))
    raw = scipy.io.loadmat(path)["x_F"]
    assert rec.n == raw.shape[0] == (3001, 1501)[index]
    assert rec.dt == pytest.approx(0.01)
    np.testing.assert_allclose(rec.F, raw[:, 2] * 1e-3)
    assert 0.05 < np.max(np.abs(rec.F)) < 1.0  # a small MR damper: about 0.1-0.3 kN
    assert count_cycles(rec.d) > 5
    # the SG velocity follows the file's own numerical derivative
    corr = np.corrcoef(rec.v, raw[:, 1])[0, 1]
    assert corr > 0.99


def test_inspect_shared_device_cli(device_files, tmp_path, capsys):
    png = tmp_path / "look.png"
    rc = cli.main(["inspect", str(device_files[0]), "--mat-var", "x_F", "--columns", "d=0,F=2",
                   "--units", "F=N", "--plot", str(png)])
    out = capsys.readouterr().out
    assert rc == 0
    assert "samples      3001" in out and "Savitzky-Golay" in out
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# --- velocity, cycles, noise, resampling -----------------------------------

def test_sg_velocity_of_sinusoid():
    dt, f, amp = 0.005, 0.8, 25.0
    t = np.arange(0, 5.0, dt)
    w = 2 * np.pi * f
    d = amp * np.sin(w * t)
    v, a, settings = differentiate(d, dt)
    vmax = amp * w
    assert np.max(np.abs(v - amp * w * np.cos(w * t))) < 1e-3 * vmax
    assert np.max(np.abs(a + amp * w**2 * np.sin(w * t))[20:-20]) < 1e-2 * amp * w**2
    assert settings["method"] == "savgol" and settings["window_chosen"] == "auto"
    v2, _, s2 = differentiate(d, dt, window=21, polyorder=3)
    assert s2 == dict(s2, window=21, polyorder=3, window_chosen="user")
    assert np.max(np.abs(v2 - amp * w * np.cos(w * t))) < 1e-3 * vmax


@pytest.mark.parametrize("n_cycles, phase", [(1, 0.0), (3, 0.0), (3, np.pi / 2), (2.5, 0.0), (5, 1.0)])
def test_count_cycles_sinusoids(n_cycles, phase):
    t = np.linspace(0, n_cycles, int(200 * n_cycles) + 1)
    d = 10 * np.sin(2 * np.pi * t + phase)
    assert count_cycles(d) == pytest.approx(n_cycles, abs=0.05)


def test_count_cycles_ignores_small_wiggles():
    t = np.linspace(0, 3, 3001)
    d = 10 * np.sin(2 * np.pi * t) + 0.05 * np.sin(2 * np.pi * 40 * t)
    assert count_cycles(d) == pytest.approx(3, abs=0.05)


@pytest.mark.parametrize("sigma", [0.5, 2.0])
def test_force_noise_white_plus_smooth(sigma):
    rng = np.random.default_rng(1)
    t = np.arange(0, 20, 0.002)
    smooth = 300 * np.sin(2 * np.pi * 0.5 * t) + 40 * np.sign(np.sin(2 * np.pi * 0.5 * t + 1.6))
    est = force_noise(smooth + rng.normal(0, sigma, t.size))
    assert est == pytest.approx(sigma, rel=0.10)


def test_resampling_slightly_irregular_time(write_csv):
    rng = np.random.default_rng(0)
    dt, n = 0.01, 401
    t = dt * np.arange(n) + rng.uniform(-0.02, 0.02, n) * dt  # steps within +-4%
    t[0], t[-1] = 0.0, dt * (n - 1)
    d, F = 20 * np.sin(2 * np.pi * t), 100 * np.cos(2 * np.pi * t)
    path = write_csv("jitter.csv", "t,d,F", [t, d, F])
    with pytest.warns(RecordWarning, match="resampled"):
        rec = read_record(str(path))
    np.testing.assert_allclose(np.diff(rec.t), dt, rtol=1e-9)
    assert rec.n == n and rec.provenance["resampled"]
    np.testing.assert_allclose(rec.d, 20 * np.sin(2 * np.pi * rec.t), atol=0.02)
    assert any("resampled" in w for w in rec.warnings)


def test_round_off_time_is_not_resampled(write_csv):
    s = sine()
    path = write_csv("ro.csv", "t,d,F", [np.round(s["t"] + 1e-7 * np.sin(s["t"] * 7), 9), s["d"], s["F"]])
    rec = read_quiet(path)
    assert not rec.provenance["resampled"]
    np.testing.assert_allclose(np.diff(rec.t), 0.01, rtol=1e-6)


# --- record, summary, inspect ------------------------------------------------

def test_record_fields_and_summary(write_csv):
    s = sine(n_cycles=4, c=1.5)
    rec = read_quiet(write_csv("r.csv", "t,d,F", [s["t"], s["d"], s["F"]]))
    summ = summarize(rec)
    assert summ["samples"] == rec.n and summ["cycles"] == pytest.approx(4, abs=0.05)
    assert summ["peak_d_mm"] == pytest.approx(20, rel=1e-3)
    assert summ["peak_F_kN"] == pytest.approx(1.5 * 20 * 2 * np.pi, rel=1e-3)
    assert summ["peak_v_mm_s"] == pytest.approx(20 * 2 * np.pi, rel=2e-3)
    part = rec.slice(0, 50)
    assert part.n == 50 and part.provenance["slice"] == [0, 50]
    with pytest.raises(ValueError):
        Record(np.arange(3.0), np.zeros(3), np.zeros(2), np.zeros(3), np.zeros(3))


def test_inspect_in_process(write_csv, tmp_path, capsys):
    s = sine()
    path = write_csv("r.csv", "t,d,F", [s["t"], s["d"], s["F"]])
    png = tmp_path / "r.png"
    assert cli.main(["inspect", str(path), "--sg-window", "9", "--sg-order", "2", "--plot", str(png)]) == 0
    out = capsys.readouterr().out
    assert "window 9 samples" in out and "order 2" in out and "warnings     none" in out
    assert png.read_bytes()[:4] == b"\x89PNG"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.csv", "r.png"]  # no temp file left


def test_savgol_matches_scipy():
    from scipy.signal import savgol_filter

    from fvd_bridge.records.savgol import savgol_derivative

    x = np.random.default_rng(3).normal(size=300).cumsum()
    for window, order, deriv in [(5, 3, 1), (5, 3, 2), (11, 2, 1), (21, 3, 2), (9, 4, 3), (7, 1, 2)]:
        ref = savgol_filter(x, window, order, deriv=deriv, delta=0.01, mode="interp")
        np.testing.assert_allclose(savgol_derivative(x, window, order, deriv, 0.01), ref,
                                   atol=1e-9 * (1 + np.max(np.abs(ref))))
