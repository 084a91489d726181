"""Figure of an exporter check: the exported model's force against fvd_bridge's."""

from __future__ import annotations


from .save import axes, finish


def check_figure(record, F_model, F_exported, title: str, path: str | None = None, label: str = "OpenSees",
                 ax=None):
    """F-t, F-d and the difference, model (fvd_bridge) against the exported one."""
    fig, ax = axes(ax, 1, 3, figsize=(14, 4), layout="constrained")
    ax[0].plot(record.t, F_model, "-", lw=1.2, color="tab:blue", label="fvd_bridge model")
    ax[0].plot(record.t, F_exported, "--", lw=0.9, color="tab:red", label=label)
    ax[0].set_xlabel("time t [s]")
    ax[1].plot(record.d, F_model, "-", lw=1.2, color="tab:blue")
    ax[1].plot(record.d, F_exported, "--", lw=0.9, color="tab:red")
    ax[1].set_xlabel("displacement d [mm]")
    ax[2].plot(record.t, F_exported - F_model, lw=0.8, color="k")
    ax[2].set_xlabel("time t [s]")
    ax[2].set_ylabel(f"{label} - model [kN]")
    for a in ax[:2]:
        a.set_ylabel("force F [kN]")
    for a in ax:
        a.grid(alpha=0.3)
    ax[0].legend()
    fig.suptitle(title)
    return finish(fig, path, ax)
