"""A virtual device made of a catalog model (any law with effects): friction
and hysteretic devices (laws 6, 8, 9) behind a contact gap, for instance,
which the orifice ``VirtualDamper`` does not cover.

The model runs on the protocol's analytic motion sampled ``oversample``
times finer than the output (its own sub-steps on top), and the output keeps
every ``oversample``-th sample, so the record is not the model's own
discretisation at the output step.  Noise as ``simulate``: force noise
first, then displacement noise, from numpy.random.default_rng(seed) (none
without ``noise``: the exact record); v and a are the exact imposed ones.  Units: kN, mm, s.
"""

from __future__ import annotations

import numpy as np

from ..records import Record
from .protocols import Protocol
from .simulate import Noise

#: output samples are every OVERSAMPLE-th of the simulation's
OVERSAMPLE = 8


def simulate_model(model, params, protocol: Protocol, noise: Noise | None = None, seed=None,
                   name: str = "model device", oversample: int = OVERSAMPLE, substeps: int = 4) -> Record:
    """A record of ``model`` (fvd_bridge.model.Model) with parameters
    ``params`` (``model.names`` order) under ``protocol``."""
    noise = noise or Noise(0.0, 0.0)
    t = protocol.times()
    fine_dt = protocol.dt / oversample
    tf = t[0] + np.arange((t.size - 1) * oversample + 1) * fine_dt
    d, v, a = protocol.motion(tf)
    fine = Record(tf, d, np.zeros_like(tf), v, a, name=name)
    F = model.force(fine, np.asarray(params, dtype=float)[None, :], substeps)[0][::oversample]
    d, v, a = d[::oversample], v[::oversample], a[::oversample]
    rng = np.random.default_rng(seed)
    F = F + (noise.force * rng.standard_normal(F.size) if noise.force else 0.0)
    d_meas = d + (noise.displacement * rng.standard_normal(d.size) if noise.displacement else 0.0)
    prov = {"source": "fvd_bridge.rig.simulate_model", "model": model.spec,
            "params": {n: float(x) for n, x in zip(model.names, params)},
            "protocol": protocol.describe(), "noise": noise.describe(),
            "units": {"t": "s", "d": "mm", "F": "kN", "v": "mm/s"},
            "velocity": {"method": "exact (rig protocol)"},
            "integration": {"oversample": int(oversample), "substeps": int(substeps)}}
    return Record(t.copy(), d_meas, F, v, a, name=name, provenance=prov)
