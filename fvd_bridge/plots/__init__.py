"""Figures (matplotlib, Agg): one module per subject."""
