"""Ground-motion readers: the shared real records, synthetic files of each
format (values touching in the fixed-width ones), scaling, and bad input."""

import re
from pathlib import Path

import numpy as np
import pytest

from fvd_bridge.errors import InputError
from fvd_bridge.records.motions import (G_MM_S2, GroundMotion, accel_factor, read_at2, read_motion, read_smc,
                                       read_text, read_two_column, read_v2a)
from fvd_bridge.rig.protocols import read_history

RECORDS = Path(__file__).resolve().parents[2].parent / "shared" / "records"

# file, component, points, dt [s], PGA [g] (records/README.md)
SHARED = [
    ("elcentro_1940_NS_2688pts_g_dt0.02.dat", None, 2688, 0.02, 0.349),
    ("lomaprieta_1989_APEEL2_RedwoodCity_np01002p_4225c_a.smc", None, 7184, 0.005, 0.278),
    ("lomaprieta_1989_APEEL2_RedwoodCity_np01002p_4225a_a.smc", None, 7183, 0.005, 0.227),
    ("kaikoura_2016_WTMC_Waiau_20161113_110259_WTMC_20.V2A", None, 8192, 0.02, 0.992),
    ("kaikoura_2016_WTMC_Waiau_20161113_110259_WTMC_20.V2A", "N28W", 8192, 0.02, 0.992),
]


# ------------------------------------------------------- synthetic files

def touching(n, width_digits=4, seed=0):
    """n values, every other one negative with `width_digits` integer digits,
    so that fixed-width fields touch."""
    rng = np.random.default_rng(seed)
    v = rng.uniform(10 ** (width_digits - 1), 10 ** width_digits - 1, n)
    v[::2] *= -1.0
    return v


def smc_text(values, rate=200.0, comments=("|synthetic", "|record"), npts=None,
             head="2 CORRECTED ACCELEROGRAM"):
    """A USGS SMC file: 11 text lines, 6 x 8 I10, 10 x 5 E15.7, comments, 8 x F10."""
    ints = [-32768] * 48
    ints[15], ints[16] = len(comments), len(values) if npts is None else npts
    reals = [1.7e38] * 50
    reals[1] = rate
    lines = [head, "*", "A020C", "     2000  01  01    0000 Test", "Mag", "station = test  component=  90"]
    lines += ["*"] * 5
    lines += ["".join(f"{v:10d}" for v in ints[i:i + 8]) for i in range(0, 48, 8)]
    lines += ["".join(f"{v:15.7E}" for v in reals[i:i + 5]) for i in range(0, 50, 5)]
    lines += list(comments)
    lines += ["".join(f"{v:10.4f}" for v in values[i:i + 8]) for i in range(0, len(values), 8)]
    return "\r\n".join(lines) + "\r\n"


def v2a_component(name, acc, dt=0.01, head="Corrected accelerogram TEST GNS Science", counts=None):
    """One GeoNet V2A component: 16 text lines, 4 x 10 I8, 6 x 10 F8, a/v/d blocks 10 x F8.1."""
    n = len(acc)
    ints = [0] * 40
    ints[33:36] = counts or (n, n, n)
    reals = [0.0] * 60
    reals[25] = dt
    lines = [head] + ["Site TEST"] * 11 + [f"Component {name}  Test Accelerometer Axis"] + ["x"] * 3
    lines += ["".join(f"{v:8d}" for v in ints[i:i + 10]) for i in range(0, 40, 10)]
    lines += ["".join(f"{v:8.4f}" for v in reals[i:i + 10]) for i in range(0, 60, 10)]
    for block in (acc, acc * 0.1, acc * 0.01):
        lines += ["".join(f"{v:8.1f}" for v in block[i:i + 10]) for i in range(0, n, 10)]
    return lines


