"""Physical effects that compose with any law: gap, series stiffness,
asymmetry, heating, friction, parallel stiffness, inertia, and user effects
from plugin files.  A model spec is 'LAW+EFFECT+EFFECT' (fvd_bridge.model)."""

from ..errors import InputError
from ..laws.base import Parameter
from .base import STAGES, Effect
from .catalog import BUILTIN, EFFECTS, FRICTION_V_F

__all__ = ["BUILTIN", "EFFECTS", "FRICTION_V_F", "STAGES", "Effect", "Parameter", "all_effects",
           "get_effect"]


def all_effects(plugins: dict | None = None) -> dict:
    """Built-in effects followed by plugin effects: {name: Effect}."""
    return {**EFFECTS, **(plugins or {})}


def get_effect(name: str, plugins: dict | None = None) -> Effect:
    """Effect by name; an unknown name is an input error listing the known ones."""
    known = all_effects(plugins)
    key = str(name).strip()
    if key not in known:
        raise InputError(f"unknown effect '{key}' (known: {', '.join(known)}; see `fvd-bridge effects`)")
    return known[key]
