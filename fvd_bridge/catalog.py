"""The catalog: the nine laws, the built-in effects and the plugin effects,
loaded once per process.

Everything that turns a name into a law, an effect or a model asks a
Catalog; plugin files are named by path (``--plugin FILE.py``) and loaded the
first time a catalog with them is asked for (``catalog(paths)`` caches it per
process, so a campaign worker loads them once).

Data never runs code: a calibration file records the plugin files its model
needs by name and sha256 (``plugin_files``), and reading it imports only the
plugins its caller gives, once they match that record (``catalog_for``).
"""

from __future__ import annotations

import functools
import os

from .effects.base import Effect
from .effects.catalog import EFFECTS
from .effects.plugins import file_sha256, load_plugins
from .errors import InputError, PluginNeeded, command, option
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
                             f"see {command('effects')})")
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
    return _cached(_paths(plugin_paths))


#: the hex digits of a sha256 a message shows
HASH_SHOWN = 12


def plugin_files(model) -> list[dict]:
    """The plugin files ``model``'s effects come from, as a calibration file
    records them: [{file: name, sha256: hex}] ([] for built-in effects only)."""
    files: dict = {}
    for e in model.effects:
        if e.name not in EFFECTS:
            files.setdefault(e.source, e.source_sha256)
    return [{"file": name, **({"sha256": digest} if digest else {})} for name, digest in files.items()]


def recorded_plugins(where: str, entries) -> dict:
    """{file name: sha256 or None} of a calibration file's ``settings.plugins``:
    {file, sha256} mappings, or the paths older files list (checked by name only)."""
    if not isinstance(entries, (list, tuple)):
        raise InputError(f"{where}: key 'settings.plugins' must be a list of {{file, sha256}}")
    out = {}
    for entry in entries:
        name = entry.get("file") if isinstance(entry, dict) else entry
        if not isinstance(name, str) or not name:
            raise InputError(f"{where}: key 'settings.plugins': {entry!r} names no plugin file")
        digest = entry.get("sha256") if isinstance(entry, dict) else None
        out[os.path.basename(name)] = str(digest).lower() if digest else None
    return out


def catalog_for(where: str, spec, recorded: dict, plugins=(), given: Catalog | None = None) -> Catalog:
    """The catalog that reads a file's model ``spec``, importing nothing the
    caller did not give.

    Parameters
    ----------
    where : str
        The file, for messages.
    spec : str
        Its model, e.g. ``"2+cubic_spring"``.
    recorded : dict
        {file name: sha256 or None}: the plugins the file needs (``recorded_plugins``).
    plugins : list of str
        The caller's plugin files (``--plugin``, ``plugins=``).
    given : Catalog, optional
        The caller's catalog; its plugin files stand for ``plugins``.

    Returns
    -------
    Catalog
        The built-in one when every effect of ``spec`` is built in; else the
        caller's plugins, once each recorded plugin is among them (by file
        name) with the recorded sha256, checked before any import.  Otherwise
        PluginNeeded, one line naming the plugin and how to give it.
    """
    foreign = [n.strip() for n in str(spec).split("+")[1:] if n.strip() not in EFFECTS]
    if not foreign:
        return given or _cached(())
    offered = given.plugin_paths if given is not None else _paths(plugins)
    by_name = {os.path.basename(p): p for p in offered}
    missing = {name: digest for name, digest in recorded.items() if name not in by_name}
    if missing or not offered:
        raise PluginNeeded(_needed(where, spec, missing, foreign))
    for name, digest in recorded.items():
        got = file_sha256(by_name[name])
        if digest and got != digest:
            raise PluginNeeded(f"{where}: plugin {by_name[name]} has sha256 {got[:HASH_SHOWN]}, the file records "
                               f"{digest[:HASH_SHOWN]} for {name}: not the plugin it was calibrated with")
    return given or _cached(offered)


def _needed(where: str, spec, missing: dict, foreign: list) -> str:
    """One line: which plugin the file's model needs and how to give it."""
    rule = "a calibration file never runs code, so give the plugin yourself if you trust it"
    if not missing:
        return (f"{where}: key 'model': {spec}: effect '{foreign[0]}' is not built in and the file names no "
                f"plugin for it; {rule}: {option('--plugin', 'FILE.py')}")
    names = ", ".join(f"{name} (sha256 {digest[:HASH_SHOWN]})" if digest else name
                      for name, digest in missing.items())
    first = next(iter(missing))
    return (f"{where}: model {spec} needs the plugin{'s' if len(missing) > 1 else ''} {names}; {rule}: "
            f"{option('--plugin', first)}")


def _paths(plugin_paths) -> tuple:
    if isinstance(plugin_paths, (str, os.PathLike)):
        plugin_paths = (plugin_paths,)
    return tuple(os.fspath(p) for p in plugin_paths or ())
