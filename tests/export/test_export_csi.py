"""``fvd-bridge export sap2000`` / ``export etabs``: each file read back by
a parser of this test's own; its numbers against the calibration's converted
by hand; the link they define integrated by scipy's solve_ivp (its own
Maxwell equation) against the calibrated model's force on the calibration
record; its linear properties against the energy a steady cycle of that
integration dissipates; bad input refused in one line, nothing written.

The calibrations are made from known parameters on lab-like records (CSV
t,d,F with force and displacement noise, read back by fvd_bridge's reader:
v derived from the noisy d), so every number has an independent truth.
Neither SAP2000 nor ETABS runs here.
"""

from __future__ import annotations

import bisect
import math
import re
import shlex

import numpy as np
import pytest
import yaml
from scipy.integrate import quad, solve_ivp
from scipy.interpolate import CubicHermiteSpline

from fvd_bridge import cli
from fvd_bridge.calibration import Calibration
from fvd_bridge.calibration.parts import TestFit
from fvd_bridge.calibration.schema import record_provenance
from fvd_bridge.catalog import parse_model
from fvd_bridge.errors import InputError
from fvd_bridge.export.csi import (EXPONENTIAL, bilinear_energy, csi_link, effective, energy_factor,
                                   power_energy)
from fvd_bridge.export.opensees import EXACT_OF, SOLVING_DEFLECTION
from fvd_bridge.fit.objective import objective
from fvd_bridge.records.device import tested_range as range_of
from fvd_bridge.rig import VirtualDamper, Noise, paper
from fvd_bridge.rig.model_device import simulate_model

from lab import lab_from_forces, lab_record

#: by hand: 1 kip = 4.4482216 kN, 1 in = 25.4 mm, 1 kN = 1000 N, 1 m = 1000 mm
KIP, INCH = 4.4482216, 25.4
#: the devices: law 2 behind a series spring; law 2 alone; law 10 (K [kN/mm], C [kN s/mm], Fr [kN], p)
SERIES = {"C": 45.0, "alpha": 0.3, "series_stiffness.Ks": 150.0}
PLAIN = {"C": 45.0, "alpha": 0.3}
OIL = {"K": 100.0, "C": 1.0, "Fr": 250.0, "p": 0.1}


def calibration_file(path, rec, spec, values, tests=None):
    """A calibration file of ``spec`` with ``values`` (the truth) on the record ``rec``."""
    model = parse_model(spec)
    P = np.array([values[n] for n in model.names])
    cal = Calibration(model, P, of=float(objective(rec.F, model.force(rec, P[None, :])[0], rec.t)),
                      record=record_provenance(rec), device=rec.name,
                      tests=tests or (TestFit(rec.name, 1.0, None, range_of(rec), record_provenance(rec)),))
    return cal.save(str(path))  # not NAME.yaml beside NAME.csv: that is the record's sidecar


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    """Calibration files: 2+series_stiffness, 2 and 10 on their own lab-like records, 9 (for refusals)."""
    folder = tmp_path_factory.mktemp("csi")
    protocol = paper(amplitude=40.0, velocity=500.0, cycles=2, dt=0.002)
    files = {}
    rec = lab_record(VirtualDamper(C=45.0, alpha=0.3, Ks=150.0), protocol, 1.0, 0.005, seed=1, tmp_path=folder,
                     name="series")
    files["series"] = calibration_file(folder / "params" / "series.yaml", rec, "2+series_stiffness", SERIES)
    rec = lab_record(VirtualDamper(C=45.0, alpha=0.3), protocol, 1.0, 0.005, seed=2, tmp_path=folder, name="plain")
    files["plain"] = calibration_file(folder / "params" / "plain.yaml", rec, "2", PLAIN)
    exact = simulate_model(parse_model("10"), list(OIL.values()), paper(amplitude=40.0, velocity=400.0, cycles=2,
                                                                        dt=0.002), Noise(0.0, 0.0), name="oil")
    rec = lab_from_forces(exact.t, exact.d, exact.F, 1.0, 0.005, seed=3, tmp_path=folder, name="oil")
    files["oil"] = calibration_file(folder / "params" / "oil.yaml", rec, "10", OIL)
    files["lugre"] = calibration_file(folder / "params" / "lugre.yaml", rec, "9",
                                      {"C": 0.5, "alpha": 0.5, "beta": 50.0})
    return folder, files


