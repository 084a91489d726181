"""Fitting: the paper's objective, its GA, the default optimizer, results."""
