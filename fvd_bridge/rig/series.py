"""Write a series of virtual devices as lab-like CSV records plus ``truth.yaml``."""

from __future__ import annotations

import os

import numpy as np
import yaml

from .._version import __version__
from ..errors import InputError
from ..io.staging import atomic_file, check_output, staged_dir
from ..records.writers import write_csv
from .device import PARAMETERS, VirtualDamper
from .protocols import Protocol
from .simulate import Noise, simulate

TRUTH_FILE = "truth.yaml"
SCHEMA_VERSION = 1


def noise_seeds(seed, n: int) -> list:
    """Independent noise seeds of n devices, derived from one series seed."""
    if seed is None:
        return [None] * n
    return [int(s.generate_state(1)[0]) for s in np.random.SeedSequence(int(seed)).spawn(n)]


def simulate_series(devices, protocol: Protocol, noise: Noise | None = None, seed=0,
                    substeps: int | None = None) -> list:
    """One Record per device; device i gets noise seed noise_seeds(seed, n)[i]."""
    seeds = noise_seeds(seed, len(devices))
    return [simulate(dev, protocol, noise, s, substeps=substeps) for dev, s in zip(devices, seeds)]


def truth_dict(devices, protocol: Protocol, noise: Noise, seed, files, scatter=None, extra=None) -> dict:
    """The content of truth.yaml (schema_version 1)."""
    return {
        "schema_version": SCHEMA_VERSION,
        "generator": f"fvd_bridge {__version__} rig",
        "units": {k: u for k, (u, _) in PARAMETERS.items()},
        "meaning": {k: m for k, (_, m) in PARAMETERS.items()},
        "sign": "positive force = tension; d = imposed displacement [mm], t [s], F [kN]",
        "force": "F = F_series(orifice x (1 +- asymmetry) x exp(-heating E) + friction tanh(v_o/v_friction), "
                 "through Ks) + Kp y + preload + mass a_y 1e-6 + noise; y = play(d, gap/2)",
        "protocol": protocol.describe(),
        "noise": {**noise.describe(), "seed": None if seed is None else int(seed),
                  "per_device_seeds": noise_seeds(seed, len(devices))},
        "scatter": dict(scatter or {}),
        **(extra or {}),
        "devices": [{"name": dev.name, "file": f, "parameters": dev.parameters()}
                    for dev, f in zip(devices, files)],
    }


def _atomic_yaml(data: dict, path: str) -> None:
    with atomic_file(path) as fh:
        yaml.safe_dump(data, fh, sort_keys=False, default_flow_style=None)


def write_series(out_dir: str, devices, protocol: Protocol, noise: Noise | None = None, *, seed=0,
                 with_velocity: bool = False, scatter: dict | None = None,
                 substeps: int | None = None, extra: dict | None = None) -> list[str]:
    """Simulate every device, then write DEVICE.csv (t,d,F[,v]; kN, mm, s) with
    its unit sidecar DEVICE.yaml for each, and truth.yaml with all true
    parameters, protocol and noise. ``noise`` None: no noise (as
    ``simulate``); Noise() is the lab-like default.

    ``out_dir`` is checked first (``io.staging.check_output``); all records
    are simulated before anything is written; the files are written into a
    staging directory beside ``out_dir`` and moved into place only when all
    of them are complete, so an error (Ctrl-C included) leaves no partial or
    half-written output. Returns the written record paths, then
    truth.yaml (the sidecars are not listed).
    """
    noise = noise or Noise(0.0, 0.0)
    devices = list(devices)
    if not devices:
        raise InputError("rig: no devices to simulate")
    names = [d.name for d in devices]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise InputError(f"rig: two devices named '{dup[0]}'")
    check_output(out_dir, "dir")
    records = simulate_series(devices, protocol, noise, seed, substeps)
    files = [f"{dev.name}.csv" for dev in devices]
    with staged_dir(out_dir) as stage:
        for rec, dev, f in zip(records, devices, files):
            comment = (f"fvd_bridge rig: device {dev.name}, protocol {protocol.name}; "
                       f"units t [s], d [mm], F [kN]{', v [mm/s]' if with_velocity else ''}; "
                       f"true parameters in {TRUTH_FILE}")
            write_csv(rec, os.path.join(stage, f), with_velocity=with_velocity, comment=comment)
        _atomic_yaml(truth_dict(devices, protocol, noise, seed, files, scatter, extra),
                     os.path.join(stage, TRUTH_FILE))
    return [os.path.join(out_dir, f) for f in files + [TRUTH_FILE]]


def read_truth(path: str) -> dict:
    """Load truth.yaml (a file or its directory): the dict as written, with
    'devices' turned into VirtualDamper objects and 'files' their full paths."""
    if os.path.isdir(path):
        path = os.path.join(path, TRUTH_FILE)
    if not os.path.exists(path):
        raise InputError(f"{path}: no such file")
    try:
        data = yaml.safe_load(open(path)) or {}
    except yaml.YAMLError as exc:
        raise InputError(f"{path}: not valid YAML ({str(exc).splitlines()[0]})") from None
    if not isinstance(data, dict) or data.get("schema_version") != SCHEMA_VERSION:
        raise InputError(f"{path}: not a rig truth file (schema_version {SCHEMA_VERSION} expected)")
    entries = data.get("devices") or []
    base = os.path.dirname(os.path.abspath(path))
    data["devices"] = [VirtualDamper.from_dict({"name": e["name"], **e["parameters"]}, where=path) for e in entries]
    data["files"] = [os.path.join(base, e["file"]) for e in entries]
    return data
