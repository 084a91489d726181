"""fvd_bridge: calibrate fluid-viscous damper (FVD) laws on test records,
explain their misfit, and export them.  Units everywhere: kN, mm, s.

The names a notebook user needs (imported on first use)::

    from fvd_bridge import read_record, parse_model, calibrate, diagnose_record, Calibration, Device

(``diagnose_record`` is the ``diagnose`` verb; the plain name belongs to the
subpackage fvd_bridge.diagnose.)
"""

__version__ = "0.2.0"

_API = {
    "read_record": ("fvd_bridge.records", "read_record"),
    "Record": ("fvd_bridge.records", "Record"),
    "Model": ("fvd_bridge.model", "Model"),
    "parse_model": ("fvd_bridge.catalog", "parse_model"),
    "calibrate": ("fvd_bridge.api", "calibrate"),
    "Calibration": ("fvd_bridge.calibration", "Calibration"),
    "Device": ("fvd_bridge.records.device", "Device"),
    "diagnose_record": ("fvd_bridge.api", "diagnose_record"),
}

__all__ = ["__version__", *_API]


def __getattr__(name):
    if name in _API:
        import importlib

        module, attr = _API[name]
        return getattr(importlib.import_module(module), attr)
    raise AttributeError(f"module 'fvd_bridge' has no attribute '{name}'")
