"""One calibration, from a record and a FitRequest to a Calibration:
the seeded runs (``runs.fit_runs``), the best run's intervals
(``runs.fit_intervals``), the warnings (``checks``).  ``fb.calibrate``
calls it; ``fvd-bridge calibrate`` and ``campaign`` run the same two steps
over every (device, model) and build each Calibration the same way
(``campaign.outputs``), so they give the same numbers by construction."""

from __future__ import annotations

from .checks import fit_warnings
from .core import Calibration
from .runs import fit_intervals, fit_runs


def calibrate(record, request, *, executor=None, progress: bool = False) -> Calibration:
    """The Calibration of ``request``'s model (a checked FitRequest) on
    ``record`` (a Record or a Device), through ``executor`` (None: in this
    process)."""
    fitted = fit_runs([record], [request], executor=executor, progress=progress)[(record.name, request.spec)]
    intervals = fit_intervals([record], {(record.name, request.spec): fitted}, [request], executor=executor,
                              progress=progress)
    model = request.model
    return Calibration.from_runs(model, fitted, record, settings=request.as_settings(),
                                 warnings=[w["message"] for w in fit_warnings(model, fitted)],
                                 intervals=intervals.get((record.name, request.spec)))
