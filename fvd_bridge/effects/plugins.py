"""User-defined effects from a Python file (``--plugin path.py``).

A plugin file defines ``EFFECTS``, a list of fvd_bridge.effects.Effect
(see examples/custom_effect.py).  Effects of any stage are allowed; a
series effect sets the connection's spring Ks [kN/mm] and/or clearance g
[mm] (its ``slots``) from its parameters (``function(P)``: a tuple of (pop,)
values), and the built-in connection solves the law behind them.  Each is checked on a small synthetic record when loaded, so
a broken plugin is refused with one line naming the file, never a traceback
in the middle of a fit.
"""

from __future__ import annotations

import dataclasses
import hashlib
import importlib.util
import math
import os
import re
import sys

import numpy as np

from ..errors import InputError, option
from ..records.record import Record
from .base import STAGES, Effect
from .catalog import EFFECTS as BUILTIN
from .catalog import SLOT_OFF

#: the connection's own arguments, which a series effect may set
CONNECTION_SLOTS = ("Ks", "g")

_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


def file_sha256(path: str) -> str:
    """The sha256 (hex) of a file's bytes: how a calibration file names the
    plugin it needs, and a campaign's fingerprint the plugins it ran with."""
    try:
        with open(path, "rb") as fh:
            return hashlib.sha256(fh.read()).hexdigest()
    except OSError as exc:
        raise InputError(f"plugin {path}: cannot read ({exc.strerror or exc})") from None


def _module_name(path: str) -> str:
    digest = hashlib.sha1(os.path.abspath(path).encode()).hexdigest()[:10]
    return f"fvd_bridge_plugin_{digest}"


def load_module(path: str):
    """Import a plugin file; any failure -> InputError naming the file."""
    if not os.path.isfile(path):
        raise InputError(f"{option('--plugin', path)}: no such file")
    name = _module_name(path)
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        raise InputError(f"{option('--plugin', path)}: not a Python file")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # pickling and dataclasses need it registered
    try:
        spec.loader.exec_module(module)
    except SyntaxError as exc:
        sys.modules.pop(name, None)
        raise InputError(f"{option('--plugin', path)}: line {exc.lineno}: syntax error ({exc.msg})") from None
    except Exception as exc:  # a user's file may raise anything
        sys.modules.pop(name, None)
        raise InputError(f"{option('--plugin', path)}: failed to load ({type(exc).__name__}: {exc})") from None
    return module


def _probe_record():
    """A 2-cycle, 1 Hz sinusoid of 20 mm with a viscous 100 kN force (for checks)."""
    t = np.arange(201) * 0.01
    w = 2.0 * math.pi
    d, v, a = 20.0 * np.sin(w * t), 20.0 * w * np.cos(w * t), -20.0 * w * w * np.sin(w * t)
    return Record(t, d, 100.0 * v / v.max(), v, a, name="plugin-probe")


