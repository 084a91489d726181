"""A FitResult speaks as a Calibration does: ``values`` the vector,
``params`` {name: FittedParameter}, ``named()`` {name: value}; and the
unit files a campaign's store wrote before that naming still load."""

from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest

import fvd_bridge as fb
from fvd_bridge.calibration import Calibration
from fvd_bridge.calibration.request import FitRequest
from fvd_bridge.calibration.runs import fit_runs
from fvd_bridge.campaign.store import SCHEMA_VERSION, UnitStore, canonical, result_from_dict, result_to_dict, sha256
from fvd_bridge.fit import FitResult
from fvd_bridge.fit.parameter import FittedParameter
from fvd_bridge.rig import Noise, VirtualDamper, paper, simulate

#: the "result" of a unit file as the store wrote it before FitResult's vector
#: was named ``values`` (OUT/.units/device_01/law2/run0000.json of a campaign,
#: byte for byte but for the history, cut to two entries): the estimates under
#: "params" by name, the order under "names"
OLD_RESULT = json.loads("""{
 "spec": "2",
 "units": {"C": "kN/(mm/s)^alpha", "alpha": "-"},
 "params": {"C": 44.791530500022795, "alpha": 0.3024053660011604},
 "of": 0.10405289385137545,
 "bounds": {"C": [0.0, 884.8803816], "alpha": [0.1, 0.9]},
 "bounds_mode": "auto",
 "optimizer": "local",
 "seed": [0, 0, 0, 0],
 "evaluations": 107,
 "history": [0.12155183788093755, 0.10405289385137545],
 "wall_s": 0.03413290300159133,
 "record": "device_01",
 "log": [false, false],
 "off": [null, null],
 "tests": ["device_01"],
 "test_of": [0.10405289385137545],
 "widened": {},
 "parent": [],
 "stop": "local: 1 basin(s) from 2 start(s); solves ended: gradient small 3, stopped in a known basin 1",
 "flat_ends": [],
 "zero": null,
 "floor": 0.004344277148314794,
 "names": ["C", "alpha"]
}""")


@pytest.fixture(scope="module")
def rec():
    return simulate(VirtualDamper(C=45.0, alpha=0.3, name="sn045"), paper(cycles=2), Noise(1.0, 0.005), seed=0)


def test_a_fit_names_its_parameters_as_the_calibration_made_from_it(rec):
    """The best run of a request and the Calibration built from it (as
    ``fb.calibrate`` builds it, which gives the same numbers): the same
    vector under ``values``, the same FittedParameters under ``params``
    (value, unit, bounds, fixed), the same ``named()``; the fit's file
    mapping keeps the estimates under "params", where it always had them."""
    bounds = {"alpha": (0.05, 1.0)}
    request = FitRequest(spec="2", search_bounds=bounds, runs=2).check()
    fitted = fit_runs([rec], [request])[(rec.name, "2")]
    fit = fitted.best
    cal = Calibration.from_runs(request.model, fitted, rec, settings=request.as_settings())
    direct = fb.calibrate(rec, "2", runs=2, bounds=bounds, intervals=0)

    assert isinstance(fit, FitResult) and isinstance(fit.values, np.ndarray) and fit.values.dtype == float
    assert np.array_equal(fit.values, cal.values) and np.array_equal(direct.values, cal.values)
    assert isinstance(fit.params, dict) and list(fit.params) == list(cal.params) == ["C", "alpha"]
    for name, p in fit.params.items():
        c = cal.params[name]
        assert isinstance(p, FittedParameter) and (p.name, p.value, p.unit, p.bounds, p.fixed) == (
            c.name, c.value, c.unit, c.bounds, c.fixed)
        assert p.stderr is None and p.ci95 is None  # a fit has no intervals
    assert fit.named() == cal.named() == direct.named() == {n: float(v) for n, v in zip(fit.names, fit.values)}

    d = fit.as_dict()
    assert "values" not in d and d["params"] == fit.named()
    assert list(d)[:4] == ["spec", "units", "params", "of"]  # the unit files' order, as before


def test_a_unit_file_written_before_the_renaming_still_loads(tmp_path, rec):
    """A unit file of the old shape (OLD_RESULT, its estimates under
    "params"), stored with the store's checksum, loads as a FitResult whose
    ``values`` are those estimates in "names"' order; written again it is
    the same data."""
    back = result_from_dict(OLD_RESULT)
    assert back.names == ["C", "alpha"] and back.values.tolist() == [44.791530500022795, 0.3024053660011604]
    assert back.named() == OLD_RESULT["params"] and back.params["alpha"].bounds == (0.1, 0.9)
    assert result_to_dict(back) == OLD_RESULT and list(result_to_dict(back)) == list(OLD_RESULT)

    store = UnitStore(str(tmp_path / "out"))
    store.open({"specs": ["2"], "runs": 1}, [rec])
    task = SimpleNamespace(id=f"{rec.name}/law2/run0000", device=rec.name, spec="2", run=0, seed=(0, 0, 0, 0))
    unit = {"task": {"id": task.id, "device": task.device, "spec": "2", "run": 0, "seed": [0, 0, 0, 0]},
            "fingerprint": store.fingerprint, "result": OLD_RESULT,
            "stored": {"session": "0123456789ab", "pid": 1, "time": "2026-11-28T14:43:12"}}
    path = tmp_path / "out" / ".units" / rec.name / "law2" / "run0000.json"
    path.parent.mkdir(parents=True)
    path.write_text(json.dumps({"schema_version": SCHEMA_VERSION, "checksum": "sha256:" + sha256(canonical(unit)),
                                "unit": unit}, indent=1))
    loaded = store.load(task)
    store.close()
    assert store.corrupt == [] and isinstance(loaded, FitResult)
    assert loaded.values.tolist() == back.values.tolist() and loaded.of == OLD_RESULT["of"]
    assert loaded.named() == OLD_RESULT["params"] and loaded.as_dict() == back.as_dict()
