"""The durable store of a campaign's finished units (tasks), inside its output directory.

    OUT/.units/campaign.json      fingerprint (sha256) of what decides every unit's
                                  result, and that content: settings + records
    OUT/.units/<task id>.json     one finished unit: task, fingerprint, FitResult
                                  (``FitResult.as_dict``), the session that stored
                                  it (a random id per start, pid, time) and the sha256
                                  of them: the store's own count of who computed what
    OUT/.units/lock               held (flock) while a campaign runs on OUT

A unit file is written to a temporary file in its directory, flushed to
disk, then renamed over its final name (``os.replace``): it is absent or
complete, whenever the process dies.  On reading, a file that does not
parse, whose checksum does not match, or that belongs to another task or
campaign is reported corrupt, removed and its unit redone.  A campaign whose
fingerprint differs from the stored one is refused (InputError, exit 2)
rather than mixing results.
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
import time
import uuid

import numpy as np

try:
    import fcntl
except ImportError:  # no flock (Windows): no protection against two runs at once
    fcntl = None

from ..errors import InputError
from ..records.device import as_device
from ..fit import FitResult
from ..fit.result import Parent

#: format of the unit files and campaign.json
SCHEMA_VERSION = 1
UNITS_DIR = ".units"


def canonical(data) -> str:
    """JSON text with sorted keys and no spaces: the bytes a checksum covers."""
    return json.dumps(data, sort_keys=True, separators=(",", ":"), default=_plain)


def sha256(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()


def _plain(x):
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, np.floating):
        return float(x)
    if isinstance(x, np.ndarray):
        return x.tolist()
    raise TypeError(f"not JSON serializable: {type(x).__name__}")


def _json_data(data):
    """``data`` as parsed JSON (plain lists, dicts, floats; key order kept)."""
    return json.loads(json.dumps(data, default=_plain))


def result_to_dict(r: FitResult) -> dict:
    """A FitResult as plain JSON data: ``FitResult.as_dict`` plus the parameter
    order ('names'); floats round-trip exactly."""
    return _json_data({**r.as_dict(), "names": list(r.names)})


def result_from_dict(d: dict) -> FitResult:
    """The FitResult of ``result_to_dict``."""
    names = list(d["names"])
    return FitResult(spec=d["spec"], names=names, units=[d["units"][n] for n in names],
                     values=np.array([d["params"][n] for n in names], dtype=float), of=float(d["of"]),
                     bounds=np.array([d["bounds"][n] for n in names], dtype=float).reshape(-1, 2),
                     bounds_mode=d["bounds_mode"], optimizer=d["optimizer"], seed=d["seed"],
                     evaluations=int(d["evaluations"]), history=[float(h) for h in d["history"]],
                     wall_s=float(d["wall_s"]), record=d["record"], log=[bool(x) for x in d["log"]],
                     off=list(d["off"]), tests=list(d.get("tests") or []),
                     test_of=[float(x) for x in d.get("test_of") or []],
                     widened={n: tuple(b) for n, b in (d.get("widened") or {}).items()},
                     parent=Parent(d["parent"][0], float(d["parent"][1])) if d.get("parent") else None,
                     stop=str(d.get("stop") or ""), flat_ends=list(d.get("flat_ends") or []),
                     zero={t: tuple(z) for t, z in d["zero"].items()} if d.get("zero") else None,
                     floor=None if d.get("floor") is None else float(d["floor"]))


def record_digest(rec) -> str:
    """sha256 of a record's (or a device's) name and samples (t, d, F, v of
    each test): what a unit was fitted to."""
    h = hashlib.sha256(rec.name.encode())
    for x in (a for test in as_device(rec).tests for a in (test.t, test.d, test.F, test.v)):
        h.update(np.ascontiguousarray(x, dtype="<f8").tobytes())
    return h.hexdigest()


def first_difference(old, new, path: str = "") -> str | None:
    """'settings.runs: 5 -> 3': the first place two JSON-like values differ, or None."""
    if isinstance(old, dict) and isinstance(new, dict):
        for key in list(old) + [k for k in new if k not in old]:
            where = f"{path}.{key}" if path else str(key)
            if key not in old or key not in new:
                return f"{where}: {'added' if key not in old else 'removed'}"
            diff = first_difference(old[key], new[key], where)
            if diff:
                return diff
        return None
    if isinstance(old, list) and isinstance(new, list) and len(old) == len(new):
        for k, (a, b) in enumerate(zip(old, new)):
            diff = first_difference(a, b, f"{path}[{k}]")
            if diff:
                return diff
        return None
    if old != new:
        return f"{path}: {_short(old)} -> {_short(new)}"
    return None


def _records_difference(old: list, new: list) -> str | None:
    """'record device_03 changed (its samples differ)' or 'devices: 4 -> 5', or None."""
    names_old, names_new = [r["name"] for r in old], [r["name"] for r in new]
    if names_old != names_new:
        return f"devices: {_short(names_old)} -> {_short(names_new)}"
    changed = [a["name"] for a, b in zip(old, new) if a["sha256"] != b["sha256"]]
    return f"record {changed[0]} changed (its samples differ)" if changed else None


def _short(x) -> str:
    text = json.dumps(x, default=str)
    return text if len(text) <= 40 else text[:37] + "..."


class UnitStore:
    """Finished units of one campaign in ``OUT/.units`` (module doc).

    ``check(settings)`` refuses changed settings before any work;
    ``open(settings, records)`` fixes the fingerprint and takes the lock;
    ``load(task)`` returns a stored FitResult or None; ``save(task, result)``
    writes one atomically.  ``computed``, ``corrupt`` count this session's.
    """

    def __init__(self, out: str, source: str = "campaign"):
        self.out, self.source = out, source
        self.root = os.path.join(out, UNITS_DIR)
        self.fingerprint = None
        self.session = uuid.uuid4().hex[:12]  # this start of the campaign
        self.computed = 0
        self.corrupt: list = []  # (path, reason) of units found corrupt and redone
        self._lock = None

    # --------------------------------------------------------------- identity
    @property
    def campaign_file(self) -> str:
        return os.path.join(self.root, "campaign.json")

    def _stored(self) -> dict | None:
        try:
            with open(self.campaign_file) as fh:
                data = json.load(fh)
        except FileNotFoundError:
            return None
        except (OSError, ValueError) as exc:
            raise InputError(f"{self.campaign_file}: unreadable ({exc}); remove {self.root} to start afresh") from None
        if not isinstance(data, dict) or data.get("schema_version") != SCHEMA_VERSION or "content" not in data:
            raise InputError(f"{self.campaign_file}: not a campaign store of schema_version {SCHEMA_VERSION}")
        return data

    def _refuse(self, diff: str):
        raise InputError(f"{self.source}: the campaign changed since {self.out} was started ({diff}); "
                         f"results would mix: restore it, or give another out (or remove {self.root})")

    def check(self, settings: dict) -> None:
        """Refuse ``settings`` that differ from the stored campaign's (before any work)."""
        stored = self._stored()
        if stored is not None:
            diff = first_difference(stored["content"]["settings"], _json_data(settings), "settings")
            if diff:
                self._refuse(diff)

    def open(self, settings: dict, records) -> str:
        """Fix the fingerprint of (settings, records) and lock the store; returns the fingerprint."""
        content = _json_data({"settings": settings,
                              "records": [{"name": r.name, "sha256": record_digest(r)} for r in records]})
        fingerprint = sha256(canonical(content))
        os.makedirs(self.root, exist_ok=True)
        self._take_lock()
        stored = self._stored()
        if stored is None:
            self._atomic_write(self.campaign_file, {"schema_version": SCHEMA_VERSION, "fingerprint": fingerprint,
                                                    "created": time.strftime("%Y-%m-%dT%H:%M:%S"),
                                                    "content": content})
        elif stored["fingerprint"] != fingerprint:
            self._refuse(_records_difference(stored["content"]["records"], content["records"])
                         or first_difference(stored["content"], content) or "fingerprint")
        self.fingerprint = fingerprint
        self._clean_temporaries()
        return fingerprint

    def _take_lock(self):
        if fcntl is None:  # no flock (Windows): no protection against two runs at once
            return
        fh = open(os.path.join(self.root, "lock"), "a+")
        try:
            fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            fh.close()
            raise InputError(f"{self.out}: another campaign is running on it (lock {self.root}/lock)") from None
        self._lock = fh

    def close(self):
        if self._lock is not None:
            self._lock.close()
            self._lock = None

    def _clean_temporaries(self):
        """Remove temporary files a killed run left behind (never a finished unit)."""
        for root, _, files in os.walk(self.root):
            for f in files:
                if f.startswith(".") and ".tmp" in f:
                    os.remove(os.path.join(root, f))

    # ------------------------------------------------------------------ units
    def path(self, task) -> str:
        """OUT/.units/<device>/law<spec>/run<k>.json."""
        parts = task.id.split("/")
        if any(p in ("", ".", "..") for p in parts):
            raise InputError(f"device name '{task.device}': not usable as a directory name")
        return os.path.join(self.root, *parts) + ".json"

    def load(self, task) -> FitResult | None:
        """The stored result of ``task``, or None when absent; a corrupt file is removed (and counted)."""
        path = self.path(task)
        try:
            with open(path) as fh:
                text = fh.read()
        except FileNotFoundError:
            return None
        reason = None
        try:
            data = json.loads(text)
            unit = data["unit"]
            if data.get("checksum") != "sha256:" + sha256(canonical(unit)):
                reason = "checksum mismatch"
            elif unit["task"]["id"] != task.id or unit["fingerprint"] != self.fingerprint:
                reason = "belongs to another task or campaign"
            else:
                return result_from_dict(unit["result"])
        except (ValueError, KeyError, TypeError) as exc:
            reason = f"unreadable ({type(exc).__name__})"
        self.corrupt.append((path, reason))
        os.remove(path)
        return None

    def save(self, task, result: FitResult) -> FitResult:
        """Write ``task``'s result atomically, count it; returns it as read back from its data."""
        unit = {"task": {"id": task.id, "device": task.device, "spec": task.spec, "run": task.run,
                         "seed": list(task.seed)},
                "fingerprint": self.fingerprint, "result": result_to_dict(result),
                "stored": {"session": self.session, "pid": os.getpid(),
                           "time": time.strftime("%Y-%m-%dT%H:%M:%S")}}
        unit = _json_data(unit)
        self._atomic_write(self.path(task), {"schema_version": SCHEMA_VERSION,
                                             "checksum": "sha256:" + sha256(canonical(unit)), "unit": unit})
        self.computed += 1
        return result_from_dict(unit["result"])

    @staticmethod
    def _atomic_write(path: str, data: dict) -> None:
        folder = os.path.dirname(path)
        os.makedirs(folder, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=folder, prefix=f".{os.path.basename(path)}.tmp")
        try:
            with os.fdopen(fd, "w") as fh:
                fh.write(json.dumps(data, indent=1, default=_plain))
                fh.flush()
                os.fsync(fh.fileno())
            os.replace(tmp, path)
        except BaseException:
            if os.path.exists(tmp):
                os.remove(tmp)
            raise
        try:  # make the rename itself durable
            dfd = os.open(folder, os.O_RDONLY)
            try:
                os.fsync(dfd)
            finally:
                os.close(dfd)
        except OSError:
            pass
