"""A calibration file never runs code.

A file planted with a plugin whose import writes a marker file is read by
every verb that reads calibration files and by ``Calibration.load``: none
imports it (the marker never appears); each says in one line which plugin
the file needs and how to give it (exit 2).  The plugin the caller gives is
checked against the file name and sha256 the file records, before it is
imported.
"""

from __future__ import annotations

import hashlib
import subprocess

import numpy as np
import pytest
import yaml

from conftest import CLI, PLUGIN, cli_env, csv_text, sine
from fvd_bridge import cli
from fvd_bridge.calibration import Calibration
from fvd_bridge.catalog import catalog
from fvd_bridge.errors import InputError, PluginNeeded

SPEC = "2+cubic_spring"
VALUES = np.array([2.0, 1.0, 1e-6])  # C, alpha, cubic_spring.K3


def sha256(path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def marking(marker) -> str:
    """A plugin that defines the same effect and, when imported, writes ``marker``."""
    return f"open({str(marker)!r}, 'w').write('imported')\n" + PLUGIN


@pytest.fixture
def lab(tmp_path, monkeypatch):
    """The good plugin, a marking one named evil.py, a record, and the
    calibration files: made with the good plugin, then pointed at evil.py."""
    good = tmp_path / "plugins" / "my_effects.py"
    good.parent.mkdir()
    good.write_text(PLUGIN)
    marker = tmp_path / "MARKER"
    evil = tmp_path / "evil.py"
    evil.write_text(marking(marker))
    s = sine()
    record = tmp_path / "rec.csv"
    record.write_text(csv_text("t,d,F", [s["t"], s["d"], s["F"]]))
    out = tmp_path / "out"
    made = Calibration(catalog([str(good)]).model(SPEC), VALUES, of=0.01, device="dev")
    made.save(str(out / "params" / "dev" / f"law{SPEC}.yaml"))
    monkeypatch.chdir(tmp_path)  # where a relative 'evil.py' would be found
    return {"good": good, "evil": evil, "marker": marker, "record": record, "out": out,
            "cal": out / "params" / "dev" / f"law{SPEC}.yaml", "tmp": tmp_path}


def plant(path, plugins, model=None) -> None:
    """Rewrite a calibration file's settings.plugins (and model: a built-in law, without its effects)."""
    data = yaml.safe_load(path.read_text())
    data["settings"]["plugins"] = plugins
    if model is not None:
        data["model"], data["effects"] = model, []
        data["parameters"] = {k: v for k, v in data["parameters"].items() if "." not in k}
    path.write_text(yaml.safe_dump(data, sort_keys=False))


def styles(lab) -> dict:
    """settings.plugins naming evil.py: as files record them now, and as older ones did (paths)."""
    return {"recorded": [{"file": "evil.py", "sha256": sha256(lab["evil"])}],
            "path": [str(lab["evil"])], "relative": ["evil.py"]}


def verbs(lab) -> dict:
    cal, rec, tmp = str(lab["cal"]), str(lab["record"]), lab["tmp"]
    return {
        "export opensees": ["export", "opensees", cal],
        "export fmu": ["export", "fmu", cal, "-o", str(tmp / "x.fmu")],
        "compare": ["compare", cal, rec, "--out", str(tmp / "cmp"), "--no-figures"],
        "frame": ["frame", cal, "--record", str(tmp / "quake.txt"), "--out", str(tmp / "frame"), "--no-figures"],
        "calibrate --start": ["calibrate", rec, "--laws", "2", "--start", cal, "--out", str(tmp / "c"), "--quiet"],
        "report": ["report", str(lab["out"])],
    }


@pytest.mark.parametrize("style", ["recorded", "path", "relative"])
def test_no_verb_and_no_api_call_runs_a_plugin_the_file_names(lab, capsys, style):
    plant(lab["cal"], styles(lab)[style])
    for name, argv in verbs(lab).items():
        assert cli.main(argv) == 2, name
        err = capsys.readouterr().err.strip()
        assert "\n" not in err and "Traceback" not in err, (name, err)
        assert "needs the plugin evil.py" in err and "--plugin evil.py" in err, (name, err)
        assert "never runs code" in err, (name, err)
        if style == "recorded":
            assert sha256(lab["evil"])[:12] in err, (name, err)
        assert not lab["marker"].exists(), name
    with pytest.raises(PluginNeeded, match=r"needs the plugin evil\.py.*plugins=\['evil\.py'\]"):
        Calibration.load(str(lab["cal"]))
    assert not lab["marker"].exists()


def test_the_command_line_itself_says_it_in_one_line(lab):
    plant(lab["cal"], styles(lab)["path"])
    res = subprocess.run([*CLI, "export", "opensees", str(lab["cal"])], capture_output=True, text=True,
                         env=cli_env(), cwd=lab["tmp"], timeout=300)
    assert res.returncode == 2 and res.stdout == ""
    assert res.stderr.count("\n") == 1 and res.stderr.startswith("fvd-bridge: ") and "evil.py" in res.stderr
    assert not lab["marker"].exists()


def test_a_built_in_model_loads_without_its_listed_plugins(lab):
    plant(lab["cal"], styles(lab)["path"], model="2")
    cal = Calibration.load(str(lab["cal"]))
    assert cal.spec == "2" and not lab["marker"].exists()


def test_a_file_naming_no_plugin_for_a_foreign_effect_says_what_is_missing(lab):
    plant(lab["cal"], [])
    with pytest.raises(PluginNeeded, match=r"effect 'cubic_spring' is not built in.*plugins=\['FILE\.py'\]"):  # Python's words
        Calibration.load(str(lab["cal"]))


def test_the_file_records_each_plugin_by_name_and_hash(lab):
    settings = yaml.safe_load(lab["cal"].read_text())["settings"]
    assert settings["plugins"] == [{"file": "my_effects.py", "sha256": sha256(lab["good"])}]
    # a model of built-in effects needs no plugin, whatever the fit was given
    plain = Calibration(catalog([str(lab["good"])]).model("2"), VALUES[:2], of=0.01, settings={"plugins": ["x.py"]})
    plain.save(str(lab["tmp"] / "plain.yaml"))
    assert yaml.safe_load((lab["tmp"] / "plain.yaml").read_text())["settings"]["plugins"] == []


def test_the_plugin_given_loads_the_model(lab, capsys):
    good = str(lab["good"])
    cal = Calibration.load(str(lab["cal"]), plugins=[good])
    assert cal.spec == SPEC and np.allclose(cal.values, VALUES)
    assert cli.main(["compare", str(lab["cal"]), str(lab["record"]), "--plugin", good,
                     "--out", str(lab["tmp"] / "cmp"), "--no-figures", "--json"]) == 0, capsys.readouterr().err
    assert '"model": "2+cubic_spring"' in capsys.readouterr().out
    assert cli.main(["report", str(lab["out"]), "--plugin", good]) == 0
    # an older file lists paths: the plugin is checked by its file name
    plant(lab["cal"], ["/elsewhere/my_effects.py"])
    assert Calibration.load(str(lab["cal"]), plugins=[good]).spec == SPEC


def test_a_plugin_with_other_content_is_refused_before_it_is_imported(lab, capsys):
    other = lab["tmp"] / "other" / "my_effects.py"
    other.parent.mkdir()
    other.write_text(marking(lab["marker"]))
    want, got = sha256(lab["good"])[:12], sha256(other)[:12]
    assert cli.main(["export", "opensees", str(lab["cal"]), "--plugin", str(other)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and want in err and got in err and "not the plugin it was calibrated with" in err
    with pytest.raises(InputError, match=f"sha256 {got}.*records {want}"):
        Calibration.load(str(lab["cal"]), plugins=[str(other)])
    # another file name is not the recorded plugin either
    renamed = lab["tmp"] / "renamed.py"
    renamed.write_text(PLUGIN)
    with pytest.raises(PluginNeeded, match="needs the plugin my_effects.py"):
        Calibration.load(str(lab["cal"]), plugins=[str(renamed)])
    assert not lab["marker"].exists()
