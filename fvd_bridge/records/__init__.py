"""Test records: reading, validation, velocity, summaries."""

from .options import ReadOptions, parse_mapping
from .readers import RecordWarning, read_record
from .record import Record
from .summary import summarize

__all__ = ["Record", "ReadOptions", "RecordWarning", "parse_mapping", "read_record",
           "summarize"]
