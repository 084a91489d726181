"""Figure of `compare`: calibrated models overlaid on a record (or on a motion)."""

from __future__ import annotations


from .save import axes, finish


def compare_figure(record, models, measured: bool, path: str | None = None, ax=None,
                   measured_label: str = "measured"):
    """F-d loops, F-t and the residuals of each (label, F) in ``models``
    (best first), over the measured force when ``measured`` (labelled
    ``measured_label``)."""
    fig, ax = axes(ax, 1, 3, figsize=(15, 4.5), layout="constrained")
    if measured:
        ax[0].plot(record.d, record.F, ".", ms=1.2, color="0.5", label=measured_label)
        ax[1].plot(record.t, record.F, ".", ms=1.2, color="0.5", label="measured")
    for k, (label, F) in enumerate(models):
        color = f"C{k % 10}"
        ax[0].plot(record.d, F, lw=0.8, color=color, label=label)
        ax[1].plot(record.t, F, lw=0.8, color=color)
        if measured:
            ax[2].plot(record.t, record.F - F, lw=0.6, color=color)
    ax[0].set_xlabel("displacement d [mm]")
    ax[1].set_xlabel("time t [s]")
    for a in ax[:2]:
        a.set_ylabel("force F [kN]")
    ax[2].set_xlabel("time t [s]")
    ax[2].set_ylabel("measured - model [kN]" if measured else "(no measured force)")
    for a in ax:
        a.grid(alpha=0.3)
    ax[0].legend(fontsize=7)
    fig.suptitle(f"calibrated models on {record.name}" + ("" if measured else " (prediction)"))
    return finish(fig, path, ax)
