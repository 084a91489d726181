"""fvd_bridge: calibrate fluid-viscous damper (FVD) laws on test records,
explain their misfit, and export them to OpenSees and FMI.  Units inside:
kN, mm, s; at the edges, the user's own.

The notebook API (``fvd_bridge.api``)::

    import fvd_bridge as fb
    rec = fb.Record.from_arrays(t, d, F, units=("N", "m", "s"))
    cal = fb.calibrate(rec, "2", bounds={"alpha": (0.1, 1.0)})
    diag = fb.diagnose(rec, "2"); better = diag.accept()

``dir(fvd_bridge)`` lists the public names.
"""

from ._version import __version__  # noqa: E402
from .kernel_cache import configure as _configure_kernel_cache  # noqa: E402

_configure_kernel_cache()  # one cache of the compiled kernels, before any is compiled

from .api import calibrate, diagnose  # noqa: E402
from .calibration import Calibration, FittedParameter  # noqa: E402
from .catalog import parse_model  # noqa: E402
from .diagnose.core import Diagnosis  # noqa: E402
from .errors import FitWarning, InputError  # noqa: E402
from .model import Model  # noqa: E402
from .records import read_record  # noqa: E402
from .records.device import Device  # noqa: E402
from .records.readers import RecordWarning  # noqa: E402
from .records.record import Record  # noqa: E402

# ``diagnose`` is the function: imported after the subpackage fvd_bridge.diagnose, whose name it takes

__all__ = ["__version__", "Calibration", "Device", "Diagnosis", "FitWarning", "FittedParameter", "InputError",
           "Model", "Record", "RecordWarning", "calibrate", "diagnose", "parse_model",
           "read_record"]


def __dir__():
    return list(__all__)
