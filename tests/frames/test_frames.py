"""Frames for damper comparisons: benchmark periods, a one-story frame against
the closed-form SDOF response, the 3-story frame bare and with dampers."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from types import SimpleNamespace

import numpy as np
import pytest

from fvd_bridge.errors import InputError
from fvd_bridge.frames.analysis import run_frame
from fvd_bridge.frames.buildings import TONNE, W_SHAPES, Building, Section, nine_story, three_story
from fvd_bridge.frames.model import build_frame, frame_commands, frame_periods
from fvd_bridge.opensees_commands import to_script
from fvd_bridge.records.motions import G_MM_S2 as G
from fvd_bridge.rig.energy import loop_area

TAG = 1000


def viscous(C: float, alpha: float) -> list[tuple]:
    """Damper commands: F = C sign(v)|v|^alpha [kN], v [mm/s]."""
    return [("uniaxialMaterial", "Viscous", TAG, C, alpha)]


def sine_motion(seconds: float, freq: float, pga_g: float, dt: float) -> SimpleNamespace:
    """A GroundMotion-like input: accel = pga sin(2 pi f t) [mm/s^2]."""
    t = np.arange(int(round(seconds / dt)) + 1) * dt
    return SimpleNamespace(name=f"sine {freq} Hz", dt=dt, accel=pga_g * G * np.sin(2 * np.pi * freq * t))


@pytest.fixture(scope="module")
def sine_runs():
    """The 3-story frame under 5 s of a 1 Hz sine at 0.2 g: bare, with a
    linear viscous damper (C = 2 kN s/mm), with an alpha = 0.3 damper."""
    b, motion = three_story(), sine_motion(5.0, 1.0, 0.2, 0.01)
    return {"bare": run_frame(b, motion),
            "linear": run_frame(b, motion, viscous(2.0, 1.0), TAG),
            "alpha03": run_frame(b, motion, viscous(60.0, 0.3), TAG)}


# ------------------------------------------------------------------ buildings


@pytest.mark.parametrize("make", [three_story, nine_story])
def test_eigen_frequencies_match_the_benchmark(make):
    """The benchmark's first three frequencies (Ohtori et al. 2004: 0.99,
    3.06, 5.83 Hz; 0.443, 1.18, 2.05 Hz) within 0.2% (measured 0.1%)."""
    b = make()
    f = 1.0 / frame_periods(b, n_modes=3)
    ref = 1.0 / np.asarray(b.reference_periods)
    assert ref == pytest.approx([0.99, 3.06, 5.83] if make is three_story else [0.443, 1.18, 2.05])
    assert np.all(np.abs(f / ref - 1.0) < 0.002), (f, ref)
    assert f[0] < f[1] < f[2]


def test_a_pinned_beam_end_is_a_moment_release():
    """The 9-story's bay-5 beams end on a stiff zeroLength pin at line 6: the
    elastic frame's frequencies equal those of elasticBeamColumn's own moment
    release (-release 2) to 6 digits, with forceBeamColumn members too."""
    import openseespy.opensees as ops
    from fvd_bridge.frames.model import structure_commands
    from fvd_bridge.opensees_commands import apply

    b = nine_story().with_(yielding=False, pinned_lines=())
    released = [c + ("-release", 2) if c[0] == "element" and c[2] >= 2000 and c[2] % 100 == 4 else c
                for c in structure_commands(b)]
    apply(released, ops)
    ref = np.asarray(ops.eigen("-fullGenLapack", 3))
    ops.wipe()
    for yielding in (False, True):
        f = 1.0 / frame_periods(nine_story().with_(yielding=yielding), n_modes=3)
        assert f == pytest.approx(np.sqrt(ref) / (2 * np.pi), rel=1e-6)
    assert 1.0 / frame_periods(b, n_modes=1)[0] > 1.05 * f[0]   # without the pins: 7% stiffer
    # an interior line pinned: each of its two beams on its own pin (release 2 on the left beam, 1 on the right)
    release = {1: 2, 2: 1}
    released = [c + ("-release", release[c[2] % 100]) if c[0] == "element" and c[2] >= 2000 and c[2] % 100 in release
                else c for c in structure_commands(b)]
    apply(released, ops)
    ref = np.asarray(ops.eigen("-fullGenLapack", 3))
    ops.wipe()
    f = 1.0 / frame_periods(b.with_(pinned_lines=(2,)), n_modes=3)
    assert f == pytest.approx(np.sqrt(ref) / (2 * np.pi), rel=1e-6)


def test_benchmark_masses_per_frame():
    assert three_story().mass_above_grade == pytest.approx(1477.0 * TONNE)     # (2 x 9.57e5 + 1.04e6) / 2 kg
    assert nine_story().mass_above_grade == pytest.approx(4501.5 * TONNE)      # 9.00e6 / 2 kg
    assert three_story().stories == 3 and nine_story().stories == 9
    assert nine_story().elevations[-1] - nine_story().elevations[1] == pytest.approx(37190.0, rel=1e-3)  # 37.19 m
    assert three_story().elevations[-1] == pytest.approx(11890.0, rel=1e-3)                         # 11.89 m


def test_building_refuses_inconsistent_data():
    b = three_story()
    with pytest.raises(InputError, match="floor_masses"):
        b.with_(floor_masses=b.floor_masses[:2])
    with pytest.raises(InputError, match="damper_bay"):
        b.with_(damper_bay=4)
    with pytest.raises(InputError, match="damper_tag"):
        run_frame(b, sine_motion(0.1, 1.0, 0.1, 0.01), viscous(1.0, 1.0), damper_tag=7)


# ------------------------------------------------------- one-story = SDOF


def one_story(mass: float) -> Building:
    """One bay, one story, elastic, no inherent damping; columns with a huge
    area so the diagonal damper cannot shorten them (a true SDOF)."""
    w = W_SHAPES["W14X311"].strong
    col = Section("W14X311, rigid axially", 1e7, w.inertia, w.plastic_modulus, w.depth)
    return Building(name="one story", story_heights=(3960.0,), bay_widths=(9150.0,), floor_masses=(mass,),
                    columns=((col, col),), beams=((W_SHAPES["W33X118"].strong,),), yielding=False,
                    damping_ratio=0.0, damping_modes=(1, 1))


def harmonic_sdof(m, c, k, amp, omega, t):
    """Closed form of m u'' + c u' + k u = -m amp sin(omega t), u(0) = u'(0) = 0:
    steady state a sin + b cos, plus the damped free vibration that cancels
    its initial values."""
    D = (k - m * omega ** 2) ** 2 + (c * omega) ** 2
    a, b = -m * amp * (k - m * omega ** 2) / D, m * amp * c * omega / D
    wn = math.sqrt(k / m)
    zeta = c / (2 * m * wn)
    wd = wn * math.sqrt(1 - zeta ** 2)
    B1 = -b
    B2 = (zeta * wn * B1 - a * omega) / wd
    return (a * np.sin(omega * t) + b * np.cos(omega * t)
            + np.exp(-zeta * wn * t) * (B1 * np.cos(wd * t) + B2 * np.sin(wd * t)))


def test_one_story_with_linear_damper_matches_closed_form():
    m, C = 0.3, 0.5                                  # kN s^2/mm (300 t), kN s/mm
    b = one_story(m)
    T = frame_periods(b)[0]
    k = m * (2 * np.pi / T) ** 2                     # story stiffness from the same model [kN/mm]
    theta = b.damper_angle[0]
    assert theta == pytest.approx(math.atan2(3960.0, 9150.0))
    c = C * math.cos(theta) ** 2                     # horizontal share of the diagonal dashpot
    omega, amp = 0.8 * 2 * np.pi / T, 0.1 * G
    motion = sine_motion(4.0, omega / (2 * np.pi), 0.1, 0.002)
    r = run_frame(b, motion, viscous(C, 1.0), TAG, free_vibration=0.0)
    exact = harmonic_sdof(m, c, k, amp, omega, r.t)
    assert 0.03 < c / (2 * m * 2 * np.pi / T) < 0.3  # a damping ratio worth checking
    assert r.solver.completed and r.solver.split_steps == 0
    assert np.max(np.abs(r.floor_displacement[:, 0] - exact)) < 0.01 * np.max(np.abs(exact))
    # the damper reads the diagonal: Delta = u cos(theta), F = C dDelta/dt
    assert np.allclose(r.damper_deformation[:, 0], r.floor_displacement[:, 0] * math.cos(theta),
                       atol=1e-3 * np.max(np.abs(r.damper_deformation)))


def test_stiff_brace_in_series_acts_as_rigid():
    b = one_story(0.3)
    motion = sine_motion(2.0, 2.0, 0.1, 0.005)
    rigid = run_frame(b, motion, viscous(0.5, 1.0), TAG)
    braced = run_frame(b.with_(brace_stiffness=1e5), motion, viscous(0.5, 1.0), TAG)
    soft = run_frame(b.with_(brace_stiffness=5.0), motion, viscous(0.5, 1.0), TAG)
    peak = np.max(np.abs(rigid.floor_displacement))
    assert np.max(np.abs(braced.floor_displacement - rigid.floor_displacement)) < 0.005 * peak
    assert soft.total_damper_energy < rigid.total_damper_energy   # a soft brace takes stroke from the damper


# ------------------------------------------------------------ 3-story frame


def test_bare_three_story_runs_with_plausible_drifts(sine_runs):
    r = sine_runs["bare"]
    assert r.solver.completed and r.solver.message == ""
    assert r.t[-1] == pytest.approx(10.0)            # 5 s record + 5 s free vibration
    assert np.all(np.isfinite(r.drift_ratio)) and np.all(np.isfinite(r.residual_drift_ratio))
    assert 0.002 < r.max_drift_ratio < 0.05          # near resonance (T1 ~ 1 s) at 0.2 g
    assert np.all(r.peak_floor_acceleration_g > 0.15) and np.all(r.peak_floor_acceleration_g < 3.0)
    assert r.ground_acceleration.max() == pytest.approx(0.2 * G, rel=1e-3)
    assert r.damper_force is None and r.damper_energy is None
    assert r.drift_ratio.shape == (r.t.size, 3) and r.floor_acceleration.shape == (r.t.size, 3)


def test_linear_damper_cuts_drift_and_its_energy_is_the_loop(sine_runs):
    bare, r = sine_runs["bare"], sine_runs["linear"]
    assert r.solver.completed
    assert r.max_drift_ratio < 0.85 * bare.max_drift_ratio   # 5 s at resonance (T1 1.00 s): 17% less
    assert np.all(r.peak_drift_ratio < bare.peak_drift_ratio)
    E = r.damper_energy
    assert np.all(E > 0)
    # 1) the closed loop's area (shoelace, fvd_bridge.rig.energy): the motion has died out at the end
    loops = np.array([loop_area(r.damper_deformation[:, i], r.damper_force[:, i]) for i in range(3)])
    assert np.allclose(E, loops, rtol=1e-3)
    # 2) integral of F v dt with v = F / C: Newmark's dDelta = dt (v_k + v_k+1) / 2 makes it exact
    F, dt = r.damper_force, np.diff(r.t)[:, None]
    assert np.allclose(E, np.sum(dt * (F[1:] + F[:-1]) ** 2 / (4 * 2.0), axis=0), rtol=1e-6)
    assert r.total_damper_energy == pytest.approx(E.sum())
    assert np.all(r.peak_damper_force > 0) and np.all(r.peak_damper_stroke > 0)


def test_alpha_03_damper_completes_and_reports_the_solver(sine_runs):
    r = sine_runs["alpha03"]
    s = r.solver
    assert s.completed, s.message
    assert s.algorithms_used and all(name in s.algorithm_steps for name in s.algorithms_used)
    assert sum(s.algorithm_steps.values()) >= r.t.size - 1      # every step done by some algorithm
    assert s.smallest_step <= 0.01
    assert r.max_drift_ratio < sine_runs["bare"].max_drift_ratio
    assert np.all(r.damper_energy > 0)
    summary = r.summary()
    assert summary["solver"]["algorithm_steps"] == s.algorithm_steps
    assert summary["peak_damper_force_kN"] == pytest.approx(list(r.peak_damper_force))


def test_without_damper_recording_the_damper_fields_are_none():
    r = run_frame(three_story().with_(yielding=False), sine_motion(1.0, 1.0, 0.1, 0.01), viscous(1.0, 1.0), TAG,
                  record_dampers=False, free_vibration=1.0)
    assert r.damper_force is None and r.damper_energy is None and r.summary()["peak_damper_force_kN"] is None
    assert r.solver.converged


def test_el_centro_through_the_motion_reader(shared_dir):
    from fvd_bridge.records.motions import read_text

    path = shared_dir / "records" / "elcentro_1940_NS_2688pts_g_dt0.02.dat"
    if not path.is_file():
        pytest.skip(f"{path} is absent")
    motion = read_text(path, units="g").window(10.0)
    r = run_frame(three_story(), motion)
    assert r.solver.converged and r.record_end == pytest.approx(10.0)
    assert 0.003 < r.max_drift_ratio < 0.03             # PGA 0.35 g on a 1 s frame
    assert r.ground_acceleration.max() <= motion.pga_g * G + 1e-9


# ------------------------------------------------------- the frame as commands


def test_frame_commands_make_a_script_that_runs_without_fvd_bridge(tmp_path):
    """The 3-story frame with a damper material, written as an OpenSeesPy
    script: plain openseespy runs it, and its eigen periods are frame_periods'
    (the Viscous links add no stiffness)."""
    b = three_story()
    commands = frame_commands(b, viscous(2.0, 0.5), TAG)
    assert commands[0] == ("wipe",) and ("uniaxialMaterial", "Viscous", TAG, 2.0, 0.5) in commands
    assert sum(c[:2] == ("element", "twoNodeLink") for c in commands) == 3
    model = build_frame(b, viscous(2.0, 0.5), TAG)
    assert commands == frame_commands(b, viscous(2.0, 0.5), TAG, rayleigh=model.rayleigh)
    assert ("rayleigh", model.rayleigh[0], 0.0, model.rayleigh[1], 0.0) in commands
    script = to_script(commands, "py")
    assert "fvd_bridge" not in script and "np." not in script
    path = tmp_path / "frame3.py"
    path.write_text(script + "import json, math\n"
                    "print(json.dumps([2 * math.pi / math.sqrt(x) for x in ops.eigen('-fullGenLapack', 3)]))\n")
    res = subprocess.run([sys.executable, str(path)], capture_output=True, text=True, timeout=120,
                         cwd=tmp_path, env={**os.environ, "PYTHONPATH": ""})
    assert res.returncode == 0, res.stderr
    periods = json.loads(res.stdout.strip().splitlines()[-1])
    assert np.allclose(periods, frame_periods(b), rtol=1e-9, atol=0.0)
    tcl = to_script(commands, "tcl").splitlines()
    assert tcl[0] == "wipe" and tcl[1] == "model basic -ndm 2 -ndf 3" and any(s.startswith("rayleigh ") for s in tcl)
