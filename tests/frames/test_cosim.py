"""Co-simulation with the damper FMU: the two examples on a 3 s window of El
Centro (a master in FMPy's low-level API with an SDOF; OpenSees' 3-story
frame with one FMU per story) against OpenSees' native materials; the
OpenSees rollback; the frame co-simulation against a native run at law 2's
velocity reversals; and a second FMI importer, fmu-manipulation-toolbox
(its checker, and its container runtime loading and stepping the FMU)."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("fmpy")

from fvd_bridge.calibration import Calibration  # noqa: E402
from fvd_bridge.errors import InputError  # noqa: E402
from fvd_bridge.export.fmu import build_fmu, sampled_input, simulate  # noqa: E402
from fvd_bridge.fit.objective import objective  # noqa: E402
from fvd_bridge.frames.buildings import three_story  # noqa: E402
from fvd_bridge.records.motions import G_MM_S2, GroundMotion  # noqa: E402
from fvd_bridge.golden import GOLDEN_DIR, REFERENCE, golden_record, read_golden  # noqa: E402
from fvd_bridge.catalog import parse_model  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = ("fmu_cosim.py", "opensees_fmu_cosim.py")

toolchain = pytest.mark.skipif(shutil.which("cmake") is None or shutil.which("cc") is None,
                               reason="building an FMU needs cmake and a C compiler")


def run_example(name, *args, cwd, script=None):
    return subprocess.run([sys.executable, str(script or REPO / "examples" / name), *args],
                          capture_output=True, text=True, cwd=cwd, timeout=600)


@pytest.fixture(scope="module")
def fmus(tmp_path_factory):
    """law -> FMU of the golden reference parameters, each built once."""
    cache = {}

    def get(law: int) -> str:
        if law not in cache:
            model = parse_model(str(law))
            cal = Calibration(model, np.array(REFERENCE[law], dtype=float), of=0.0)
            cache[law] = build_fmu(cal, tmp_path_factory.mktemp("fmu") / f"law{law}.fmu")
        return cache[law]
    return get


def synthetic_motion(duration: float = 3.0, dt: float = 0.02) -> GroundMotion:
    t = np.arange(0.0, duration + 1e-9, dt)
    return GroundMotion("synthetic", dt, 0.3 * G_MM_S2 * np.sin(2 * np.pi * 1.2 * t) * np.minimum(1.0, t), {})


# ------------------------------------------------------------------ examples
@toolchain
def test_fmu_cosim_example(shared_dir, tmp_path):
    """SDOF under 3 s of El Centro, laws 2 and 7 (h = 5 ms): the iterative
    master reproduces OpenSees' Viscous / ViscousDamper SDOF (measured: peak
    u 4e-12 / 2e-8, peak F 6e-13 / 2e-6, OF 3e-11 / 5e-6, 7.0-7.3 FMU steps per
    step); the explicit master lags (peak u +0.9-1.0%, OF 0.011-0.013)."""
    out = tmp_path / "sdof"
    res = run_example("fmu_cosim.py", "--duration", "3", "--out", str(out), cwd=tmp_path)
    assert res.returncode == 0, res.stderr[-3000:]
    assert "iterative" in res.stdout and "explicit" in res.stdout
    summary = json.loads((out / "summary.json").read_text())
    assert summary["steps"] == 600 and set(summary["laws"]) == {"2", "7"}
    for law, rows in summary["laws"].items():
        it, ex = rows["iterative"], rows["explicit"]
        assert abs(it["peak_u_rel"]) <= 1e-6 and abs(it["peak_F_rel"]) <= 1e-5, law
        assert it["of"] <= 1e-4, law
        assert it["fmu_steps_per_step"] <= 12, law
        assert abs(ex["peak_u_rel"]) <= 0.03 and ex["of"] <= 0.05, law
        assert ex["of"] > 100 * it["of"], law
    assert (out / "law2.fmu").is_file() and (out / "law7.fmu").is_file()


@toolchain
def test_opensees_fmu_cosim_example(shared_dir, tmp_path):
    """3-story frame (elastic members), law 7, 3 s of El Centro (h = 5 ms):
    the iterative co-simulation reproduces run_frame with ViscousDamper
    (measured: max drift 1.5e-7, peak forces 3e-6, OF 8e-6) in 2.00
    OpenSees solves and about 4 FMU steps per damper per step; the explicit
    one within 0.4% drift, 0.6% force, OF 0.016."""
    out = tmp_path / "frame"
    res = run_example("opensees_fmu_cosim.py", "--duration", "3", "--out", str(out), cwd=tmp_path)
    assert res.returncode == 0, res.stderr[-3000:]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["law"] == 7 and summary["members"] == "elastic"
    it, ex = summary["iterative"], summary["explicit"]
    assert it["completed"] and ex["completed"] and it["steps"] == 600
    assert abs(it["max_drift_rel"]) <= 1e-5 and it["max_force_rel"] <= 1e-4 and max(it["of"]) <= 1e-4
    assert it["unconverged_steps"] == 0 and it["opensees_solves_per_step"] <= 2.05
    assert it["fmu_steps_per_damper_step"] <= 8
    assert abs(ex["max_drift_rel"]) <= 0.02 and ex["max_force_rel"] <= 0.03 and max(ex["of"]) <= 0.05
    assert ex["opensees_solves_per_step"] == 1.0


@pytest.mark.parametrize("name", EXAMPLES)
def test_examples_note_a_missing_record(name, tmp_path):
    """Without ../shared the examples say so and exit 0."""
    script = tmp_path / "repo" / "examples" / name
    script.parent.mkdir(parents=True)
    shutil.copy(REPO / "examples" / name, script)
    res = run_example(name, "--out", str(tmp_path / "out"), cwd=tmp_path, script=script)
    assert res.returncode == 0, res.stderr
    assert "is absent; nothing to do" in res.stdout


# ------------------------------------------------------------ frame co-simulation
def test_node_checkpoint_repeats_steps_bit_for_bit():
    """Saving the nodes' committed state, going on with changing damper loads,
    restoring and repeating gives the same response, bit for bit (elastic members)."""
    import openseespy.opensees as ops

    from fvd_bridge.frames.cosim import FrameDampers, NodeCheckpoint
    from fvd_bridge.frames.model import build_frame
    from fvd_bridge.frames.transient import start_transient

    motion = synthetic_motion()
    building = three_story().with_(yielding=False)
    model = build_frame(building)
    start_transient(motion.dt, motion.accel)
    dampers = FrameDampers(building)
    checkpoint = NodeCheckpoint()

    def steps(k0, k1):
        out = []
        for k in range(k0, k1):
            dampers.set_forces([50.0 * np.sin(k / 5.0), -20.0, 10.0 * np.cos(k / 3.0)])
            assert ops.analyze(1, motion.dt) == 0
            out.append([ops.nodeDisp(n, 1) for n in model.floor_nodes] + list(np.concatenate(dampers.read())))
        return np.array(out)

    steps(0, 60)
    checkpoint.save()
    first = steps(60, 100)
    checkpoint.restore()
    again = steps(60, 100)
    ops.wipe()
    assert np.array_equal(first, again)
    assert np.ptp(first[:, 0]) > 1.0  # the frame does move


def test_iterative_cosimulation_refuses_yielding_members():
    from fvd_bridge.frames.cosim import cosimulate_frame

    with pytest.raises(InputError, match="yielding=False"):
        cosimulate_frame(three_story(), synthetic_motion(), "unused.fmu", "iterative")
    with pytest.raises(InputError, match="scheme"):
        cosimulate_frame(three_story(), synthetic_motion(), "unused.fmu", "implicit")


@toolchain
def test_frame_cosimulation_through_law2_reversals(fmus, monkeypatch):
    """Law 2 (alpha 0.3: the force ~|v|^0.3 at velocity reversals) in the
    elastic 3-story frame, 3 s of a synthetic motion at h = 20 ms: the
    iterative co-simulation equals the native Viscous frame solved without
    step halving (Newton allowed 200 iterations) within OF 0.005: Newton
    diverges at one reversal (t = 0.5 s), which KrylovNewton completes, and
    that step moves the native force by OF 0.0025 (before it the two agree
    to 3e-5 of the peak force)."""
    from fvd_bridge.export.opensees import opensees_export
    from fvd_bridge.frames import analysis, transient
    from fvd_bridge.frames.cosim import cosimulate_frame

    monkeypatch.setattr(transient, "ALGORITHMS", tuple((a, (t[0], t[1], 200)) for a, t in transient.ALGORITHMS))
    motion = synthetic_motion()
    building = three_story().with_(yielding=False)
    model = parse_model("2")
    commands = opensees_export(model, dict(zip(model.names, REFERENCE[2])), 1000).commands
    native = analysis.run_frame(building, motion, commands, 1000, free_vibration=0.0)
    assert native.solver.split_steps == 0 and native.solver.completed
    result, stats = cosimulate_frame(building, motion, fmus(2), "iterative")
    assert result.solver.completed and stats.unconverged == 0 and stats.opensees_solves == 2.0
    for i in range(3):
        assert objective(native.damper_force[:, i], result.damper_force[:, i], result.t) <= 0.005
    before = result.t < 0.49
    peak = np.max(np.abs(native.damper_force))
    assert np.max(np.abs(native.damper_force[before] - result.damper_force[before])) <= 1e-4 * peak
    assert abs(result.max_drift_ratio / native.max_drift_ratio - 1.0) <= 1e-3


@toolchain
def test_frame_runs_a_model_opensees_cannot_hold_through_its_fmu():
    """``frame``'s cases: law 9 with an asymmetry of 1e-9 (OpenSees has no
    material for the asymmetry, the FMU carries it; at that size it is law 9)
    in the yielding 3-story frame, 3 s of a synthetic motion and the free
    vibration, runs by the explicit co-simulation at COSIM_STEP and lands on
    the native law-9 frame (BoucWen + Viscous) solved at the same step: peak
    drift within 0.2%, damper force within 0.5%, the force histories within
    OF 0.01 (measured 0.01%, 0.04%, 0.007: the one-step force lag and
    BoucWen's implicit Euler step differ)."""
    from fvd_bridge.frames.compare import COSIM_STEP, run_cases

    law9 = Calibration(parse_model("9"), np.array(REFERENCE[9], dtype=float), of=0.1, device="native")
    asym = Calibration(parse_model("9+asymmetry"), np.array([*REFERENCE[9], 1e-9]), of=0.1, device="fmu")
    bare, native, fmu = run_cases(three_story(), synthetic_motion(), [law9, asym], dt_analysis=COSIM_STEP)
    assert not native.fmu and fmu.fmu and "co-simulated with its FMU" in fmu.note
    assert fmu.result is not None and fmu.result.solver.completed
    n, f = native.values(), fmu.values()
    assert abs(f["drift"] / n["drift"] - 1.0) <= 0.002 and abs(f["force"] / n["force"] - 1.0) <= 0.005
    assert f["drift"] < 0.95 * bare.values()["drift"]  # the dampers act
    for i in range(3):
        assert objective(native.result.damper_force[:, i], fmu.result.damper_force[:, i], fmu.result.t) <= 0.01


# -------------------------------------------------------- a second FMI importer
def _toolbox(cli: str, *args, cwd):
    """Run a fmu-manipulation-toolbox command line (fmutool, fmucontainer)."""
    code = f"import sys; from fmu_manipulation_toolbox.cli.{cli} import {cli}; sys.exit({cli}())"
    return subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True, cwd=cwd,
                          timeout=300)


