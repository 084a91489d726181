"""Records: readers (CSV, sidecar, .mat), units, velocity, cycles, noise, resampling, inspect."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest
import scipy.io

from conftest import csv_text, sine
from fvd_bridge import cli
from fvd_bridge.errors import InputError
from fvd_bridge.records import ReadOptions, Record, RecordWarning, read_record, summarize
from fvd_bridge.records.cycles import count_cycles, displacement_noise, dominant_period, force_noise
from fvd_bridge.records.velocity import derive, differentiate, fixed_derivative, noise_gain
from fvd_bridge.rig import acceptance, paper
from fvd_bridge.units import factor

#: the reader's note on a file that states no unit at all
NO_UNITS = "no unit information: read as t [s], d [mm], F [kN]"
#: ... and how to give them, in Python's words
GIVE_UNITS = "give the units (units={'d': 'm', 'F': 'N'}, e.g.), a sidecar or a header such as 'F [N]'"


def read_quiet(path, opts=None):
    """read_record with RecordWarnings turned into errors: the record must be
    clean, except for the note that a file without sidecar or --units states
    no unit (most files here are written that way)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", RecordWarning)
        warnings.filterwarnings("ignore", message=".*no unit information", category=RecordWarning)
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
    assert vel["method"] == "savgol" and vel["window_chosen"] == "adaptive" and vel["polyorder"] == 3
    assert vel["rule"] == "ICI" and vel["gamma"] > 0 and vel["windows_used"][0] % 2 == 1
    assert rec.warnings == [f"{path}: {NO_UNITS}; {GIVE_UNITS}"]


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
    with pytest.warns(RecordWarning, match="read in kN"):
        rec2 = read_record(str(path), ReadOptions(units={"F": "kN"}))
    np.testing.assert_allclose(rec2.F, s["F"] / 4.4482216, rtol=1e-8)
    np.testing.assert_allclose(rec2.d, s["d"], atol=1e-8)
    # ... visibly: the column replaced is noted, with the factor between the two units; the others are not
    notes = [w for w in rec2.warnings if "apart" in w]
    assert len(notes) == 1 and "column 'load' read in kN" in notes[0] and "sidecar lab.yaml says kip" in notes[0]
    assert "a factor 4.448 apart" in notes[0]
    assert not [w for w in read_quiet(path, ReadOptions(units={"F": "kip", "d": "cm"})).warnings if "apart" in w]


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
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RecordWarning)
        rec = read_record(str(path), ReadOptions(mat_var="x_F", columns={"d": "0", "F": "2"}, units={"F": "N"},
                                                 dt=dt))
    # the only note: each MR test starts at rest (1.85 s; 1.5 s) with a load-cell offset, which a fit
    # would take for the damper's
    assert [str(w.message) for w in caught] == rec.warnings and len(rec.warnings) == 1
    assert f"starts with {(1.85, 1.5)[index]:g} s at rest" in rec.warnings[0]
    assert "% of the peak force)" in rec.warnings[0] and "readers.cut(record, " in rec.warnings[0]  # Python's words
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
    assert "samples      3001" in out and "Savitzky-Golay" in out and "warnings     1" in out
    assert "at rest with a force of" in out and "--window 1.85,30" in out
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
    assert settings["method"] == "savgol" and settings["window_chosen"] == "adaptive"
    v2, _, s2 = differentiate(d, dt, window=21, polyorder=3)
    assert s2 == dict(s2, window=21, polyorder=3, window_chosen="user")
    assert np.max(np.abs(v2 - amp * w * np.cos(w * t))) < 1e-3 * vmax


