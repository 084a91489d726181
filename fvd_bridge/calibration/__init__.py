"""The calibration: one calibrated model of one device, the contract
between identification and every exporter (OpenSees, FMU, frames, compare).

``core``: the Calibration and its parameters (each a FittedParameter,
``fit.parameter``'s, re-exported here); ``parts``: its tests
(TestFit), their records' sources (RecordSource, Peaks), run statistics
(RunStats), intervals (BootstrapIntervals, an Interval each) and how
its search ended (SolverStatus); ``schema``: the file (save, load, checks); ``text``: the fit
report; ``tested``: where it holds and which calibrations rank together.
"""

from ..fit.parameter import FittedParameter
from .core import Calibration
from .parts import BootstrapIntervals, Interval, Peaks, RecordSource, RunStats, SolverStatus, TestFit
from .schema import SCHEMA_VERSION, record_provenance
from .tested import common_tests, data_key, same_data

__all__ = ["BootstrapIntervals", "Calibration", "FittedParameter", "Interval", "Peaks", "RecordSource", "RunStats",
           "SCHEMA_VERSION", "SolverStatus", "TestFit", "common_tests", "data_key", "record_provenance", "same_data"]