# ------------------------------------------------------------------ readers of this test's own
def read_s2k(text: str) -> dict:
    """{table: [row {key: value}]} of a $2k file (values unquoted; numbers stay text)."""
    tables, current = {}, None
    for line in text.splitlines():
        if line.startswith("TABLE:"):
            current = tables.setdefault(line.split('"')[1], [])
        elif line.startswith("END TABLE DATA"):
            current = None
        elif current is not None and line.strip():
            current.append({k: v.strip('"') for k, v in re.findall(r'(\w+)=("[^"]*"|\S+)', line)})
    return tables


def read_e2k(text: str) -> dict:
    """{block: [line tokens]} of an .e2k file ('$ NAME' lines open blocks; tokens shell-split)."""
    blocks, current = {}, None
    for line in text.splitlines():
        if line.startswith("$ "):
            current = blocks.setdefault(line[2:].strip(), [])
        elif current is not None and line.strip():
            current.append(shlex.split(line) if '"' in line else line.split())
    return blocks


def export(target, path, out, *extra):
    return cli.main(["export", target, str(path), "-o", str(out), *extra])


def record_of(path):
    """The calibration and its record, read as calibrate read it."""
    from fvd_bridge.records.readers import read_as_stored

    cal = Calibration.load(str(path))
    return cal, read_as_stored(cal.record)


def travel(rec, scale=1.0):
    """The record's velocity between samples as fvd_bridge's series spring
    sees it (effects/connection.py ``series_advance``): the cubic Hermite
    interpolant of v and a, or the displacement increment spread evenly over
    a sample step where v jumps to or from 0 (the record's rests); times
    ``scale``."""
    t, v, d = rec.t, rec.v * scale, rec.d * scale
    c = CubicHermiteSpline(t, v, rec.a * scale).c.T.tolist()  # per step: cubic in s - t_i
    jump = ((v[:-1] == 0.0) != (v[1:] == 0.0)).tolist()
    slope = (np.diff(d) / np.diff(t)).tolist()
    times = t.tolist()

    def velocity(s):
        i = min(max(bisect.bisect_right(times, s) - 1, 0), len(times) - 2)
        if jump[i]:
            return slope[i]
        x, (c3, c2, c1, c0) = s - times[i], c[i]
        return ((c3 * x + c2) * x + c1) * x + c0

    return velocity


def maxwell(t, v, k, c, cexp, limit=None, cy=None, rtol=1e-7, max_step=None):
    """F(t) of a spring k in series with a dashpot under the velocity v(s)
    (a callable), from F = 0, by solve_ivp (Radau, the exact Jacobian; steps
    up to the samples' by default): dF/dt = k (v - v_c(F)), v_c = sign(F)(|F|/c)^(1/cexp); with
    a force limit: v_c = F/c up to it, sign(F)(limit/c + (|F| - limit)/cy)
    beyond."""
    def v_c(F):
        if limit is None:
            return math.copysign((abs(F) / c) ** (1.0 / cexp), F)
        return F / c if abs(F) <= limit else math.copysign(limit / c + (abs(F) - limit) / cy, F)

    def slope(F):  # dv_c/dF
        if limit is None:
            return (abs(F) / c) ** (1.0 / cexp - 1.0) / (cexp * c)
        return 1.0 / c if abs(F) <= limit else 1.0 / cy

    sol = solve_ivp(lambda s, y: [k * (v(s) - v_c(y[0]))], (t[0], t[-1]), [0.0], t_eval=t, method="Radau",
                    jac=lambda s, y: [[-k * slope(y[0])]], rtol=rtol, atol=rtol * max(1.0, c),
                    max_step=max_step or float(t[1] - t[0]))
    assert sol.success, sol.message
    return sol.y[0]