def check_effect(e, where: str) -> Effect:
    """Refuse a malformed effect with one line; returns it."""
    if not isinstance(e, Effect):
        raise InputError(f"{where}: EFFECTS must hold fvd_bridge.effects.Effect objects, "
                         f"got {type(e).__name__}")
    label = f"{where}: effect '{e.name}'"
    if not isinstance(e.name, str) or not _NAME.match(e.name):
        raise InputError(f"{where}: effect name '{e.name}' must be an identifier (letters, digits, _)")
    if e.stage not in STAGES:
        raise InputError(f"{label}: stage '{e.stage}' (expected input, output or parallel)")
    if e.stage == "series" and (not e.slots or not set(e.slots) <= set(CONNECTION_SLOTS)):
        raise InputError(f"{label}: a series effect sets the connection's {' and/or '.join(CONNECTION_SLOTS)}: "
                         f"slots {tuple(e.slots)}")
    if e.stage != "series" and (e.slots or e.inside_with):
        raise InputError(f"{label}: only a series effect has slots (the element's are built in)")
    if not callable(e.function):
        raise InputError(f"{label}: function is not callable")
    if not e.parameters:
        raise InputError(f"{label}: no parameters")
    if len(e.none) != len(e.parameters):
        raise InputError(f"{label}: 'none' has {len(e.none)} values for {len(e.parameters)} parameters")
    names = [p.name for p in e.parameters]
    if len(set(names)) != len(names):
        raise InputError(f"{label}: parameter names repeat ({', '.join(names)})")
    rec = _probe_record()
    try:
        b = e.bounds(rec.scales())
    except Exception as exc:
        raise InputError(f"{label}: bounds failed ({type(exc).__name__}: {exc})") from None
    if b.shape != (len(names), 2) or not np.all(np.isfinite(b)) or np.any(b[:, 0] > b[:, 1]):
        raise InputError(f"{label}: bounds must be finite (low, high) pairs with low <= high")
    none = np.clip(np.asarray(e.none, dtype=float), b[:, 0], b[:, 1])
    if not np.allclose(none, np.asarray(e.none, dtype=float), equal_nan=False) and np.all(np.isfinite(e.none)):
        raise InputError(f"{label}: the 'no effect' values {tuple(e.none)} lie outside the bounds "
                         f"(models must be nested)")
    # call the function itself on plain arrays (no compiled law kernels here:
    # a parent process that ran numba's thread pool must not fork workers)
    P = np.vstack([none, b.mean(axis=1)])
    n = rec.n
    x, xv, xa = rec.d[None, :], rec.v[None, :], rec.a[None, :]
    try:
        if e.stage == "series":
            arrays = _series_slots(e, np.vstack([np.asarray(e.none, dtype=float), P[1]]), label)
        elif e.stage == "input":
            out = e.function(P, x, xv, xa, rec.dt)
            if not isinstance(out, tuple) or len(out) != 3:
                raise InputError(f"{label}: an input effect returns (x, xv, xa)")
            arrays = out
        elif e.stage == "output":
            arrays = (e.function(P, np.vstack([rec.F, rec.F]), x, xv, rec.dt),)
        else:
            arrays = (e.function(P, rec.t, x, xv, xa),)
    except InputError:
        raise
    except Exception as exc:
        raise InputError(f"{label}: failed on a test record ({type(exc).__name__}: {exc})") from None
    for arr in arrays if e.stage != "series" else ():
        try:
            arr = np.broadcast_to(np.asarray(arr, dtype=float), (2, n))
        except (ValueError, TypeError):
            shape = getattr(arr, "shape", type(arr).__name__)
            raise InputError(f"{label}: returned shape {shape}, expected (population, {n}) "
                             f"or broadcastable to it") from None
        if not np.all(np.isfinite(arr)):
            raise InputError(f"{label}: returned non-finite values on a test record")
    return e


def _series_slots(e, P, label: str) -> tuple:
    """A series effect's slot values on the probe rows (its 'off' values,
    then mid-bounds): one (pop,) array per slot, the first row at the
    slots' own 'off' values (a rigid spring, no clearance: nesting)."""
    out = e.function(P)
    if not isinstance(out, tuple) or len(out) != len(e.slots):
        raise InputError(f"{label}: a series effect returns a tuple of {len(e.slots)} arrays ({', '.join(e.slots)})")
    arrays = []
    for slot, value in zip(e.slots, out):
        try:
            arr = np.broadcast_to(np.asarray(value, dtype=float), (P.shape[0],))
        except (ValueError, TypeError):
            raise InputError(f"{label}: its {slot} has shape {np.shape(value)}, expected ({P.shape[0]},)") from None
        if arr[0] != SLOT_OFF[slot]:
            raise InputError(f"{label}: at its 'no effect' values {tuple(e.none)} its {slot} is {arr[0]:g}, "
                             f"not {SLOT_OFF[slot]:g} (models must be nested)")
        if np.isnan(arr).any() or arr[1] < 0.0:
            raise InputError(f"{label}: its {slot} must be a number >= 0 (got {arr[1]:g} mid-bounds)")
        arrays.append(arr)
    return tuple(arrays)


def load_plugins(paths) -> dict:
    """Effects of the plugin files: {name: Effect}; clashes are refused."""
    if isinstance(paths, str):
        paths = [paths]
    out: dict = {}
    for path in paths:
        module = load_module(path)
        digest = file_sha256(path)
        effects = getattr(module, "EFFECTS", None)
        if effects is None:
            raise InputError(f"{option('--plugin', path)}: defines no EFFECTS list (see examples/custom_effect.py)")
        if isinstance(effects, Effect):
            effects = [effects]
        try:
            effects = list(effects)
        except TypeError:
            raise InputError(f"{option('--plugin', path)}: EFFECTS must be a list of Effect objects") from None
        if not effects:
            raise InputError(f"{option('--plugin', path)}: EFFECTS is empty")
        for e in effects:
            if isinstance(e, Effect):
                # a plugin has no C step form and no OpenSees form: the registry says so
                e = dataclasses.replace(e, source=os.path.basename(path), source_sha256=digest, fmu=False,
                                        opensees=None)
            check_effect(e, path)
            if e.name in BUILTIN:
                raise InputError(f"{path}: effect '{e.name}' clashes with the built-in effect of that name")
            if e.name in out:
                raise InputError(f"{path}: effect '{e.name}' is defined twice")
            out[e.name] = e
    return out
