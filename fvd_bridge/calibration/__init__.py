"""The calibration: one calibrated model of one device, the contract
between identification and every exporter (OpenSees, FMU, frames, compare).

``core``: the Calibration and its parameters (each a FittedParameter,
``fit.parameter``'s, re-exported here); ``parts``: its tests
(TestFit), their records' sources (RecordSource, Peaks) and run statistics
(RunStats); ``schema``: the file (save, load, checks); ``text``: the fit
report; ``tested``: where it holds and which calibrations rank together.
"""

from ..fit.parameter import FittedParameter
from .core import Calibration
from .parts import Peaks, RecordSource, RunStats, TestFit
from .schema import SCHEMA_VERSION, record_provenance
from .tested import common_tests, data_key, same_data

__all__ = ["Calibration", "FittedParameter", "Peaks", "RecordSource", "RunStats", "SCHEMA_VERSION", "TestFit",
           "common_tests", "data_key", "record_provenance", "same_data"]
