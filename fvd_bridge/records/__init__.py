"""Test records: reading, validation, velocity, summaries."""

from .record import Record
from .readers import ReadOptions, parse_mapping, read_record

__all__ = ["Record", "ReadOptions", "parse_mapping", "read_record"]
