"""Saving figures atomically (temp file, then rename)."""

from __future__ import annotations

import os


def save(fig, path: str, dpi: int = 110) -> str:
    """Write ``fig`` to ``path`` (PNG) without leaving a partial file; closes it."""
    import matplotlib.pyplot as plt

    tmp = f"{path}.part.png"
    fig.savefig(tmp, dpi=dpi, bbox_inches="tight")
    plt.close(fig)
    os.replace(tmp, path)
    return path