# ------------------------------------------------------------------ SAP2000
def test_s2k_row_is_the_calibration_in_kip_in_s(lab, tmp_path):
    """2+series_stiffness in kip, in, s: k = Ks 25.4/4.4482216, c = C 25.4^0.3/4.4482216, cexp = alpha;
    the tables and keys of SAP2000's own export."""
    _, files = lab
    out = tmp_path / "damper.s2k"
    assert export("sap2000", files["series"], out, "--units", "kip,in,s") == 0
    tables = read_s2k(out.read_text())
    assert tables["PROGRAM CONTROL"][0]["CurrUnits"] == "kip, in, F"
    (general,) = tables["LINK PROPERTY DEFINITIONS 01 - GENERAL"]
    assert general["Link"] == "FVD1" and general["LinkType"] == "Damper - Exponential"
    (row,) = tables["LINK PROPERTY DEFINITIONS 04 - DAMPER"]
    assert (row["Link"], row["DOF"], row["Fixed"], row["NonLinear"]) == ("FVD1", "U1", "No", "Yes")
    assert float(row["TransK"]) == pytest.approx(150.0 * INCH / KIP, rel=1e-12)
    assert float(row["TransC"]) == pytest.approx(45.0 * INCH ** 0.3 / KIP, rel=1e-12)
    assert float(row["CExp"]) == 0.3
    assert out.read_bytes().count(b"\r\n") == out.read_text().count("\n")  # CRLF, as SAP2000 writes


def test_s2k_link_integrated_reproduces_the_model(lab, tmp_path):
    """The link read back (kip, in, s), integrated by solve_ivp on the
    calibration record's motion, against the calibrated model's force: the
    same Maxwell equation, so OF within the exact-mapping bound of the
    OpenSees export (2e-4: fvd_bridge's one TR-BDF2 step a sample)."""
    _, files = lab
    out = tmp_path / "damper.s2k"
    assert export("sap2000", files["series"], out, "--units", "kip,in,s") == 0
    (row,) = read_s2k(out.read_text())["LINK PROPERTY DEFINITIONS 04 - DAMPER"]
    cal, rec = record_of(files["series"])
    F = maxwell(rec.t, travel(rec, 1.0 / INCH), float(row["TransK"]), float(row["TransC"]), float(row["CExp"])) * KIP
    of = objective(cal.force(rec), F, rec.t)
    assert of < EXACT_OF
    said = re.search(r"OF ([0-9.e-]+) \(eq. 18\)", out.read_text()).group(1)  # what the file says of its check
    assert float(said) == pytest.approx(of, abs=EXACT_OF)


def test_bilinear_row_and_force_in_N_mm_s(lab, tmp_path):
    """Law 10 as Damper - Bilinear in N, mm, s: TransK 1000 K, TransC 1000 C,
    TransCy 1000 p C, ForceLimit 1000 Fr; integrated, the oil damper's force
    within 2e-4 (its step form against solve_ivp: tests/laws/test_oil_damper.py)."""
    _, files = lab
    out = tmp_path / "oil.s2k"
    assert export("sap2000", files["oil"], out, "--units", "N,mm,s") == 0
    tables = read_s2k(out.read_text())
    assert tables["LINK PROPERTY DEFINITIONS 01 - GENERAL"][0]["LinkType"] == "Damper - Bilinear"
    (row,) = tables["LINK PROPERTY DEFINITIONS 14 - BILINEAR DAMPER"]
    got = {key: float(row[key]) for key in ("TransK", "TransC", "TransCy", "ForceLimit")}
    assert got == pytest.approx({"TransK": 1e5, "TransC": 1e3, "TransCy": 100.0, "ForceLimit": 2.5e5}, rel=1e-12)
    cal, rec = record_of(files["oil"])
    assert np.max(np.abs(cal.force(rec))) > 1.04 * OIL["Fr"]  # the relief valve opened in this test
    v = lambda s: np.interp(s, rec.t, rec.v)  # noqa: E731 (law 10's step: v linear over a sample)
    F = maxwell(rec.t, v, got["TransK"], got["TransC"], 1.0, got["ForceLimit"], got["TransCy"]) / 1000.0
    assert objective(cal.force(rec), F, rec.t) < EXACT_OF


