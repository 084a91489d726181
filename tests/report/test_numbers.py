"""Numbers for people (report.numbers): hand-computed cases."""

import pytest

from fvd_bridge.report.numbers import interval, rounded, share, with_unit


@pytest.mark.parametrize("value, uncertainty, text", [
    (39.92029, 0.135, "39.92"),        # the uncertainty's second digit is the hundredths
    (0.300330, 0.00062, "0.30033"),
    (1.3761150366403045, None, "1.376"),  # no uncertainty: 4 significant digits
    (123456.0, None, "123500"),
    (27.09172893, 1e-9, "27.0917"),     # at most 6 significant digits
    (-2.1e-7, None, "-2.100e-07"),
    (0.0, 0.1, "0"),
    (float("nan"), None, "n/a"),
    (None, None, "-"),
])
def test_rounded(value, uncertainty, text):
    assert rounded(value, uncertainty) == text


def test_interval_share_and_header():
    assert interval(39.7728, 40.3019, 0.135) == "[39.77, 40.30]"
    assert share(0.0123) == "1.2%" and share(0.594) == "59%" and share(1.135) == "114%" and share(0.0005) == "0.050%"
    assert with_unit("C", "kN") == "C [kN]" and with_unit("alpha", "") == "alpha"


def test_cells_and_spreads():
    from fvd_bridge.report.numbers import cell, with_spread

    assert cell(3001) == "3001" and cell("2865") == "2865"  # counts are exact
    assert cell("1.3761150366403045") == "1.376" and cell(267.4933484401716) == "267.5"
    assert cell("law 2 | device_01") == "law 2 | device_01" and cell(None) == "" and cell("") == ""
    assert cell("nan") == "n/a" and cell(True) == "yes"
    assert with_spread(45.4136, 0.048) == "45.414 (0.048)"
    assert with_spread(0.001891, 0.0) == "0.001891" and with_spread(0.02752, 3.5e-18) == "0.02752"


def test_small_shares():
    from fvd_bridge.report.numbers import small_share

    assert small_share(4.6e-9) == "<0.01%" and small_share(-2e-6) == "-<0.01%"
    assert small_share(0.026) == "2.6%" and small_share(0.0) == "0%"
