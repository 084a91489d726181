"""Quick-look figure of a record: F-t, d-t, F-d loop, F-v loop (kN, mm, s)."""

from __future__ import annotations

import os

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ..errors import InputError, option
from ..io.staging import check_output
from ..records.record import Record


def check_target(path: str) -> str:
    """Refuse an image path whose folder is missing or whose format matplotlib
    cannot write; returns the format (the extension, png when there is none)."""
    fmt = os.path.splitext(path)[1].lstrip(".").lower() or "png"
    known = FigureCanvasAgg(Figure()).get_supported_filetypes()
    if fmt not in known:
        raise InputError(f"{option('--plot', path)}: unknown image format '.{fmt}' (known: {', '.join(sorted(known))})")
    check_output(path, "file", "--plot")
    return fmt


#: the measured samples as dots, the model as a line
MEASURED = {"ls": "none", "marker": ".", "ms": 1.5, "color": "tab:blue", "label": "measured"}
MODEL = {"ls": "-", "lw": 0.8, "color": "tab:red", "label": "model"}
AXIS_LABELS = {"d": "displacement d [mm]", "v": "velocity v [mm/s]", "t": "time t [s]"}


def loop(rec: Record, F_model=None, ax=None, x: str = "d", title: str | None = None):
    """Measured force and, when given, the model's F_model [kN] against
    ``x`` ('d', 'v' or 't') of ``rec`` on ``ax`` (None: a new figure's);
    returns the Axes, left open."""
    if x not in AXIS_LABELS:
        raise InputError(f"x='{x}': expected one of {', '.join(AXIS_LABELS)}")
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(6, 4), layout="constrained")
    xs = getattr(rec, x)
    ax.plot(xs, rec.F, **MEASURED)
    if F_model is not None:
        ax.plot(xs, F_model, **MODEL)
    ax.set_xlabel(AXIS_LABELS[x])
    ax.set_ylabel("force F [kN]")
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left", fontsize=8)
    if title:
        ax.set_title(title)
    return ax


def plot_record(rec: Record, path: str | None = None, title: str | None = None, ax=None):
    """Draw the 2x2 quick-look of ``rec`` (F-t, d-t, F-d, F-v) on ``ax``
    (four Axes or a Figure; None: a new figure) and, given ``path``, write
    it there atomically (the format follows the extension: png, pdf, svg,
    ...; PATH.<pid>.part first, then renamed) and return ``path``; else
    return the Figure, left open."""
    fmt = check_target(path) if path else None
    if ax is None and path:  # the command line's quick look: no pyplot figure to keep
        fig = Figure(figsize=(10, 7), layout="constrained")
        FigureCanvasAgg(fig)
        ax = fig.subplots(2, 2)
    else:
        from .save import axes

        fig, ax = axes(ax, 2, 2, figsize=(10, 7), layout="constrained")
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
    if not path:
        return fig
    tmp = f"{path}.{os.getpid()}.part"
    try:
        fig.savefig(tmp, format=fmt, dpi=120)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return path