def at2_text(values, line4, line3="ACCELERATION TIME SERIES IN UNITS OF G"):
    """A PEER NGA AT2 file: 4 header lines, then 5 values a line (E15.7)."""
    lines = ["PEER NGA STRONG MOTION DATABASE RECORD", "Synthetic 2000, TEST, 0", line3, line4]
    lines += ["".join(f"{v:15.7E}" for v in values[i:i + 5]) for i in range(0, len(values), 5)]
    return "\n".join(lines) + "\n"


def write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text if isinstance(text, str) else "\n".join(text) + "\n")
    return path


# ----------------------------------------------------- real shared records

@pytest.mark.parametrize("name,component,npts,dt,pga", SHARED)
def test_shared_records(name, component, npts, dt, pga):
    if not RECORDS.is_dir():
        pytest.skip(f"shared records not found at {RECORDS}")
    m = read_motion(RECORDS / name, component=component)
    assert m.accel.size == npts
    assert m.dt == pytest.approx(dt, rel=1e-9)
    assert m.pga_g == pytest.approx(pga, rel=0.005)
    assert m.duration == pytest.approx((npts - 1) * dt)


def test_shared_v2a_components_match_their_headers():
    """Each component's PGA equals the 'Acceleration: peak' line of its own text header."""
    if not RECORDS.is_dir():
        pytest.skip(f"shared records not found at {RECORDS}")
    path = RECORDS / "kaikoura_2016_WTMC_Waiau_20161113_110259_WTMC_20.V2A"
    peaks = [abs(float(ln.split()[2])) for ln in path.read_text().splitlines() if ln.startswith("Acceleration:")]
    for k, key in enumerate(["N28W", "s62w", "up"]):
        m = read_v2a(path, component=key)
        assert m.source["component_index"] == k and m.accel.size == 8192
        assert np.max(np.abs(m.accel)) == pytest.approx(peaks[k], abs=0.05)
    assert read_v2a(path, component=2).source["component"] == "Up"


# --------------------------------------------------------- synthetic formats

def test_smc_touching_fields_and_partial_last_line(tmp_path):
    vals = touching(21)  # 8 + 8 + 5 on the last line
    path = write(tmp_path, "syn.smc", smc_text(vals, rate=100.0))
    m = read_smc(path)
    assert m.accel.size == 21 and m.dt == pytest.approx(0.01)
    assert np.allclose(m.accel, vals * 10.0, atol=1e-3)  # cm/s^2 -> mm/s^2
    assert read_motion(path).accel.size == 21


def test_v2a_components_by_index_and_name(tmp_path):
    a = [touching(25, 5, seed=k) for k in range(3)]  # -12345.6: F8.1 fields touch
    lines = v2a_component("N10E", a[0]) + v2a_component("S80E", a[1]) + v2a_component("Up", a[2])
    path = write(tmp_path, "syn.V2A", lines)
    for k, comp in enumerate([None, "s80", 2]):
        m = read_motion(path, component=comp)
        assert m.dt == pytest.approx(0.01) and m.accel.size == 25
        assert np.allclose(m.accel, a[k if comp is not None else 0], atol=0.051)
    assert read_motion(path, component="up").name.endswith(":Up")


@pytest.mark.parametrize("line4", ["NPTS=  2000, DT=   .0100 SEC", "2000   0.0100   NPTS, DT"])
def test_at2_both_header_forms(tmp_path, line4):
    vals = np.random.default_rng(1).normal(0.0, 0.05, 2000)
    vals[777] = -0.31
    path = write(tmp_path, "syn.AT2", at2_text(vals, line4))
    m = read_motion(path)
    assert m.accel.size == 2000 and m.dt == pytest.approx(0.01)
    assert m.pga_g == pytest.approx(0.31, rel=1e-6)
    assert np.allclose(m.accel / G_MM_S2, vals, rtol=1e-6, atol=1e-12)


