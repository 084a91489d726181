"""Lab-like records for tests: simulated, written as CSV t,d,F with the unit
sidecar (as ``fvd-bridge rig`` writes them) and read back by fvd_bridge's
reader, so that v and a are derived from the noisy displacement by the tool,
as they are for a lab record (not the rig's exact v and a).

    rec = lab_record(VirtualDamper(C=45.4, alpha=0.3), paper(cycles=3), 1.0, 0.005, seed=0, tmp_path=tmp_path)
    rec = lab_from_forces(t, d, F, 1.0, 0.005, seed=0, tmp_path=tmp_path, name="law9")

Noise is drawn as ``fvd_bridge.rig.simulate`` draws it (force first, then
displacement, from numpy.random.default_rng(seed)), so the same seed gives
the same noise as an in-memory ``simulate``. The returned record's
provenance['truth'] holds what made it (rig parameters or the caller's
note, protocol, noise, seed). Units: kN, mm, s.
"""

from __future__ import annotations

import os
import warnings

import numpy as np

from fvd_bridge.records import Record, RecordWarning, read_record
from fvd_bridge.records.writers import write_csv
from fvd_bridge.rig import VirtualDamper, Noise, simulate

#: lab-like defaults: force noise [kN], displacement noise [mm]
FORCE_NOISE, DISP_NOISE = 1.0, 0.005


def lab_record(source, protocol=None, force_noise: float = FORCE_NOISE, disp_noise: float = DISP_NOISE,
               seed=0, tmp_path=None, name: str | None = None, opts=None) -> Record:
    """A lab-like record of ``source`` under ``protocol``.

    ``source``: a rig ``VirtualDamper`` (simulated under ``protocol``), or the dict
    of ``fvd_bridge.rig.trace`` (its exact t, d, F; ``protocol`` unused).
    ``tmp_path``: the directory the CSV and its sidecar go to (pytest's
    tmp_path); ``opts``: ReadOptions for reading it back (e.g. a fixed
    --sg-window). Reading must give no RecordWarning.
    """
    if isinstance(source, VirtualDamper):
        if protocol is None:
            raise ValueError("lab_record: a VirtualDamper needs a protocol")
        exact = simulate(source, protocol, None, name=name or source.name)
        truth = {k: exact.provenance[k] for k in ("rig", "protocol")}
        return lab_from_forces(exact.t, exact.d, exact.F, force_noise, disp_noise, seed, tmp_path,
                               name=name or source.name, truth=truth, opts=opts)
    if isinstance(source, dict) and {"t", "d", "F"} <= set(source):
        return lab_from_forces(source["t"], source["d"], source["F"], force_noise, disp_noise, seed, tmp_path,
                               name=name or "trace", truth={"source": "rig trace"}, opts=opts)
    raise TypeError("lab_record: source must be a fvd_bridge.rig.VirtualDamper or a rig trace dict")


def lab_from_forces(t, d_exact, F_exact, force_noise: float = FORCE_NOISE, disp_noise: float = DISP_NOISE,
                    seed=0, tmp_path=None, name: str = "model", truth: dict | None = None, opts=None) -> Record:
    """A lab-like record from an exact displacement d_exact [mm] and force
    F_exact [kN] at times t [s] (e.g. a model's force on a protocol's
    motion): noise added (force first, then displacement, as the rig does),
    written as ``tmp_path/NAME.csv`` with its sidecar, read back."""
    if tmp_path is None:
        raise ValueError("lab_from_forces: give tmp_path, the directory to write the CSV to")
    noise = Noise(force_noise, disp_noise)
    t, d, F = (np.asarray(x, dtype=float) for x in (t, d_exact, F_exact))
    rng = np.random.default_rng(seed)
    F = F + (noise.force * rng.standard_normal(F.size) if noise.force else 0.0)
    d = d + (noise.displacement * rng.standard_normal(d.size) if noise.displacement else 0.0)
    path = os.path.join(os.fspath(tmp_path), f"{name}.csv")
    zero = np.zeros_like(t)
    write_csv(Record(t, d, F, zero, zero, name=name), path,
              comment=f"lab-like test record {name}: noise {noise.force:g} kN / {noise.displacement:g} mm, "
                      f"seed {seed}")
    with warnings.catch_warnings():
        warnings.simplefilter("error", RecordWarning)
        rec = read_record(path, opts, name=name)
    rec.provenance["truth"] = {**(truth or {}), "noise": noise.describe(), "seed": seed}
    return rec
