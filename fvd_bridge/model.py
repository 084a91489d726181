"""Model = law + effects: the spec string '2+friction+series_stiffness', the
parameter vector layout (law parameters, then 'effect.param'), derived
quantities, and the operations that add or remove an effect.

A Model is the interface: no module builds or splits a spec string itself.
Models come from ``fvd_bridge.catalog`` (``catalog().model(spec)`` or
``parse_model(spec)``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .errors import InputError
from .laws import Law


@dataclass(frozen=True)
class Model:
    """A law with optional physical effects; ``force(record, P)`` -> (pop, n_t) [kN]."""

    law: Law
    effects: tuple = field(default_factory=tuple)

    @classmethod
    def from_spec(cls, spec: str, plugins=()) -> "Model":
        """'2', '9+gap' or '2+series_stiffness+friction' -> Model; ``plugins``: effect files."""
        return parse_model(spec, _catalog(plugins))

    @property
    def spec(self) -> str:
        """'2+friction': the law's number, then the effects in the order added."""
        return "+".join([self.law.key] + [e.name for e in self.effects])

    @property
    def effect_names(self) -> list[str]:
        return [e.name for e in self.effects]

    @property
    def parameters(self) -> list:
        """All parameters in vector order (law first, then each effect's)."""
        out = list(self.law.parameters)
        for e in self.effects:
            out.extend(e.parameters)
        return out

    @property
    def names(self) -> list[str]:
        """Parameter names in vector order: the law's, then 'effect.param'."""
        return self.law.names + [n for e in self.effects for n in e.names]

    @property
    def units(self) -> list[str]:
        return [p.unit for p in self.parameters]

    def has(self, effect_name: str) -> bool:
        return effect_name in self.effect_names

    def with_effect(self, effect, spec_text: str | None = None) -> "Model":
        """This model plus ``effect`` (an Effect); a repeated effect or a clashing
        parameter name is an input error (quoting ``spec_text`` when given)."""
        text = spec_text or f"{self.spec}+{effect.name}"
        if self.has(effect.name):
            raise InputError(f"model '{text}': effect '{effect.name}' appears twice")
        model = Model(self.law, self.effects + (effect,))
        names = model.names
        if len(set(names)) != len(names):
            dup = sorted({n for n in names if names.count(n) > 1})[0]
            raise InputError(f"model '{text}': parameter name '{dup}' clashes")
        return model

    def without_effect(self, effect_name: str) -> "Model":
        """This model without the named effect (the nested model)."""
        if not self.has(effect_name):
            raise InputError(f"model '{self.spec}' has no effect '{effect_name}'")
        return Model(self.law, tuple(e for e in self.effects if e.name != effect_name))

    def columns_without(self, effect_name: str) -> list[int]:
        """Indices of the parameter vector that remain without the named effect."""
        drop = set(next(e for e in self.effects if e.name == effect_name).names)
        return [k for k, n in enumerate(self.names) if n not in drop]

    def split(self, P: np.ndarray) -> tuple[np.ndarray, dict]:
        """(pop, n_par) -> the law's parameters (pop, n_law) and {effect name: (pop, n_e)}."""
        j = len(self.law.parameters)
        out = {}
        for e in self.effects:
            k = len(e.parameters)
            out[e.name] = P[:, j:j + k]
            j += k
        return P[:, :len(self.law.parameters)], out

    def derived(self, params) -> dict:
        """Derived quantities of one parameter vector: {name: (value, unit)} (law 8: mu*N [kN])."""
        p = np.asarray(params, dtype=float)[:len(self.law.parameters)]
        return {d.name: (float(d.value(p)), d.unit) for d in self.law.derived}

    def bounds(self, mode: str, scales: dict) -> np.ndarray:
        """(n_par, 2) bounds; effects use their own bounds in both modes."""
        rows = [self.law.bounds(mode, scales)]
        rows += [e.bounds(scales) for e in self.effects]
        return np.vstack(rows)

    def off_values(self) -> list:
        """Per parameter: the value that switches its effect off (None for law parameters)."""
        return [None] * len(self.law.parameters) + [v for e in self.effects for v in e.none]

    def log_scale(self, mode: str) -> np.ndarray:
        """Which parameters the default optimizer searches on a log scale."""
        return np.array([p.log and mode == "auto" for p in self.parameters])

    def force(self, record, P: np.ndarray, substeps: int = 1) -> np.ndarray:
        """Model force [kN] for each parameter row of P (pop, n_par) -> (pop, n_t)."""
        P = np.atleast_2d(np.asarray(P, dtype=float))
        if P.shape[1] != len(self.names):
            raise InputError(f"model {self.spec}: expected {len(self.names)} parameters "
                             f"({', '.join(self.names)}), got {P.shape[1]}")
        if not self.effects:
            return self.law.force(record.d, record.v, record.dt, P, substeps)
        from .effects.compose import composed_force

        return composed_force(self, record, P, substeps)


def parse_model(spec, catalog=None) -> Model:
    """'2', 'law2' or '2+friction+series_stiffness' -> Model, from ``catalog``
    (``fvd_bridge.catalog.Catalog``; default: the built-in laws and effects)."""
    return (catalog or _catalog()).model(spec)


def _catalog(plugins=()):
    from .catalog import catalog

    return catalog(plugins)
