"""Where a campaign's devices come from: record files (paths or globs), or a
virtual production series from the rig, written once into OUT/records.

The rig block of a campaign file (kN, mm, s; every key optional):

    rig:
      devices: 200                                  # how many
      nominal: {C: 45.4, alpha: 0.3, Ks: 150}       # fvd_bridge.rig.VirtualDamper parameters
      scatter: {C: 0.05, alpha: 0.02}               # relative std per parameter, or one number for all
      protocol: paper                               # paper | acceptance | history:FILE.csv, or
                                                    # {name: paper, cycles: 3, amplitude: 40, velocity: 500, dt: 0.002}
      noise: {force: 1.0, displacement: 0.005}      # standard deviations [kN], [mm]
      seed: 0                                       # scatter and noise
"""

from __future__ import annotations

import glob
import json
import os

from ..errors import InputError
from ..rig import PARAMETERS, TRUTH_FILE, VirtualDamper, Noise, from_spec, production_series, read_truth, write_series
from .acceptance import Rating

RIG_KEYS = ("devices", "nominal", "scatter", "protocol", "noise", "seed")
PROTOCOL_KEYS = ("name", "amplitude", "velocity", "cycles", "dt")
RECORDS_DIR = "records"


def expand_records(patterns, base: str, where: str, key: str = "records") -> list[str]:
    """Paths of ``patterns`` (paths or globs, relative to ``base``), in the given
    order, each glob sorted, no file twice; a pattern matching nothing is an error."""
    if isinstance(patterns, str):
        patterns = [patterns]
    if not isinstance(patterns, list) or not patterns:
        raise InputError(f"{where}: key '{key}': expected a path, a glob or a list of them")
    paths = []
    for pattern in patterns:
        full = os.path.join(base, os.path.expanduser(str(pattern)))
        found = sorted(glob.glob(full)) if glob.has_magic(full) else ([full] if os.path.exists(full) else [])
        if not found:
            raise InputError(f"{where}: key '{key}': '{pattern}' matches no file")
        paths += [p for p in found if p not in paths]
    return paths


def rig_spec(spec, where: str) -> dict:
    """The rig block checked and completed with defaults (plain data: the
    campaign's fingerprint covers it)."""
    if not isinstance(spec, dict):
        raise InputError(f"{where}: key 'rig': expected a mapping ({', '.join(RIG_KEYS)})")
    unknown = [k for k in spec if k not in RIG_KEYS]
    if unknown:
        raise InputError(f"{where}: unknown key 'rig.{unknown[0]}' (known: {', '.join(RIG_KEYS)})")
    nominal = spec.get("nominal") or {}
    if not isinstance(nominal, dict):
        raise InputError(f"{where}: key 'rig.nominal': expected a mapping of rig parameters")
    nominal = VirtualDamper.from_dict(dict(nominal), where=f"{where}: rig.nominal").parameters()
    scatter = spec.get("scatter") or {}
    if not isinstance(scatter, dict):
        scatter = {k: scatter for k in PARAMETERS if k != "v_friction"}
    protocol = spec.get("protocol", "paper")
    protocol = dict(protocol) if isinstance(protocol, dict) else {"name": str(protocol)}
    bad = [k for k in protocol if k not in PROTOCOL_KEYS]
    if bad:
        raise InputError(f"{where}: unknown key 'rig.protocol.{bad[0]}' (known: {', '.join(PROTOCOL_KEYS)})")
    protocol.setdefault("name", "paper")
    noise = spec.get("noise") or {}
    if not isinstance(noise, dict) or any(k not in ("force", "displacement") for k in noise):
        raise InputError(f"{where}: key 'rig.noise': expected {{force: KN, displacement: MM}}")
    out = {"devices": _whole(spec.get("devices", 5), "rig.devices", where, 1),
           "nominal": nominal, "scatter": {str(k): v for k, v in scatter.items()}, "protocol": protocol,
           "noise": {"force": noise.get("force", 0.0), "displacement": noise.get("displacement", 0.0)},
           "seed": _whole(spec.get("seed", 0), "rig.seed", where, 0)}
    _build(out, where)  # every value checked before any work
    return out


def _whole(value, key: str, where: str, low: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, str)) or not str(value).strip().isdigit():
        raise InputError(f"{where}: key '{key}': '{value}' is not a whole number >= {low}")
    if int(value) < low:
        raise InputError(f"{where}: key '{key}': {value} must be >= {low}")
    return int(value)


def _build(spec: dict, where: str):
    """(devices, protocol, noise) of a checked rig block."""
    proto = dict(spec["protocol"])
    name = proto.pop("name")
    try:
        protocol = from_spec(name, **{k: float(v) for k, v in proto.items()})
        devices = production_series(spec["devices"], VirtualDamper(**spec["nominal"]), spec["scatter"], spec["seed"])
        noise = Noise(**spec["noise"])
    except InputError as exc:
        raise InputError(f"{where}: rig: {exc}") from None
    except (TypeError, ValueError) as exc:
        raise InputError(f"{where}: rig: {exc}") from None
    return devices, protocol, noise


def rig_rating(spec: dict) -> Rating:
    """The rating of a checked rig block's nominal damper: its orifice's C and
    alpha (``acceptance.Rating``: C V^alpha at the design velocity; the virtual
    damper's other parameters are what it is, not what it is rated)."""
    return Rating(float(spec["nominal"]["C"]), float(spec["nominal"]["alpha"]), "rig nominal device")


def rig_records(spec: dict, out: str, where: str) -> list[str]:
    """Paths of the series' records in OUT/records, simulated and written (all
    or nothing) unless that directory already holds this very series."""
    folder = os.path.join(out, RECORDS_DIR)
    plain = json.loads(json.dumps(spec))
    truth = os.path.join(folder, TRUTH_FILE)
    if os.path.exists(truth):
        try:
            data = read_truth(truth)
            if json.loads(json.dumps(data.get("campaign_rig"))) == plain and all(map(os.path.exists, data["files"])):
                return data["files"]
        except InputError:
            pass  # not ours or damaged: simulate again
    devices, protocol, noise = _build(spec, where)
    try:
        paths = write_series(folder, devices, protocol, noise, seed=spec['seed'], scatter=spec["scatter"],
                             extra={"campaign_rig": plain})
    except OSError as exc:
        raise InputError(f"{where}: cannot write {folder} ({exc.strerror or exc})") from None
    return paths[:-1]
