"""The virtual test rig: virtual FVDs with known physics, protocols, noise.

A VirtualDamper holds the true physical parameters (orifice C, alpha; series
stiffness, seal friction, heating, pin gap, asymmetry, accumulator stiffness
and preload, moving mass); ``simulate`` integrates it accurately under the
analytic motion of a Protocol and returns a Record; ``write_series`` writes
lab-like CSVs and truth.yaml. Units: kN, mm, s (mass kg, energy MJ).
"""

from .device import (DEMO_NOISE, DEMO_NOMINAL, DEMO_SCATTER, PARAMETERS, VirtualDamper, demo_series,
                     production_series)
from .energy import cycle_bounds, energy_per_cycle, loop_area, orifice_energy_per_cycle
from .protocols import (HistoryProtocol, Protocol, SineProtocol, SineSegment, acceptance, from_spec,
                        history, paper, read_history)
from .series import TRUTH_FILE, read_truth, simulate_series, truth_dict, write_series
from .simulate import Noise, simulate, trace

__all__ = [
    "DEMO_NOISE", "DEMO_NOMINAL", "DEMO_SCATTER", "PARAMETERS", "TRUTH_FILE",
    "VirtualDamper", "HistoryProtocol", "Noise", "Protocol", "SineProtocol", "SineSegment",
    "acceptance", "cycle_bounds", "demo_series", "energy_per_cycle", "from_spec", "history",
    "loop_area", "orifice_energy_per_cycle", "paper", "production_series", "read_history",
    "read_truth", "simulate", "simulate_series", "trace", "truth_dict", "write_series",
]
