"""Quick-look figure of a record: F-t, d-t, F-d loop, F-v loop (kN, mm, s)."""

from __future__ import annotations

import os
import tempfile

from ..errors import InputError
from ..records.record import Record


def plot_record(rec: Record, path: str, title: str | None = None) -> str:
    """Draw the 2x2 quick-look of ``rec`` and write it to ``path`` atomically.

    The image format follows the file extension (png, pdf, svg, ...); the
    figure goes to a temporary file in the same folder, then is renamed.
    Returns ``path``.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    folder = os.path.dirname(os.path.abspath(path))
    fmt = os.path.splitext(path)[1].lstrip(".").lower() or "png"
    fig = Figure(figsize=(10, 7), layout="constrained")
    canvas = FigureCanvasAgg(fig)
    if fmt not in canvas.get_supported_filetypes():
        raise InputError(f"--plot {path}: unknown image format '.{fmt}' "
                         f"(known: {', '.join(sorted(canvas.get_supported_filetypes()))})")
    if not os.path.isdir(folder):
        raise InputError(f"--plot {path}: folder {folder} does not exist")
    ax = fig.subplots(2, 2)
    style = {"lw": 0.8}
    ax[0, 0].plot(rec.t, rec.F, **style)
    ax[0, 0].set(xlabel="t [s]", ylabel="F [kN]", title="force")
    ax[0, 1].plot(rec.t, rec.d, color="C1", **style)
    ax[0, 1].set(xlabel="t [s]", ylabel="d [mm]", title="displacement")
    ax[1, 0].plot(rec.d, rec.F, color="C2", **style)
    ax[1, 0].set(xlabel="d [mm]", ylabel="F [kN]", title="force-displacement loop")
    ax[1, 1].plot(rec.v, rec.F, color="C3", **style)
    method = rec.provenance.get("velocity", {}).get("method", "")
    ax[1, 1].set(xlabel=f"v [mm/s]{' (' + method + ')' if method else ''}", ylabel="F [kN]",
                 title="force-velocity loop")
    for a in ax.flat:
        a.grid(alpha=0.3)
    fig.suptitle(title or rec.name)
    fd, tmp = tempfile.mkstemp(prefix=".plot-", suffix=f".{fmt}", dir=folder)
    try:
        with os.fdopen(fd, "wb") as fh:
            fig.savefig(fh, format=fmt, dpi=120)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return path
