"""Model = law + effects, the spec string '2+friction+series_stiffness',
and the layout of the parameter vector (law parameters, then 'effect.param').
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .errors import InputError
from .laws import Law, get_law


@dataclass(frozen=True)
class Model:
    """A law with optional physical effects; ``force(record, P)`` -> (pop, n_t) [kN]."""

    law: Law
    effects: tuple = field(default_factory=tuple)

    @property
    def spec(self) -> str:
        return "+".join([self.law.key] + [e.name for e in self.effects])

    @property
    def parameters(self) -> list:
        """All parameters in vector order (law first, then each effect's)."""
        out = list(self.law.parameters)
        for e in self.effects:
            out.extend(e.parameters)
        return out

    @property
    def names(self) -> list[str]:
        return self.law.names + [f"{e.name}.{p.name}" for e in self.effects for p in e.parameters]

    @property
    def units(self) -> list[str]:
        return [p.unit for p in self.parameters]

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


def parse_model(spec, plugins: dict | None = None) -> Model:
    """'2', 'law2' or '2+friction+series_stiffness' -> Model.

    Effects come from fvd_bridge.effects and ``plugins`` (name -> Effect);
    unknown names and clashing parameter names are input errors.
    """
    text = str(spec).strip()
    law_key, *effect_names = [s.strip() for s in text.split("+")]
    law = get_law(law_key)
    if not effect_names:
        return Model(law)
    from .effects import get_effect

    effects = tuple(get_effect(n, plugins) for n in effect_names)
    seen = set()
    for e in effects:
        if e.name in seen:
            raise InputError(f"model '{text}': effect '{e.name}' appears twice")
        seen.add(e.name)
    model = Model(law, effects)
    if len(set(model.names)) != len(model.names):
        dup = sorted({n for n in model.names if model.names.count(n) > 1})[0]
        raise InputError(f"model '{text}': parameter name '{dup}' clashes")
    return model
