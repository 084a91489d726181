"""The seams the exporters build on: models as objects, the catalog, the
calibration file as a contract, the campaign executor, the CLI's parser, the
Python API of the README."""

import os
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml

from conftest import CLI, PLUGIN, cli_env
from fvd_bridge.calibration import Calibration
from fvd_bridge.catalog import catalog, parse_model
from fvd_bridge.errors import InputError
from fvd_bridge.records import read_record
from fvd_bridge.rig import VirtualDamper, Noise, paper, simulate

REPO = Path(__file__).resolve().parents[2]
FIXTURES = REPO / "tests" / "fixtures"


@pytest.fixture(scope="module")
def lab_csv(tmp_path_factory):
    """A rig device written as a lab would: other column names and units (ms, m, N)."""
    rec = simulate(VirtualDamper(C=45.4, alpha=0.3, friction=3.0), paper(cycles=3), Noise(force=1.0, displacement=0.005), seed=2)
    path = tmp_path_factory.mktemp("lab") / "lab_dev.csv"
    rows = ["time,disp,load"] + [f"{t * 1e3:.6f},{d * 1e-3:.9f},{F * 1e3:.6f}"
                                 for t, d, F in zip(rec.t, rec.d, rec.F)]
    path.write_text("\n".join(rows) + "\n")
    return path


# ------------------------------------------------------------- models as objects
def test_model_operations_nest_and_refuse_clashes():
    base = parse_model("2")
    m = base.with_effect(catalog().effect("friction")).with_effect(catalog().effect("gap"))
    assert m.spec == "2+friction+gap" and m.names == ["C", "alpha", "friction.Ff", "gap.g"]
    assert m.without_effect("gap").spec == "2+friction" and m.columns_without("friction") == [0, 1, 3]
    with pytest.raises(InputError, match="appears twice"):
        m.with_effect(catalog().effect("gap"))
    with pytest.raises(InputError, match="has no effect 'inertia'"):
        m.without_effect("inertia")
    law8 = parse_model("8+asymmetry")
    assert law8.derived([0.1, 50.0, 0.4, 250.0, 0.1]) == {"mu*N": (pytest.approx(100.0), "kN")}
    # the effect switched off reproduces the model without it, row by row
    rec = simulate(VirtualDamper(C=45.4, alpha=0.3), paper(cycles=2), seed=0)
    P = np.array([[45.0, 0.3, 0.0, 0.0], [40.0, 0.35, 0.0, 0.0]])
    assert np.allclose(m.force(rec, P), base.force(rec, P[:, :2]), rtol=0, atol=1e-9)


def test_catalog_loads_plugins_once_per_process(tmp_path):
    path = tmp_path / "plug.py"
    path.write_text(PLUGIN)
    a, b = catalog([str(path)]), catalog((str(path),))
    assert a is b and "cubic_spring" in a.effects and "cubic_spring" not in catalog().effects
    assert a.model("2+cubic_spring").names[-1] == "cubic_spring.K3"
    with pytest.raises(InputError, match="unknown effect 'cubic_spring'"):
        catalog().model("2+cubic_spring")


# ------------------------------------------------------ the calibration contract
@pytest.mark.parametrize("name, spec", [("law8.yaml", "8"), ("law2+friction.yaml", "2+friction")])
def test_schema_1_files_still_read(name, spec):
    cal = Calibration.load(str(FIXTURES / "calibration_v1" / name))
    raw = yaml.safe_load(open(FIXTURES / "calibration_v1" / name))
    assert raw["schema_version"] == 1 and cal.spec == spec
    assert cal.named() == {k: v["value"] for k, v in raw["parameters"].items()}
    assert cal.of == raw["of"] and cal.record.columns is None
    if spec == "8":
        p = cal.named()
        assert cal.derived()["mu*N"][0] == pytest.approx(p["mu"] * p["N"], rel=1e-15)


