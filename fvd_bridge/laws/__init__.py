"""The FVD laws (the paper's nine and the bilinear oil damper): parameters,
bounds, population drivers, scalar steps, export forms."""

from .base import BOUND_MODES, Law, Parameter
from .catalog import LAWS, PAPER_LAWS, PAPER_SPEC, get_law, parse_law_list

__all__ = ["BOUND_MODES", "LAWS", "Law", "PAPER_LAWS", "PAPER_SPEC", "Parameter", "get_law", "parse_law_list"]
