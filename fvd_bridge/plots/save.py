"""Saving figures atomically (temp file, then rename)."""

from __future__ import annotations

import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def save(fig, path: str, dpi: int = 110) -> str:
    """Write ``fig`` to ``path`` (PNG) without leaving a partial file; closes it."""
    tmp = f"{path}.part.png"
    fig.savefig(tmp, dpi=dpi, bbox_inches=None if fig.get_layout_engine() else "tight")
    plt.close(fig)
    os.replace(tmp, path)
    return path
