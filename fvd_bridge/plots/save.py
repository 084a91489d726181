"""Saving figures atomically (temp file, then rename), and the Axes a figure draws on (``axes``, ``finish``)."""

from __future__ import annotations

import os

import numpy as np
import matplotlib.pyplot as plt
from matplotlib.figure import Figure

from ..errors import InputError
from ..io.staging import atomic_file


def save(fig, path: str, dpi: int = 110, tight: bool = True) -> str:
    """Write ``fig`` to ``path`` (PNG) without leaving a partial file; closes it.
    ``tight``: crop to the drawn area (a second drawing pass), unless a layout engine placed the Axes."""
    fmt = os.path.splitext(path)[1].lstrip(".").lower() or "png"
    try:
        with atomic_file(path, "wb") as fh:
            fig.savefig(fh, format=fmt, dpi=dpi,
                        bbox_inches="tight" if tight and not fig.get_layout_engine() else None)
    finally:
        plt.close(fig)
    return path


def axes(ax, nrows: int = 1, ncols: int = 1, **kw):
    """(Figure, Axes) to draw on: the caller's ``ax`` (an Axes; for a figure
    of several panels an array of nrows x ncols Axes, or a Figure to fill),
    else a new pyplot figure (``kw``: plt.subplots' options)."""
    if ax is None:
        return plt.subplots(nrows, ncols, **kw)
    squeeze = kw.get("squeeze", True)
    if isinstance(ax, Figure):
        return ax, ax.subplots(nrows, ncols, squeeze=squeeze, sharex=kw.get("sharex", False))
    grid = np.asarray(ax, dtype=object)
    if grid.size != nrows * ncols:
        raise InputError(f"ax: this figure draws {nrows} x {ncols} panels; give as many Axes, or a Figure")
    grid = grid.reshape(nrows, ncols)
    if squeeze:
        grid = grid[0, 0] if grid.size == 1 else grid.reshape(-1) if 1 in (nrows, ncols) else grid
    return grid.flat[0].figure if isinstance(grid, np.ndarray) else grid.figure, grid


def finish(fig, path: str | None, ax, tight: bool = True):
    """``path`` when given (the figure written there and closed; ``tight``
    as ``save``); else what was drawn on, left open: the Axes of a one-panel
    figure, or the Figure."""
    if path:
        return save(fig, path, tight=tight)
    return ax if not isinstance(ax, np.ndarray) else fig