# ------------------------------------------------------------------ ETABS
def test_e2k_without_series_spring_gets_the_stated_stiff_spring(lab, tmp_path):
    """Law 2 alone in N, mm, s: k = C v^alpha / (0.005 d) from the file's
    tested range, C 1000 C; the link with that spring integrated: it lags
    the dashpot by what the file states (OF 0.018 here: a spring that takes
    0.5% of the stroke, at alpha 0.3), within the integrator's 2e-4; a
    spring ten times stiffer (--spring-deflection 0.0005) lags less."""
    _, files = lab
    out = tmp_path / "damper.e2k"
    assert export("etabs", files["plain"], out, "--units", "N,mm,s") == 0
    text = out.read_text()
    blocks = read_e2k(text)
    assert blocks["PROGRAM INFORMATION"] == [["PROGRAM", "ETABS", "VERSION", "20.2.0"]]
    assert blocks["CONTROLS"] == [["UNITS", "N", "MM", "C"]]
    kind, dof = blocks["LINK PROPERTIES"]
    assert kind == ["LINKPROP", "FVD1", "TYPE", "DAMPER - EXPONENTIAL"]
    assert dof[:4] == ["LINKPROP", "FVD1", "DOF", "U1"]
    values = dict(zip(dof[4::2], dof[5::2]))
    tested = yaml.safe_load(open(files["plain"]))["tests"][0]["range"]
    k = 45.0 * tested["v"] ** 0.3 / (SOLVING_DEFLECTION * tested["d"]) * 1000.0
    assert float(values["K"]) == pytest.approx(k, rel=1e-12)
    assert float(values["C"]) == pytest.approx(45000.0, rel=1e-12) and float(values["EXP"]) == 0.3
    assert "no series spring (or a rigid one): a stiff spring that deflects 0.5% of the tested stroke" in text
    cal, rec = record_of(files["plain"])
    of = objective(cal.force(rec), maxwell(rec.t, travel(rec), k, 45000.0, 0.3, rtol=1e-6) / 1000.0, rec.t)
    said = float(re.search(r"OF ([0-9.e-]+) \(eq. 18\)", text).group(1))
    assert said == pytest.approx(of, abs=EXACT_OF) and 0.005 < of < 0.03
    assert export("etabs", files["plain"], out, "--units", "N,mm,s", "--spring-deflection", "0.0005") == 0
    stiffer = out.read_text()
    values = dict(zip(*[iter(read_e2k(stiffer)["LINK PROPERTIES"][1][4:])] * 2))
    assert float(values["K"]) == pytest.approx(10.0 * k, rel=1e-12)
    assert float(re.search(r"OF ([0-9.e-]+) \(eq. 18\)", stiffer).group(1)) < 0.4 * said


def steady_cycle(k, c, cexp, u0, frequency):
    """K', C' of the link's fourth cycle under u0 sin(omega t), integrated
    (``maxwell``): the first harmonic of its force, K' = 2/(T u0^2) integral
    F u dt, C' = W / (pi omega u0^2), W = integral F du."""
    w = 2.0 * math.pi * frequency
    t = np.linspace(0.0, 4 * 2 * math.pi / w, 4001)
    F = maxwell(t, lambda s: u0 * w * math.cos(w * s), k, c, cexp, max_step=0.5 / w / 100)
    last = t >= 3 * 2 * math.pi / w
    tc, Fc = t[last], F[last]
    K = 2.0 / ((tc[-1] - tc[0]) * u0 ** 2) * np.trapezoid(Fc * u0 * np.sin(w * tc), tc)
    return K, np.trapezoid(Fc * u0 * w * np.cos(w * tc), tc) / (math.pi * w * u0 ** 2)


