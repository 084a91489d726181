"""Physical effects that compose with any law: gap, series stiffness,
asymmetry, heating, friction, parallel stiffness, inertia, and user effects
from plugin files.  A model spec is 'LAW+EFFECT+EFFECT' (fvd_bridge.model);
names are resolved by fvd_bridge.catalog."""

from ..laws.base import Parameter
from .base import STAGES, Effect
from .catalog import BUILTIN, EFFECTS, FRICTION_V_F

__all__ = ["BUILTIN", "EFFECTS", "FRICTION_V_F", "STAGES", "Effect", "Parameter"]
