"""Every figure can go on the user's own Axes: given ``ax`` a plotting
function draws there and returns it, open; given a path it writes a file."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from fvd_bridge.errors import InputError  # noqa: E402
from fvd_bridge.plots import campaign, effects, record  # noqa: E402
from fvd_bridge.rig import VirtualDamper, Noise, paper, simulate  # noqa: E402


@pytest.fixture(scope="module")
def rec():
    return simulate(VirtualDamper(C=45.0, alpha=0.3), paper(cycles=2), Noise(1.0, 0.005), seed=0)


def test_one_panel_figures_draw_on_the_given_axes(rec):
    fig, ax = plt.subplots()
    assert campaign.pareto(["2", "9"], [0.1, 0.05], [0.01, 0.02], [False, True], ax=ax) is ax
    assert len(ax.collections) >= 1 and plt.fignum_exists(fig.number)  # drawn, left open
    fig, ax = plt.subplots()
    assert record.loop(rec, rec.F * 0.9, ax=ax, x="v") is ax and len(ax.lines) == 2
    plt.close("all")


def test_several_panels_go_on_several_axes_or_a_figure(rec, tmp_path):
    fig, ax = plt.subplots(1, 3)
    assert campaign.loops(rec, rec.F, "loops", ax=ax) is fig and all(len(a.lines) == 2 for a in ax)
    fig = plt.figure()
    assert effects.gap_figure(ax=fig) is fig and len(fig.axes) == 2
    fig = plt.figure()
    assert record.plot_record(rec, ax=fig) is fig and len(fig.axes) == 4
    _, two = plt.subplots(1, 2)
    with pytest.raises(InputError, match="1 x 3 panels"):
        campaign.loops(rec, rec.F, "loops", ax=two)
    path = campaign.of_bars(["2"], ["a", "b"], np.array([[0.1, 0.2]]), np.array([[1e-3, 2e-3]]),
                            str(tmp_path / "bars.png"))
    assert path.endswith("bars.png") and (tmp_path / "bars.png").stat().st_size > 1000
    plt.close("all")
