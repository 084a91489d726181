"""Figures (matplotlib, Agg): one module per subject.

Each module imports matplotlib at its top; the rest of the package imports
these modules only inside the function that draws (matplotlib takes about a
second to import, and a run without figures needs none of it).

Every function draws on the caller's ``ax`` when given (an Axes; for a
figure of several panels as many Axes, or a Figure: ``save.axes``) and
returns what it drew on, left open; given a ``path`` it writes the figure
there, closes it and returns the path."""
