"""Moved to ``fvd_bridge.text.diagnosis``: this line stays until ``diagnose/__init__.py`` imports it there."""
from ..text.diagnosis import format_diagnosis, format_ladder  # noqa: F401
