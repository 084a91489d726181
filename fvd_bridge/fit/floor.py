"""The noise floor of a record: the OF the true model would reach on it.

A lab record carries noise on the force *and* on the displacement, and the
velocity and acceleration the tool derives from the displacement carry that
noise amplified by the differentiator.  The model is evaluated on those
inputs, so its force carries their noise through its sensitivity (dF/dv,
dF/dd): for a law with alpha ~ 0.3, dF/dv -> infinity at the reversals.

The floor is estimated from the record itself, by propagating both noises
through the fitted model (Monte Carlo, ``FLOOR_DRAWS`` draws, seeded):

    e_d ~ N(0, sigma_d) white, sigma_d the record's displacement noise;
    d' = d + e_d, v', a' = the record's differentiator applied to d';
    e_F ~ N(0, sigma_F) white, sigma_F the record's force noise;
    OF_floor = mean over draws of  integral |F(d', v', a') - F(d, v, a) + e_F| dt
                                    / (std(F_measured) (t_end - t_start))

(eq. 18 of the error that noise alone makes).  A measured velocity column
gets white noise of the reader's estimate of its noise (``record.v_noise``)
instead of the differentiator's.  Without displacement noise
this is E|e_F| / std(F) = sigma_F sqrt(2/pi) / std(F), the force-only floor
``fit.noise_floor``, which the report gives beside it.

The floor belongs to the record, not to a model (``record_floor``): it is
propagated through the law alone, the effects off, and a diagnosis and
every rung of its ladder judge each model against that one number.  An
effect's own sensitivity must not raise it: through a gap's jump or a
series spring's stiff branch the derived velocity's noise makes several
times the law's error (on a real friction damper's record, 0.0005 through
law 9 against 0.0057 through law 9 with a gap and a spring), so "16x the
floor" would mean different things for different models.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from .objective import noise_floor, objective
from ..model import Model
from ..records.cycles import force_noise
from ..records.velocity import rederive, rest_mask

#: Monte Carlo draws of the input noise
FLOOR_DRAWS = 4


def displacement_noise(record) -> float:
    """The record's displacement noise std [mm]: the reader's estimate, else
    the same 4th-difference estimate as the force's."""
    value = getattr(record, "d_noise", None)
    return float(value) if value is not None else force_noise(record.d)


@dataclass(frozen=True)
class NoiseFloor:
    """A record's noise floor (module docstring): ``floor``, the OF (eq. 18)
    its force and displacement noise give through the model; ``force_floor``,
    the force noise's alone; the noise std of the force ``sigma_F`` [kN],
    the displacement ``sigma_d`` [mm] and the derived velocity ``sigma_v``
    [mm/s] (the median over the record)."""

    floor: float
    force_floor: float
    sigma_F: float
    sigma_d: float
    sigma_v: float = 0.0

    def as_dict(self) -> dict:
        """{floor, force_floor, sigma_F, sigma_d, sigma_v} (the --json report's 'noise')."""
        return dataclasses.asdict(self)


def input_noise_floor(model, params, record, seed: int = 0, draws: int = FLOOR_DRAWS, F_ref=None) -> NoiseFloor:
    """The NoiseFloor of ``model`` at ``params`` on ``record`` (module
    docstring); ``F_ref`` its force on the record, when already computed."""
    sigma_F = force_noise(record.F)
    sigma_d = displacement_noise(record)
    force_only = noise_floor(sigma_F, record.F)
    out = NoiseFloor(force_only, force_only, float(sigma_F), float(sigma_d))
    if not np.isfinite(sigma_F) or not np.isfinite(sigma_d):
        return out
    p = np.asarray(params, dtype=float)[None, :]
    F_ref = model.force(record, p)[0] if F_ref is None else F_ref
    rng = np.random.default_rng([int(seed), 1789])
    still = rest_mask(record)  # the record's rests hold still in every draw (noise on noise hides them)
    ofs, dv = [], []
    for _ in range(draws):
        d_new = record.d + sigma_d * rng.standard_normal(record.n)
        derived = rederive(record, d_new)
        if derived is not None:
            v_new, a_new = derived
        elif getattr(record, "v_noise", None) is not None:  # a measured velocity with its own noise
            v_new, a_new = record.v + record.v_noise * rng.standard_normal(record.n), record.a
        else:  # exact v and a (a rig record in memory)
            v_new, a_new = record.v, record.a
        v_new, a_new = np.where(still, 0.0, v_new), np.where(still, 0.0, a_new)
        perturbed = dataclasses.replace(record, d=d_new, v=v_new, a=a_new)
        F_new = model.force(perturbed, p)[0] + sigma_F * rng.standard_normal(record.n)
        ofs.append(float(objective(record.F, record.F + (F_new - F_ref), record.t)))
        dv.append(float(np.median(np.abs(v_new - record.v))) / 0.6745)
    return dataclasses.replace(out, floor=float(np.mean(ofs)), sigma_v=float(np.median(dv)))


def record_floor(model, params, record, seed: int = 0) -> NoiseFloor:
    """``input_noise_floor`` of ``record`` through ``model``'s law alone at
    its law parameters (module docstring): the record's floor, the same for
    every model with that law."""
    law = Model(model.law, ())
    return input_noise_floor(law, np.asarray(params, dtype=float)[:len(model.law.parameters)], record, seed)


def device_floor(model, layout, params, device) -> float:
    """The noise floor of a device's tests together, as its OF is: the
    weighted mean of each test's ``record_floor`` at that test's parameters
    (``layout``: the fit's Layout; ``params``: its column vector)."""
    floors = [record_floor(model, layout.for_test(params, k)[0], test).floor for k, test in enumerate(device.tests)]
    return float(np.dot(device.weights, floors))


def device_force_floor(device) -> float:
    """The force noise's floor alone (``noise_floor`` of each test's 4th-difference
    force noise, weighted as the OF is): below ``device_floor``, and a
    fraction of its cost (no propagation)."""
    return float(np.dot(device.weights, [noise_floor(force_noise(t.F), t.F) for t in device.tests]))