def test_calibration_keeps_provenance_and_round_trips(lab_csv, tmp_path):
    from fvd_bridge import calibrate
    from fvd_bridge.fit import objective
    from fvd_bridge.records import ReadOptions

    opts = ReadOptions(columns={"t": "time", "d": "disp", "F": "load"}, units={"t": "ms", "d": "m", "F": "N"})
    rec = read_record(str(lab_csv), opts)
    cal = calibrate(rec, "8", runs=2, seed=1)
    path = cal.save(str(tmp_path / "out" / "law8.yaml"))
    back = Calibration.load(path)
    assert back.named() == cal.named() and back.of == cal.of and back.spec == "8"
    assert back.record.source_units == {"t": "ms", "d": "m", "F": "N"}
    assert back.record.columns == {"t": "time", "d": "disp", "F": "load"}
    assert back.record.velocity["method"] == "savgol" and back.record.samples == rec.n
    raw = yaml.safe_load(open(path))
    assert raw["schema_version"] == 3 and raw["derived"]["mu*N"]["unit"] == "kN"
    assert raw["derived"]["mu*N"]["value"] == pytest.approx(cal.named()["mu"] * cal.named()["N"])
    assert any("mu*N" in w for w in back.warnings)
    # the file alone reproduces its OF on the record
    assert objective(rec.F, back.force(rec), rec.t) == pytest.approx(back.of, rel=1e-9)
    assert not list((tmp_path / "out").glob("*.partial-*"))


def test_malformed_calibration_files_get_one_line(tmp_path):
    good = yaml.safe_load(open(FIXTURES / "calibration_v1" / "law8.yaml"))
    cases = [({**good, "schema_version": 7}, "schema_version"),
             ({**good, "model": "8+wobble"}, "key 'model'"),
             ({**good, "of": "abc"}, "key 'of'"),
             ({**good, "parameters": {**good["parameters"], "Q": {"value": 1, "unit": "-"}}}, "parameters.Q")]
    for k, (data, words) in enumerate(cases):
        path = tmp_path / f"bad{k}.yaml"
        path.write_text(yaml.safe_dump(data))
        with pytest.raises(InputError) as exc:
            Calibration.load(str(path))
        assert words in str(exc.value) and str(path) in str(exc.value) and "\n" not in str(exc.value)


# ------------------------------------------------------------- executor seam
def test_executors_give_the_same_campaign(tmp_path):
    from fvd_bridge.campaign.executors import Processes, Serial
    from fvd_bridge.campaign.runner import CampaignSettings, run_campaign
    from fvd_bridge.calibration.tasks import make_tasks

    recs = [simulate(VirtualDamper(C=c, alpha=0.3, name=f"d{k}"), paper(cycles=2), Noise(force=1.0), seed=k)
            for k, c in enumerate((44.0, 47.0))]
    cs = CampaignSettings(specs=("2", "9"), runs=2, pop=6, gens=15)
    tasks = make_tasks(recs, cs.requests())
    assert len({t.id for t in tasks}) == len(tasks) == 8 and tasks[0].id == "d0/law2/run0000"

    class Reversed:  # any order of completion gives the same tables
        def run(self, fn, items):
            for item in reversed(list(items)):
                yield item, fn(*item)

    runs = [run_campaign(recs, cs, progress=False, executor=e) for e in (Serial(), Reversed(), Processes(2))]
    for other in runs[1:]:
        for key, fits in runs[0].items():
            assert [f.of for f in fits] == [f.of for f in other[key]]
            assert all(np.array_equal(a.values, b.values) for a, b in zip(fits, other[key]))


def _worker_pid(_):
    time.sleep(0.2)  # long enough that both workers take tasks
    return os.getpid()


def test_one_pool_serves_every_run_inside_with():
    """Inside ``with Processes(2)`` two runs are served by the same two
    worker processes (started once); outside, each run starts its own; a
    task that fails ends the shared pool and the next run starts another."""
    from fvd_bridge.campaign.executors import Processes

    def pids(ex):
        return {pid for _, pid in ex.run(_worker_pid, [(k,) for k in range(6)])}

    with Processes(2) as ex:
        first, second = pids(ex), pids(ex)
        assert first & second and len(first | second) <= 2 and os.getpid() not in first
        with pytest.raises(ZeroDivisionError):
            list(ex.run(divmod, [(1, 0), (2, 1)]))
        assert pids(ex).isdisjoint(first)
    ex = Processes(2)
    assert pids(ex).isdisjoint(pids(ex))


# ------------------------------------------------------------------- the CLI
def run_cli(*args, cwd=None):
    return subprocess.run([*CLI, *args], capture_output=True, text=True, env=cli_env(), cwd=cwd)


