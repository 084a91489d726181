"""The catalog: the nine laws, the built-in effects and the plugin effects,
loaded once per process.

Everything that turns a name into a law, an effect or a model asks a
Catalog; plugin files are named by path (``--plugin FILE.py``) and loaded the
first time a catalog with them is asked for (``catalog(paths)`` caches it per
process, so a campaign worker loads them once).
"""

from __future__ import annotations

import functools
import os

from .effects.base import Effect
from .effects.catalog import EFFECTS
from .effects.plugins import load_plugins
from .errors import InputError
from .laws import LAWS, get_law
from .model import Model


class Catalog:
    """Laws and effects by name; ``plugin_paths`` are the files the plugin effects came from."""

    def __init__(self, plugin_effects: dict | None = None, plugin_paths: tuple = ()):
        self.laws = dict(LAWS)
        self.plugin_paths = tuple(plugin_paths)
        self.effects: dict[str, Effect] = {**EFFECTS, **(plugin_effects or {})}

    def law(self, key):
        """Law by number ('2', 'law2', 2); an unknown key is an input error."""
        return get_law(key)

    def effect(self, name: str) -> Effect:
        """Effect by name; an unknown name is an input error listing the known ones."""
        key = str(name).strip()
        if key not in self.effects:
            raise InputError(f"unknown effect '{key}' (known: {', '.join(self.effects)}; "
                             f"see `fvd-bridge effects`)")
        return self.effects[key]

    def model(self, spec):
        """'2', 'law2' or '2+friction+series_stiffness' -> Model (``fvd_bridge.model``)."""
        text = str(spec).strip()
        law_key, *effect_names = [s.strip() for s in text.split("+")]
        model = Model(self.law(law_key))
        for name in effect_names:
            model = model.with_effect(self.effect(name), text)
        return model


@functools.lru_cache(maxsize=None)
def _cached(paths: tuple) -> Catalog:
    if not paths:
        return Catalog()
    return Catalog(load_plugins(list(paths)), paths)


def parse_model(spec, catalog: Catalog | None = None) -> Model:
    """A model from its spec.

    Parameters
    ----------
    spec : str
        A law and its effects: ``"2"``, ``"law2"`` or ``"2+friction+series_stiffness"``.
    catalog : Catalog, optional
        Where laws and effects come from; default the built-in ones.

    Returns
    -------
    Model
        An unknown law or effect raises InputError naming it.
    """
    return (catalog or _cached(())).model(spec)


def catalog(plugin_paths=()) -> Catalog:
    """The catalog with the effects of these plugin files (loaded once per process)."""
    if isinstance(plugin_paths, str):
        plugin_paths = (plugin_paths,)
    return _cached(tuple(os.fspath(p) for p in plugin_paths or ()))