def test_at2_partial_last_line(tmp_path):
    vals = np.linspace(-0.1, 0.2, 1998)
    m = read_at2(write(tmp_path, "p.at2", at2_text(vals, "NPTS=   1998, DT=   .0050 SEC")))
    assert m.accel.size == 1998 and m.dt == pytest.approx(0.005) and m.pga_g == pytest.approx(0.2)


def test_text_one_column_units_and_format_override(tmp_path):
    path = write(tmp_path, "a.txt", "# a in cm/s^2\n1.0\n-2.0\n3.0 # peak\n\n0.5\n")
    m = read_motion(path, units="cm/s^2", dt=0.01)
    assert m.dt == 0.01 and np.allclose(m.accel, [10.0, -20.0, 30.0, 5.0])
    two = write(tmp_path, "b.csv", "0.5, 0.1\n0.52, -0.2\n0.54, 0.0\n")
    m = read_text(two, units="m/s^2")
    assert m.dt == pytest.approx(0.02) and m.source["t0_s"] == 0.5 and m.pga_g == pytest.approx(200.0 / G_MM_S2)
    at2 = write(tmp_path, "rec.txt", at2_text([0.1, -0.2, 0.05], "NPTS=  3, DT=  .01 SEC"))
    assert read_motion(at2, fmt="at2").pga_g == pytest.approx(0.2)
    assert accel_factor("g") == G_MM_S2 and accel_factor("gal") == 10.0 and accel_factor("in/s/s") == 25.4


# ------------------------------------------------------- scaling and window

def test_scaled_to_pga_and_window():
    a = np.sin(np.linspace(0.0, 20.0, 1001)) * 0.2 * G_MM_S2
    m = GroundMotion("sine", 0.01, a, {"file": "x"})
    s = m.scaled_to_pga(0.5)
    assert s.pga_g == pytest.approx(0.5) and s.source["scale_factor"] == pytest.approx(2.5, rel=1e-3)
    assert s.scaled_to_pga(0.25).source["scale_factor"] == pytest.approx(s.source["scale_factor"] / 2)
    assert m.pga_g == pytest.approx(0.2, rel=1e-3) and "scale_factor" not in m.source
    assert m.t[-1] == pytest.approx(10.0) and m.duration == pytest.approx(10.0)
    w = m.window(2.5)
    assert w.accel.size == 251 and w.duration == pytest.approx(2.5) and w.source["window_s"][1] == pytest.approx(2.5)
    assert m.window(60.0).accel.size == 1001
    with pytest.raises(ValueError):
        m.accel[0] = 1.0  # read-only
    with pytest.raises(InputError, match="PGA"):
        m.scaled_to_pga(-1.0)
    with pytest.raises(InputError, match="zero"):
        GroundMotion("z", 0.01, np.zeros(5)).scaled_to_pga(0.3)


# ---------------------------------------------------- rig history from text

@pytest.mark.parametrize("sep", [" ", ",", "\t"])
def test_read_history_plain_two_column(tmp_path, sep):
    t = np.arange(0.0, 2.0, 0.01)
    d = 5.0 * np.sin(2 * np.pi * t)
    path = tmp_path / "h.txt"
    path.write_text("# t [s], d [mm]\n" + "\n".join(f"{a:.2f}{sep}{b:.9f}" for a, b in zip(t, d)) + "\n")
    p = read_history(str(path))
    dd, _, _ = p.motion(p.times())
    assert p.n == t.size and np.max(np.abs(dd - d)) < 1e-8
    assert np.allclose(read_two_column(path)[1], d)
    with_header = tmp_path / "h.csv"
    with_header.write_text("t,d,F\n" + "\n".join(f"{a},{b},0" for a, b in zip(t, d)) + "\n")
    assert read_history(str(with_header)).n == t.size  # a CSV with header as before
    bad = tmp_path / "bad.txt"
    bad.write_text("0 0\n0.1 1\n0.2 x\n0.3 2\n0.4 1\n")
    with pytest.raises(InputError, match=r"bad\.txt: line 3, column 2"):
        read_history(str(bad))