def test_options_before_the_verb_and_descriptions(lab_csv, tmp_path):
    res = run_cli("--runs", "1", "--pop", "6", "--gens", "10", "calibrate", str(lab_csv), "--laws", "2",
                  "--columns", "t=time,d=disp,F=load", "--units", "t=ms,d=m,F=N", "--out", str(tmp_path / "c"),
                  "--jobs", "1", "--quiet", "--no-figures", "--intervals", "0")
    assert res.returncode == 0, res.stderr
    assert yaml.safe_load(open(tmp_path / "c" / "summary.json"))["settings"]["runs"] == 1
    for verb in ("calibrate", "laws", "demo", "diagnose", "rig", "inspect", "effects"):
        text = run_cli(verb, "--help").stdout
        usage_end = text.index("\n\n")
        assert text[usage_end:].strip().split("\n")[0] and not text[usage_end:].lstrip().startswith(
            ("positional", "options")), verb  # a description precedes the option lists
    res = run_cli("calbrate", "x.csv")
    assert res.returncode == 2 and "unknown verb 'calbrate'" in res.stderr


def test_bad_bound_is_refused_before_any_work(lab_csv, tmp_path):
    res = run_cli("calibrate", str(lab_csv), "--laws", "9", "--bound", "9:alpha=5,0", "--out", str(tmp_path / "b"),
                  "--columns", "t=time,d=disp,F=load", "--units", "t=ms,d=m,F=N")
    assert res.returncode == 2 and res.stderr.count("\n") == 1
    assert "--bound '9:alpha=5,0'" in res.stderr and "lower bound must be below" in res.stderr
    assert "calibrating" not in res.stderr and not (tmp_path / "b").exists()


def test_report_columns_are_whole_and_apart():
    from fvd_bridge.text.campaign import format_report

    names = ["arts_brfd_0.5Hz_25lb", "arts_brfd_1Hz_35lb"]
    m = {"names": ["C", "alpha"], "units": ["kN/(mm/s)^alpha", "-"], "of_mean": np.array([0.1, 0.2]),
         "of_sigma": np.array([0.0, 0.01]), "p_mean": np.array([[45.0, 0.3], [46.0, 0.31]]),
         "p_sigma": np.zeros((2, 2)), "of_overall": 0.15, "beta": 0.02, "non_dominated": True,
         "warnings": {n: [] for n in names}}
    text = format_report({"devices": names, "models": {"8+gap+asymmetry": m}})
    assert all(n in text for n in names) and "C [kN/(mm/s)^alpha]" in text
    row = next(line for line in text.splitlines() if line.startswith("law 8+gap+asymmetry"))
    assert re.match(r"law 8\+gap\+asymmetry\s{2,}OF\s", row)


# -------------------------------------------------------------- the Python API
@pytest.mark.parametrize("page", ["docs/guide/python.md", "README.md"])
def test_the_python_examples_run_as_written(tmp_path, page):
    code = "\n".join(re.findall(r"```python\n(.*?)```", (REPO / page).read_text(), re.S))
    assert "calibrate(" in code and "diagnose(" in code
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=cli_env(),
                         cwd=tmp_path, timeout=600)
    assert res.returncode == 0, res.stderr[-2000:]
    nothing_to_add = "nothing left to explain" in res.stdout or "no candidate effect helps beyond noise" in res.stdout
    assert "OF" in res.stdout and (nothing_to_add or page == "README.md")


def test_report_says_what_one_device_cannot_tell():
    """With one device the robustness index is 0 by definition: the report
    says so, and its column is named apart from a law's parameter beta."""
    from fvd_bridge.text.campaign import format_report

    m = {"names": ["C", "alpha", "beta"], "units": ["kN/(mm/s)", "1/mm", "kN/mm"], "of_mean": np.array([0.1]),
         "of_sigma": np.array([0.0]), "p_mean": np.array([[0.2, 0.15, 27.0]]), "p_sigma": np.zeros((1, 3)),
         "of_overall": 0.1, "beta": 0.0, "non_dominated": True, "warnings": {"dev": []}}
    text = format_report({"devices": ["dev"], "models": {"9": m}})
    assert "beta_r" in text and "one device: beta_r" in text
    assert "one device" not in format_report({"devices": ["a", "b"], "models": {"9": {
        **m, "of_mean": np.array([0.1, 0.1]), "of_sigma": np.zeros(2), "p_mean": np.array([[0.2, 0.15, 27.0]] * 2),
        "p_sigma": np.zeros((2, 3)), "warnings": {"a": [], "b": []}}}})
