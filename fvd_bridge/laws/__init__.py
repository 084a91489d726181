"""The nine FVD laws of the paper: parameters, bounds, population drivers, scalar steps."""

from .base import BOUND_MODES, Law, Parameter
from .catalog import LAWS, get_law, parse_law_list

__all__ = ["BOUND_MODES", "LAWS", "Law", "Parameter", "get_law", "parse_law_list"]
