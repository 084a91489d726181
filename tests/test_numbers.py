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