def test_linear_properties_against_the_links_steady_cycle(lab, tmp_path):
    """TransKE, TransCE read back from the file (alpha 0.3, k 150 kN/mm, the
    design motion given: 30 mm, 1.5 Hz) against the link's own steady cycle:
    C' within 2% (the dashpot's energy at its own amplitude, exact for it
    alone; the spring makes its motion not quite a sine); K' from the
    linearized dashpot is the Maxwell model's, which a near-rectangular
    alpha-0.3 force overshoots in storage: half the cycle's 1.2 kN/mm here,
    within 10% of the loss stiffness omega C' (9.5 kN/mm), as docs/guide/csi.md says."""
    _, files = lab
    out = tmp_path / "damper.s2k"
    assert export("sap2000", files["series"], out, "--amplitude", "30", "--frequency", "1.5") == 0
    text = out.read_text()
    assert "u0 30 mm (given), f 1.5 Hz (given)" in text
    (row,) = read_s2k(text)["LINK PROPERTY DEFINITIONS 04 - DAMPER"]
    K, C = steady_cycle(float(row["TransK"]), float(row["TransC"]), float(row["CExp"]), 30.0, 1.5)
    assert float(row["TransCE"]) == pytest.approx(C, rel=0.02)
    assert abs(float(row["TransKE"]) - K) < 0.1 * 2.0 * math.pi * 1.5 * C


def test_linear_properties_are_exact_for_a_linear_dashpot():
    """With cexp = 1 the link is linear: K', C' of ``effective`` equal its
    steady cycle's (0.2%), where the spring takes two thirds of the stroke."""
    lin = effective(EXPONENTIAL, {"k": 150.0, "c": 45.0, "cexp": 1.0}, 30.0, 1.5)
    K, C = steady_cycle(150.0, 45.0, 1.0, 30.0, 1.5)
    assert lin.u_dashpot / 30.0 == pytest.approx(1.0 / 3.0, rel=0.01)
    assert (lin.ke, lin.ce) == pytest.approx((K, C), rel=2e-3)


def test_the_energy_per_cycle_against_quadrature():
    """lambda(1) = pi; the closed forms of the power-law (FEMA 356) and the
    bilinear dashpot's energy a cycle against scipy's quad of f(v) v dt."""
    assert energy_factor(1.0) == pytest.approx(math.pi, rel=1e-14)
    w, u0 = 2.0 * math.pi * 1.7, 25.0
    for alpha in (0.1, 0.3, 0.6, 1.0):
        W = quad(lambda s: 45.0 * abs(u0 * w * math.cos(w * s)) ** (alpha + 1.0), 0.0, 2 * math.pi / w)[0]
        assert power_energy(45.0, alpha, w, u0) == pytest.approx(W, rel=1e-9)
    for limit in (50.0, 250.0, 1e6):  # opened far, just, never
        def f(v):
            return v if abs(v) <= limit else math.copysign(limit + 0.1 * (abs(v) - limit), v)
        tr = math.acos(min(1.0, limit / (u0 * w)))  # the kinks: where the valve opens and closes
        kinks = [x / w for x in (tr, math.pi - tr, math.pi + tr, 2 * math.pi - tr)]
        W = quad(lambda s: f(u0 * w * math.cos(w * s)) * u0 * w * math.cos(w * s), 0.0, 2 * math.pi / w,
                 points=kinks, limit=200)[0]
        assert bilinear_energy(1.0, limit, 0.1, w, u0) == pytest.approx(W, rel=1e-9)


