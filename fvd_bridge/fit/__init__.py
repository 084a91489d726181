"""Fitting: the paper's objective (eq. 18), its GA, the default optimizer, results."""

from .api import DEFAULT_OPTIMIZER, OPTIMIZERS, evaluate_params, fit_model, polish_model, settings_for
from .objective import mean_abs_noise, noise_floor, objective
from .result import FitResult

__all__ = ["DEFAULT_OPTIMIZER", "OPTIMIZERS", "FitResult", "evaluate_params", "fit_model", "mean_abs_noise",
           "noise_floor", "objective", "polish_model", "settings_for"]
