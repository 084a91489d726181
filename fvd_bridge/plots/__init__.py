"""Figures (matplotlib, Agg): one module per subject.

Each module imports matplotlib at its top; the rest of the package imports
these modules only inside the function that draws (matplotlib takes about a
second to import, and a run without figures needs none of it)."""