def test_law7_maxwell_and_the_oil_column_are_exponential_links():
    """Law 7 with beta 1 is the Maxwell model: k = K, behind a series spring
    K Ks / (K + Ks) (springs in series); an oil column's Ks is k; beta 1.2
    (a power-law spring) and a seal's friction are refused, naming the way;
    the Python call's bad arguments in Python's words."""
    tested = {"d": 40.0, "v": 500.0}
    law7 = {"C": 45.0, "alpha": 0.3, "K": 100.0, "beta": 1.0}
    assert csi_link("7", law7, tested=tested).native == {"k": 100.0, "c": 45.0, "cexp": 0.3}
    behind = csi_link("7+series_stiffness", {**law7, "series_stiffness.Ks": 150.0}, tested=tested)
    assert behind.native["k"] == pytest.approx(100.0 * 150.0 / 250.0, rel=1e-15)
    assert csi_link("2+oil_column", {**PLAIN, "oil_column.Ks": 150.0}, tested=tested).native["k"] == 150.0
    with pytest.raises(InputError, match=r"law 7 with beta = 1.2 .*'2\+series_stiffness'"):
        csi_link("7", {**law7, "beta": 1.2}, tested=tested)
    with pytest.raises(InputError, match=r"^frequency=0.0: must be a positive number$"):  # Python's words
        csi_link("2", PLAIN, tested=tested, frequency=0.0)
    with pytest.raises(InputError, match=r"^units='kN,m,ms': SAP2000 and ETABS work in seconds$"):
        csi_link("2", PLAIN, units="kN,m,ms", tested=tested)
    with pytest.raises(InputError, match="effect 'friction'"):
        csi_link("2+oil_column+friction", {**PLAIN, "oil_column.Ks": 150.0, "friction.Ff": 2.0,
                                           "friction.v_f": 1.0}, tested=tested)


# ------------------------------------------------------------------ what is refused
def one_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    return lines[0]


def test_what_no_link_expresses_is_refused_in_one_line(lab, tmp_path, capsys):
    """Law 9, unit sets CSI has not, bad outputs: exit 2, one line, nothing written."""
    _, files = lab
    out = tmp_path / "d.s2k"
    assert export("sap2000", files["lugre"], out) == 2
    line = one_line(capsys.readouterr().err)
    assert "law 9" in line and "laws 1 and 2" in line and "--laws 2+series_stiffness" in line
    for units, words in (("kN,m,ms", "seconds"), ("kip,m,s", "not a SAP2000/ETABS unit set"),
                         ("kN,furlong,s", "unknown unit 'furlong'")):
        assert export("etabs", files["series"], tmp_path / "d.e2k", "--units", units) == 2
        assert words in one_line(capsys.readouterr().err)
    assert export("etabs", files["series"], tmp_path / "d.s2k") == 2
    assert "the suffix must be .e2k" in one_line(capsys.readouterr().err)
    assert export("sap2000", files["series"], tmp_path / "missing" / "d.s2k") == 2
    assert "does not exist" in one_line(capsys.readouterr().err)
    assert export("sap2000", files["series"], out, "--frequency", "0") == 2
    assert "--frequency 0.0: must be a positive number" in one_line(capsys.readouterr().err)
    assert list(tmp_path.iterdir()) == []


def test_a_parameter_fitted_per_test_takes_the_test_named(lab, tmp_path, capsys):
    """C fitted per test (A 40, B 52): refused without --test, test B's C with it."""
    folder, files = lab
    cal, rec = record_of(files["plain"])
    tests = tuple(TestFit(name, 1.0, None, range_of(rec), record_provenance(rec), {"C": c})
                  for name, c in (("A", 40.0), ("B", 52.0)))
    path = calibration_file(tmp_path / "per_test.yaml", rec, "2", {"C": 40.0, "alpha": 0.3}, tests)
    out = tmp_path / "d.s2k"
    assert export("sap2000", path, out) == 2
    assert "--test A or --test B" in one_line(capsys.readouterr().err) and not out.exists()
    assert export("sap2000", path, out, "--test", "B") == 0
    (row,) = read_s2k(out.read_text())["LINK PROPERTY DEFINITIONS 04 - DAMPER"]
    assert float(row["TransC"]) == 52.0
