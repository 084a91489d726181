"""Data-driven starts (fvd_bridge/laws/starts.py) on lab-like records of
known laws: each start lies in its optimum's basin, so one local solve from
it alone reaches the OF of DE's global search; where a closed form reads a
parameter directly, the start is near the truth."""

from __future__ import annotations

import numpy as np
import pytest

from fvd_bridge.catalog import parse_model
from fvd_bridge.fit import fit_model
from fvd_bridge.fit.api import _problem, evaluate_params
from fvd_bridge.fit.layout import Layout
from fvd_bridge.fit.local import FROM_START, run_local
from fvd_bridge.fit.nested import data_start
from fvd_bridge.records.device import as_device
from fvd_bridge.rig import VirtualDamper, paper

from lab import lab_from_forces, lab_record

#: realistic parameters of each law with a start (the catalog's reference sets)
LAWS = (1, 2, 3, 4, 5, 6, 8, 9, 10)


def lab(law_no, tmp_path):
    model = parse_model(str(law_no))
    p = np.array(model.law.reference)
    protocol = paper(cycles=3)
    t = protocol.times()
    d, v, _ = protocol.motion(t)
    F = model.law.force(d, v, t[1] - t[0], p[None, :])[0]
    return model, p, lab_from_forces(t, d, F, 1.0, 0.005, seed=law_no, tmp_path=tmp_path, name=f"law{law_no}")


@pytest.mark.parametrize("law_no", LAWS)
def test_one_local_solve_from_the_data_start_reaches_the_global_optimum(law_no, tmp_path):
    model, _, rec = lab(law_no, tmp_path)
    device = as_device(rec)
    _, b, space, evaluate, residuals = _problem(model, device, Layout(model, tuple(device.test_names)), "auto")
    start = np.clip(data_start(model, rec), b[:, 0], b[:, 1])
    of = run_local(evaluate, residuals, space.n, np.random.default_rng(0), FROM_START, None,
                   space.to_unit(start)).of
    de = fit_model(model, rec, optimizer="de", seed=0, widen=False)
    assert of <= de.of * (1.0 + 1e-3)
    assert min(evaluate_params(model, rec, p) for p in start) > of  # the start is a start, not the answer


def test_the_closed_forms_read_the_parameters(tmp_path):
    """law 2: C and alpha from the log-log regression within 5%; law 9: the
    friction force beta/alpha from the reversals within 10%."""
    _, p, rec = lab(2, tmp_path)
    np.testing.assert_allclose(data_start(parse_model("2"), rec)[0], p, rtol=0.05)
    _, p, rec = lab(9, tmp_path)
    C, alpha, beta = data_start(parse_model("9"), rec)[0]
    assert beta / alpha == pytest.approx(p[2] / p[1], rel=0.1)


def test_a_connection_with_play_hides_the_friction_at_the_reversals_not_at_speed(tmp_path):
    """A friction damper (12 kN, a linear 0.02 kN/(mm/s) dashpot) behind a
    1 mm pin gap: at each reversal the force drops while the gap closes, so
    the reading there sees a fraction of the friction; the second reading,
    |F| = Ff + C |v| at speed, reads Ff and C within 10%.  Law 8's fit from
    the data's starts reaches DE's optimum."""
    rec = lab_record(VirtualDamper(C=0.02, alpha=1.0, friction=12.0, v_friction=0.1, gap=1.0, name="play"),
                     paper(cycles=3), 0.3, 0.005, seed=3, tmp_path=tmp_path)
    (C0, K0, mu0, N0), (C1, K1, mu1, N1) = data_start(parse_model("8"), rec)
    assert mu0 * N0 < 0.5 * 12.0
    assert mu1 * N1 == pytest.approx(12.0, rel=0.1)
    assert C1 == pytest.approx(0.02, rel=0.1)
    model = parse_model("8")
    assert fit_model(model, rec, seed=0).of <= fit_model(model, rec, optimizer="de", seed=0).of * 1.01


def test_the_closed_form_line_is_numpys_least_squares_line():
    """starts._line against np.polyfit (an SVD least squares): slope and intercept agree to round-off."""
    from fvd_bridge.laws.starts import _line
    rng = np.random.default_rng(3)
    x = rng.uniform(1.0, 6.0, 400)
    y = 0.37 * x - 2.1 + 0.2 * rng.standard_normal(400)
    np.testing.assert_allclose(_line(x, y), np.polyfit(x, y, 1), rtol=1e-10)
