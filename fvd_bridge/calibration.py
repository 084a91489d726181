"""Reading a calibrated parameter file (params/<device>/law<SPEC>.yaml).

This is the one file the exporters (OpenSeesPy, FMU) read.  Schema version 1
is written by fvd_bridge.campaign.outputs; a file is checked against it and
refused with a one-line message naming the file and key.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import yaml

from .errors import InputError
from .model import Model, parse_model

SUPPORTED_SCHEMAS = (1,)


@dataclass(frozen=True)
class Calibration:
    """A model with its calibrated parameter vector (model order) and the file's metadata."""

    model: Model
    params: np.ndarray
    of: float
    source: dict

    def named(self) -> dict:
        return dict(zip(self.model.names, map(float, self.params)))


def read_calibration(path: str, plugins: dict | None = None) -> Calibration:
    """Load and check a calibrated parameter file."""
    try:
        with open(path) as fh:
            data = yaml.safe_load(fh)
    except OSError as exc:
        raise InputError(f"{path}: cannot read ({exc.strerror})") from None
    except yaml.YAMLError as exc:
        raise InputError(f"{path}: not valid YAML ({str(exc).splitlines()[0]})") from None
    if not isinstance(data, dict) or data.get("kind") != "fvd_bridge.calibration":
        raise InputError(f"{path}: not an fvd_bridge calibration file (key 'kind')")
    if data.get("schema_version") not in SUPPORTED_SCHEMAS:
        raise InputError(f"{path}: key 'schema_version': {data.get('schema_version')!r} is not supported "
                         f"(supported: {', '.join(map(str, SUPPORTED_SCHEMAS))})")
    model = parse_model(data.get("model", ""), plugins)
    given = data.get("parameters")
    if not isinstance(given, dict):
        raise InputError(f"{path}: key 'parameters' must be a mapping")
    values = []
    for name, unit in zip(model.names, model.units):
        entry = given.get(name)
        if not isinstance(entry, dict) or "value" not in entry:
            raise InputError(f"{path}: key 'parameters.{name}' is missing (model {model.spec})")
        if entry.get("unit") != unit:
            raise InputError(f"{path}: key 'parameters.{name}.unit': '{entry.get('unit')}', expected '{unit}'")
        try:
            value = float(entry["value"])
        except (TypeError, ValueError):
            raise InputError(f"{path}: key 'parameters.{name}.value': {entry['value']!r} is not a number") from None
        if not np.isfinite(value):
            raise InputError(f"{path}: key 'parameters.{name}.value' is not finite")
        values.append(value)
    extra = sorted(set(given) - set(model.names))
    if extra:
        raise InputError(f"{path}: key 'parameters.{extra[0]}' is not a parameter of model {model.spec}")
    return Calibration(model, np.array(values), float(data.get("of", np.nan)), data)
