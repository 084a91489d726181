"""Moved to ``fvd_bridge.text.calibration``: this line stays until ``calibration/core.py`` imports it there."""
from ..text.calibration import REPORTED_CORRELATION, interval_lines, report  # noqa: F401
