"""Explain the misfit: where a model fails, which physical effect is missing,
and the ladder that adds effects while they help beyond the noise floor."""

from .core import DIAGNOSE_GENS, Diagnosis, diagnose, diagnose_settings
from .ladder import Ladder, Rung, climb
from .rank import MARGIN, Candidate, Judge, floor_uncertainty
from ..text.diagnosis import format_diagnosis, format_ladder
from .where import analyse, summary_lines

__all__ = ["DIAGNOSE_GENS", "MARGIN", "Candidate", "Diagnosis", "Judge",
           "Ladder", "Rung", "analyse", "climb", "diagnose", "diagnose_settings", "floor_uncertainty",
           "format_diagnosis", "format_ladder", "summary_lines"]