@toolchain
def test_fmu_manipulation_toolbox_checks_the_fmu(fmus):
    """Its checker validates modelDescription.xml against the FMI 3.0 XSD
    and its semantic rules."""
    pytest.importorskip("fmu_manipulation_toolbox")
    res = _toolbox("fmutool", "-input", fmus(2), "-check", cwd=Path(fmus(2)).parent)
    log = res.stdout + res.stderr
    assert res.returncode == 0, log
    assert "compliant with FMI-3.0" in log and "No semantic error" in log


@toolchain
def test_fmu_manipulation_toolbox_container_runs_the_fmu(fmus, tmp_path):
    """fmu-manipulation-toolbox's container runtime (its own C importer)
    loads the damper FMU's binary and steps it inside a container FMU: the
    force on the law-2 golden input equals FMPy's direct run to 1e-9 of the
    peak force."""
    pytest.importorskip("fmu_manipulation_toolbox")
    from fmpy import simulate_fmu

    shutil.copy(fmus(2), tmp_path / "law2.fmu")
    (tmp_path / "box.csv").write_text("rule;from_fmu;from_port;to_fmu;to_port\n"
                                      "FMU;law2.fmu;;;\n"
                                      "INPUT;;d;law2.fmu;d\nINPUT;;v;law2.fmu;v\nINPUT;;a;law2.fmu;a\n"
                                      "OUTPUT;law2.fmu;F;;F\nOUTPUT;law2.fmu;E;;E\n")
    _, cols = read_golden(GOLDEN_DIR / "law2.csv")
    record = golden_record(cols)
    res = _toolbox("fmucontainer", "-container", f"box.csv:{record.dt}", "-fmi", "3", "-no-auto-input",
                   "-no-auto-output", cwd=tmp_path)
    assert res.returncode == 0 and (tmp_path / "box.fmu").is_file(), res.stdout + res.stderr
    boxed = simulate_fmu(str(tmp_path / "box.fmu"), start_time=record.t[0], stop_time=record.t[-1],
                         step_size=record.dt, output_interval=record.dt,
                         input=sampled_input(record, ("d",)), output=["F"])
    direct = simulate(fmus(2), record)["F"]
    assert boxed.size == record.t.size
    assert np.max(np.abs(boxed["F"] - direct)) <= 1e-9 * np.max(np.abs(direct))
    assert np.ptp(direct) > 100.0
