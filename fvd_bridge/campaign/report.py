"""Moved to ``fvd_bridge.text.campaign``: this line stays until ``commands/demo.py`` imports it there."""
from ..text.campaign import format_report  # noqa: F401