# ----------------------------------------------------------------- bad input

def edited(tmp_path, name, text, line_no, a, b, new):
    """``text`` with characters a..b (1-based) of line ``line_no`` replaced by ``new``."""
    lines = text.replace("\r\n", "\n").split("\n")
    lines[line_no - 1] = lines[line_no - 1][:a - 1] + new + lines[line_no - 1][b:]
    return write(tmp_path, name, "\n".join(lines))


CASES = {
    "missing file": lambda tp: (tp / "nope.dat", {}, r"no such file"),
    "empty file": lambda tp: (write(tp, "empty.dat", "\n  \n"), {}, r"empty file"),
    "only comments": lambda tp: (write(tp, "c.dat", "# nothing\n"), {}, r"no data lines"),
    "non-numeric cell": lambda tp: (write(tp, "n.dat", "0 0.1\n0.02 abc\n"), {}, r"line 2, column 2: 'abc'"),
    "nan cell": lambda tp: (write(tp, "nan.dat", "0 0.1\n0.02 nan\n"), {}, r"line 2, column 2"),
    "ragged rows": lambda tp: (write(tp, "r.dat", "0 0.1\n0.02\n"), {}, r"line 2 has 1 columns"),
    "three columns": lambda tp: (write(tp, "3.dat", "0 0.1 2\n"), {}, r"line 1 has 3 columns"),
    "one column without dt": lambda tp: (write(tp, "1.dat", "0.1\n0.2\n"), {}, r"1 column; give .*dt"),
    "non-increasing time": lambda tp: (write(tp, "t.dat", "# t a\n0 0.1\n0.02 0.2\n0.02 0.3\n"), {},
                                       r"line 4, column 1: time 0.02 s does not increase"),
    "off-grid time": lambda tp: (write(tp, "g.dat", "0 0\n0.01 0\n0.05 0\n0.06 0\n"), {},
                                 r"line 2, column 1: .*uniform grid"),
    "unknown unit": lambda tp: (write(tp, "u.dat", "0 0.1\n0.02 0.2\n"), {"units": "furlong/s^2"},
                                r"unknown acceleration unit 'furlong/s\^2'"),
    "unknown format": lambda tp: (write(tp, "f.dat", "0 0\n"), {"fmt": "xyz"}, r"unknown format 'xyz'"),
    "smc wrong header": lambda tp: (write(tp, "h.smc", smc_text(touching(8), head="1 UNCORRECTED ACCELEROGRAM")),
                                    {}, r"line 1: '1 UNCORRECTED"),
    "smc fewer points": lambda tp: (write(tp, "short.smc", smc_text(touching(20), npts=24)), {},
                                    r"line 32: the data ends after 20 of the 24 acceleration points"),
    "smc file ends": lambda tp: (write(tp, "end.smc", smc_text(touching(24), npts=40)), {},
                                 r"line 32: the file ends after 24 of the 40 acceleration points"),
    "smc more points": lambda tp: (write(tp, "more.smc", smc_text(touching(20), npts=16)), {},
                                   r"line 32: data after the 16 points"),
    "smc more values on the last line": lambda tp: (write(tp, "more2.smc", smc_text(touching(20), npts=18)), {},
                                                    r"line 32, characters 21-: more acceleration values than the 18"),
    "smc non-numeric field": lambda tp: (edited(tp, "cell.smc", smc_text(touching(16)), 31, 21, 30, "  12.3x567"),
                                         {}, r"line 31, field 3 \(characters 21-30, acceleration point 11 of 16\)"),
    "smc bad point count": lambda tp: (edited(tp, "i.smc", smc_text(touching(8)), 14, 1, 10, "      8.0 "),
                                       {}, r"line 14, field 1 \(characters 1-10, integer header no. 17\): '8.0'"),
    "smc no sample rate": lambda tp: (write(tp, "r.smc", smc_text(touching(8), rate=1.7e38)), {},
                                      r"line 18, field 2: sample rate .* is unset"),
    "v2a wrong header": lambda tp: (write(tp, "w.V2A", v2a_component("N", touching(5), head="Something else")), {},
                                    r"line 1: 'Something else' is not the header of a GeoNet V2A"),
    "v2a fewer points": lambda tp: (write(tp, "s.V2A", v2a_component("N", touching(25), counts=(35, 25, 25))), {},
                                    r"line 35: the file ends inside component N.s data "
                                    r"\(header: 35, 25, 25 points; lines missing: 1\)"),
    "v2a truncated block": lambda tp: (write(tp, "tb.V2A", v2a_component("N", touching(25))[:28]), {},
                                       r"line 28: the file ends inside component N's data"),
    "v2a unknown component": lambda tp: (write(tp, "k.V2A", v2a_component("N10E", touching(5))), {"component": "EW"},
                                         r"component 'EW' not found; the file has: 0 N10E"),
    "v2a component index": lambda tp: (write(tp, "k2.V2A", v2a_component("N10E", touching(5))), {"component": 3},
                                       r"no component 3"),
    "at2 wrong header": lambda tp: (write(tp, "w.AT2", at2_text([0.1] * 5, "DT = 0.01")), {},
                                    r"line 4: expected 'NPTS= n, DT= dt SEC'"),
    "at2 not in g": lambda tp: (write(tp, "v.AT2", at2_text([0.1] * 5, "NPTS=  5, DT= .01 SEC", "VELOCITY IN CM/S")),
                                {},
                                r"line 3: expected '... IN UNITS OF G'"),
    "at2 fewer points": lambda tp: (write(tp, "f.AT2", at2_text([0.1] * 12, "NPTS=  20, DT=   .0100 SEC")), {},
                                    r"line 7: the file ends after 12 of the 20 points line 4 gives"),
    "at2 more points": lambda tp: (write(tp, "m.AT2", at2_text([0.1] * 12, "NPTS=  10, DT=   .0100 SEC")), {},
                                   r"line 7: more values than the 10 points"),
    "at2 non-numeric": lambda tp: (edited(tp, "x.AT2", at2_text([0.1] * 10, "10 .01 NPTS, DT"), 6, 16, 30,
                                          "  1.0000000F-01"), {}, r"line 6, column 2: '1.0000000F-01'"),
    "component of a one-component file": lambda tp: (write(tp, "o.dat", "0 0\n0.01 1\n"), {"component": "N"},
                                                     r"holds one component"),
}


@pytest.mark.parametrize("case", list(CASES))
def test_bad_input_names_file_and_line(tmp_path, case):
    path, kwargs, pattern = CASES[case](tmp_path)
    with pytest.raises(InputError) as err:
        read_motion(path, **kwargs)
    msg = str(err.value)
    assert msg.startswith(f"{path}: ") and "\n" not in msg, msg
    assert re.search(pattern, msg), msg


def test_the_shipped_el_centro_record_reads_by_name(tmp_path, monkeypatch):
    """The README's frame example names 'el-centro-1940', shipped with the
    package: 3995 samples at 0.02 s, PGA 0.313 g (its header, from the
    quakeio copy), read from any folder; a file of that name wins."""
    from fvd_bridge.records.motions import G_MM_S2, read_motion

    monkeypatch.chdir(tmp_path)
    m = read_motion("el-centro-1940")
    assert m.dt == 0.02 and m.accel.size == 3995
    assert np.max(np.abs(m.accel)) / G_MM_S2 == pytest.approx(0.3129, abs=1e-4)
    (tmp_path / "el-centro-1940").write_text("0 0.1\n0.01 0.2\n0.02 -0.1\n")
    assert read_motion("el-centro-1940").dt == 0.01