def test_fixed_window_is_scipy_savgol_and_noise_gain_is_exact():
    from scipy.signal import savgol_coeffs, savgol_filter

    x = np.random.default_rng(3).normal(size=300).cumsum()
    for window, order, deriv in [(5, 3, 1), (5, 3, 2), (11, 2, 1), (21, 3, 2), (9, 4, 3), (7, 1, 2)]:
        ref = savgol_filter(x, window, order, deriv=deriv, delta=0.01, mode="interp") if deriv <= order \
            else np.zeros(x.size)
        est, noise = fixed_derivative(x, 0.01, 0.5, deriv, window, order)
        p = min(max(order, deriv), window - 1)  # the order is raised to the derivative's
        if p == order:
            np.testing.assert_allclose(est, ref, atol=1e-9 * (1 + np.max(np.abs(ref))))
        centre, edge = noise_gain(window, p, deriv, 0.01)
        # the centre and every end position against scipy's own coefficients
        assert centre == pytest.approx(np.linalg.norm(savgol_coeffs(window, p, deriv=deriv, delta=0.01)), rel=1e-9)
        for pos in range(window // 2):
            h = savgol_coeffs(window, p, deriv=deriv, delta=0.01, pos=pos, use="dot")
            assert edge[pos] == pytest.approx(np.linalg.norm(h), rel=1e-7)
        assert noise[window // 2 + 1] == pytest.approx(0.5 * centre) and noise[0] == pytest.approx(0.5 * edge[0])
        assert noise[-1] == pytest.approx(noise[0])


def former_window(d, dt):
    """The former default: one window for the whole record, 1/25 of the
    dominant period, odd, 5..101 samples (kept here to compare against)."""
    w = int(round(dominant_period(d, dt) / dt / 25.0))
    w = min(max(w, 5), 101)
    return w if w % 2 else w + 1


def _rms(x):
    return float(np.sqrt(np.mean(np.square(x))))


# RMS error [mm/s] of v against the exact one, mean of seeds 0-2 (measured
# once): former fixed window -> adaptive ICI (windows used)
#   paper       0.005 mm: 0.62 -> 0.13 (25..65)   0.02 mm: 2.47 -> 0.32 (25..97)    former window 11
#   acceptance  0.005 mm: 0.28 -> 0.11 (13..513)  0.02 mm: 1.06 -> 0.33 (17..769)   former window 19
# and of a [mm/s^2]: paper 88 -> 38, 348 -> 68; acceptance 93 -> 46, 125 -> 77
@pytest.mark.parametrize("name", ["paper", "acceptance"])
@pytest.mark.parametrize("sigma", [0.005, 0.02])
def test_adaptive_velocity_beats_the_fixed_window(name, sigma):
    prot = paper() if name == "paper" else acceptance()  # acceptance: 5 to 500 mm/s, periods 2 to 0.25 s
    t = prot.times()
    d0, v0, a0 = prot.motion(t)
    dt = prot.dt
    assert dt == 0.002
    if name == "acceptance":
        peaks = [s.peak_velocity for s in prot.segments]
        assert max(peaks) / min(peaks) >= 20
    for seed in range(3):
        d = d0 + sigma * np.random.default_rng(seed).standard_normal(t.size)
        out = derive(d, dt)
        w = former_window(d, dt)
        v_old, _ = fixed_derivative(d, dt, sigma, 1, w)
        a_old, _ = fixed_derivative(d, dt, sigma, 2, w)
        old, new = _rms(v_old - v0), _rms(out.v - v0)
        assert new < 0.6 * old, (seed, old, new)
        assert _rms(out.a - a0) < 0.9 * _rms(a_old - a0)
        # sigma_d estimated within 20% (measured: within 3%)
        assert out.d_noise == pytest.approx(sigma, rel=0.2)
        assert out.settings["d_noise_mm"] == out.d_noise
        assert out.settings["v_noise_mm_s"] == pytest.approx(np.median(out.v_noise))
    # the stated noise is that of the filters used: the windows chosen at each
    # sample (last seed), applied to the noise alone (linear filters), give
    # v_noise's spread (v_noise is from the estimated sigma_d)
    e = d - d0
    v_e = np.empty(t.size)
    for w in np.unique(out.v_window):
        at = out.v_window == w
        v_e[at] = fixed_derivative(e, dt, sigma, 1, int(w))[0][at]
    assert np.std(v_e / out.v_noise * out.d_noise / sigma) == pytest.approx(1.0, abs=0.1)


@pytest.mark.parametrize("sigma", [0.005, 0.02])
def test_displacement_noise_estimate(sigma):
    """4th-difference MAD estimate on a smooth 40 mm sinusoid (500 mm/s) at 500 Hz:
    the signal's own 4th difference (< 2e-5 mm) is far below the noise's."""
    t = np.arange(0, 10, 0.002)
    d = 40 * np.sin(12.5 * t)
    assert np.max(np.abs(np.diff(d, 4))) < 2e-5
    est = [displacement_noise(d + sigma * np.random.default_rng(s).standard_normal(t.size)) for s in range(5)]
    assert est == pytest.approx([sigma] * 5, rel=0.10)
    # a record quantized coarser than its noise still has a nonzero noise (q / sqrt 12)
    q = 0.01
    assert displacement_noise(np.round(d / q) * q) == pytest.approx(q / np.sqrt(12), rel=0.5)


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
        rec = read_record(str(path), ReadOptions(units={"t": "s"}))
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
    assert cli.main(["inspect", str(path), "--sg-window", "9", "--sg-order", "2", "--units", "F=kN",
                     "--plot", str(png)]) == 0
    out = capsys.readouterr().out
    assert "window 9 samples" in out and "order 2" in out and "warnings     none" in out
    assert "disp. noise" in out and "vel. noise" in out
    assert png.read_bytes()[:4] == b"\x89PNG"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.csv", "r.png"]  # no temp file left


def test_inspect_reports_displacement_and_velocity_noise(tmp_path, capsys):
    prot = paper(cycles=3)
    t = prot.times()
    d, v, _ = prot.motion(t)
    rng = np.random.default_rng(5)
    path = tmp_path / "noisy.csv"
    path.write_text(csv_text("t,d,F", [t, d + 0.01 * rng.standard_normal(t.size), 0.5 * v]))
    assert cli.main(["inspect", str(path), "--units", "d=mm"]) == 0
    out = capsys.readouterr().out
    line = next(ln for ln in out.splitlines() if ln.startswith("disp. noise"))
    assert float(line.split()[2]) == pytest.approx(0.01, rel=0.2) and line.endswith("mm")
    line = next(ln for ln in out.splitlines() if ln.startswith("vel. noise"))
    assert 0.005 < float(line.split()[2]) < 1.0 and "mm/s" in line
    assert "ICI" in out and "warnings     none" in out
    rec = read_quiet(path)
    assert rec.d_noise == pytest.approx(0.01, rel=0.2) and rec.v_noise.shape == rec.t.shape
    assert summarize(rec)["velocity_noise_mm_s"] == pytest.approx(np.median(rec.v_noise))


# --- unit information ------------------------------------------------------

def test_csv_without_unit_information_warns(tmp_path, capsys):
    s = sine()
    text = csv_text("t,d,F", [s["t"], s["d"], s["F"]])
    bare = tmp_path / "bare.csv"
    bare.write_text(text)
    with pytest.warns(RecordWarning, match=re.escape(NO_UNITS)):
        rec = read_record(str(bare))
    assert rec.warnings == [f"{bare}: {NO_UNITS}; {GIVE_UNITS}"]
    assert cli.main(["inspect", str(bare)]) == 0
    out = capsys.readouterr().out
    assert "warnings     1" in out and NO_UNITS in out
    # any unit information silences it: --units (even one key), or a sidecar with units
    assert read_quiet(bare, ReadOptions(units={"d": "mm"})).warnings == []
    (tmp_path / "side.csv").write_text(text)
    (tmp_path / "side.yaml").write_text("units: {t: s, d: mm, F: kN}\n")
    assert read_quiet(tmp_path / "side.csv").warnings == []
    # a sidecar that names the columns but no unit still leaves the units unstated
    (tmp_path / "cols.csv").write_text(text)
    (tmp_path / "cols.yaml").write_text("columns: {t: t, d: d, F: F}\n")
    assert any(NO_UNITS in w for w in read_quiet(tmp_path / "cols.csv").warnings)
    # a measured velocity column is named too
    (tmp_path / "withv.csv").write_text(csv_text("t,d,F,v", [s["t"], s["d"], s["F"], s["v"]]))
    assert any("F [kN], v [mm/s]; give" in w for w in read_quiet(tmp_path / "withv.csv").warnings)


def test_mat_without_unit_information_warns(tmp_path):
    s = sine()
    scipy.io.savemat(tmp_path / "m.mat", {"x_F": np.column_stack([s["d"], s["F"]]), "Ts": 0.01})
    opts = ReadOptions(mat_var="x_F", columns={"d": "0", "F": "1"})
    with pytest.warns(RecordWarning, match=re.escape(NO_UNITS)):
        rec = read_record(str(tmp_path / "m.mat"), opts)
    assert len(rec.warnings) == 1
    assert read_quiet(tmp_path / "m.mat", ReadOptions(mat_var="x_F", columns={"d": "0", "F": "1"},
                                                      units={"F": "kN"})).warnings == []


def test_calibrate_shows_the_unit_warning(tmp_path, capsys):
    s = sine(n_cycles=3, c=1.5)
    bare = tmp_path / "bare.csv"
    bare.write_text(csv_text("t,d,F", [s["t"], s["d"], s["F"]]))
    rc = cli.main(["calibrate", str(bare), "--laws", "1", "--runs", "1", "--pop", "8", "--gens", "5",
                   "--no-figures", "--jobs", "1", "--out", str(tmp_path / "cal"), "--intervals", "0"])
    assert rc == 0
    assert NO_UNITS in capsys.readouterr().err


def test_record_noise_fields_follow_slices(write_csv):
    s = sine(n_cycles=4)
    rec = read_quiet(write_csv("r.csv", "t,d,F", [s["t"], s["d"], s["F"]]))
    part = rec.slice(10, 60)
    assert part.d_noise == rec.d_noise and np.array_equal(part.v_noise, rec.v_noise[10:60])
    assert np.array_equal(part.a_noise, rec.a_noise[10:60])
    bare = Record(s["t"], s["d"], s["F"], s["v"], s["v"])
    assert bare.v_noise is None and bare.d_noise is None
    assert Record(s["t"], s["d"], s["F"], s["v"], s["v"], v_noise=0.5).v_noise.shape == s["t"].shape


def test_a_measured_velocity_can_be_left_out(tmp_path):
    """--columns v=none: a record's own v column is ignored and v derived from
    d, as without the column; only v can be left out (one line otherwise)."""
    import argparse

    from fvd_bridge.commands.common import add_record_options, read_options

    t = np.arange(0.0, 4.0, 0.005)
    d = 20.0 * np.sin(2 * np.pi * t)
    v = 40.0 * np.pi * np.cos(2 * np.pi * t)
    path = tmp_path / "with_v.csv"
    path.write_text("t,d,F,v\n" + "\n".join(f"{a:.3f},{b:.6f},{0.5 * c:.6f},{c:.6f}" for a, b, c in zip(t, d, v)))
    parser = argparse.ArgumentParser()
    add_record_options(parser)
    measured = read_record(str(path), read_options(parser.parse_args(["--units", "t=s,d=mm,F=kN,v=mm/s"])))
    derived = read_record(str(path), read_options(parser.parse_args(["--units", "t=s,d=mm,F=kN,v=mm/s",
                                                                      "--columns", "v=none"])))
    assert measured.provenance["velocity"]["method"] == "measured"
    assert derived.provenance["velocity"]["method"] != "measured"
    assert np.allclose(measured.v, v, rtol=0, atol=1e-6) and not np.allclose(derived.v, v, rtol=0, atol=1e-6)
    assert np.max(np.abs(derived.v - v)[200:-200]) < 0.01 * np.max(np.abs(v))  # d is exact here
    with pytest.raises(InputError, match="only the velocity can be left out"):
        read_options(parser.parse_args(["--columns", "d=none"]))


def test_a_force_offset_at_rest_is_flagged(tmp_path):
    """A record that starts with 2 s at rest and a force there of 20% of the
    peak (a load-cell offset) gets one warning naming the --window that leaves
    the rest out; without the offset, none."""
    t = np.arange(0.0, 8.0, 0.01)
    d = np.where(t < 2.0, 0.0, 20.0 * np.sin(2 * np.pi * (t - 2.0)))
    F = 100.0 * np.gradient(d, t) / (40.0 * np.pi)  # a viscous 100 kN damper
    for offset, flagged in ((-20.0, True), (0.0, False)):
        path = tmp_path / f"rest{int(-offset)}.csv"
        path.write_text("t,d,F\n" + "\n".join(f"{a:.2f},{b:.6f},{c + offset:.6f}" for a, b, c in zip(t, d, F)))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RecordWarning)
            rec = read_record(str(path), ReadOptions(units={"t": "s", "d": "mm", "F": "kN"}))
        assert rec.warnings == ([rec.warnings[0]] if flagged else []), rec.warnings
        if flagged:
            assert "starts with 2.01 s at rest with a force of -20 kN" in rec.warnings[0]
            assert "(20% of the peak force)" in rec.warnings[0] and "cut(record, 2.01, 7.99)" in rec.warnings[0]
