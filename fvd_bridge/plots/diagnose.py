"""Diagnose figures: where the model fails (residual against time,
displacement and velocity; the loop coloured by the residual; the error per
cycle; the candidate effects) and the OF falling along the ladder."""

from __future__ import annotations

import numpy as np

from .save import axes, finish


def where(record, diag, path: str | None = None, ax=None):
    """Six panels: r(t), r(d), r(v), F-d loop coloured by r, mean |r| per cycle,
    OF of each candidate against the base OF and the noise floor."""
    r = record.F - diag.F_model
    lim = float(np.max(np.abs(r))) or 1.0
    fig, ax = axes(ax, 2, 3, figsize=(16, 9), layout="constrained")
    a = ax[0, 0]
    a.plot(record.t, r, lw=0.6, color="tab:blue")
    noise = diag.noise_std
    a.axhspan(-2 * noise, 2 * noise, color="tab:green", alpha=0.15, label="+-2 x force noise")
    a.set_xlabel("time t [s]")
    a.set_ylabel("residual r = measured - model [kN]")
    a.legend(loc="upper right", fontsize=8)
    for a, x, lab in ((ax[0, 1], record.d, "displacement d [mm]"), (ax[0, 2], record.v, "velocity v [mm/s]")):
        a.scatter(x, r, s=2, c=record.t, cmap="viridis")
        a.axhline(0.0, color="k", lw=0.5)
        a.set_xlabel(lab)
        a.set_ylabel("residual r [kN] (colour: time)")
    a = ax[1, 0]
    a.plot(record.d, diag.F_model, color="0.6", lw=0.6, label="model")
    sc = a.scatter(record.d, record.F, s=3, c=r, cmap="coolwarm", vmin=-lim, vmax=lim)
    fig.colorbar(sc, ax=a, label="residual r [kN]")
    a.set_xlabel("displacement d [mm]")
    a.set_ylabel("force F [kN] (measured, coloured by r)")
    a.legend(loc="upper left", fontsize=8)
    a = ax[1, 1]
    cyc = diag.where.cycles
    if cyc:
        mid = [0.5 * (c.t_start + c.t_end) for c in cyc]
        width = [0.9 * (c.t_end - c.t_start) for c in cyc]
        a.bar(mid, [c.mean_abs for c in cyc], width=width, color="tab:orange")
    a.axhline(noise * np.sqrt(2 / np.pi), color="tab:green", ls="--", label="noise alone")
    a.set_xlabel("time t [s] (one bar per cycle)")
    a.set_ylabel("mean |r| per cycle [kN]")
    a.legend(fontsize=8)
    a = ax[1, 2]
    if diag.candidates:
        names = [c.effect for c in diag.candidates][::-1]
        ofs = [c.of for c in diag.candidates][::-1]
        colors = ["tab:red" if c.significant else "0.6" for c in diag.candidates][::-1]
        a.barh(names, ofs, color=colors)
        a.set_xscale("log")
    else:
        a.text(0.5, 0.5, "no candidates refitted", ha="center", va="center", transform=a.transAxes)
    a.axvline(diag.of, color="k", label=f"{diag.spec}: OF {diag.of:.3g}")
    a.axvline(diag.floor, color="tab:green", ls="--", label=f"noise floor {diag.floor:.3g}")
    a.set_xlabel("OF after adding the effect and refitting (red: helps beyond noise)")
    a.legend(fontsize=8, loc="lower right")
    for a in ax.ravel():
        a.grid(alpha=0.3)
    fig.suptitle(f"{record.name}: where model {diag.spec} fails (OF {diag.of:.4g}, "
                 f"noise floor {diag.floor:.4g})")
    return finish(fig, path, ax)


def ladder(lad, path: str | None = None, ax=None):
    """OF of each rung of the ladder (log scale) with the noise floor."""
    specs = [r.spec for r in lad.rungs]
    ofs = [r.of for r in lad.rungs]
    fig, ax = axes(ax, figsize=(max(6.0, 1.8 * len(specs) + 2), 4.5), layout="constrained")
    ax.plot(range(len(specs)), ofs, "o-", color="tab:blue")
    for k, (of, rung) in enumerate(zip(ofs, lad.rungs)):
        label = f"{of:.3g}" if rung.improvement is None else f"{of:.3g} (-{rung.improvement:.0%})"
        ax.annotate(label, (k, of), textcoords="offset points", xytext=(0, 8), ha="center", fontsize=8)
    ax.axhline(lad.final.floor, color="tab:green", ls="--", label=f"noise floor {lad.final.floor:.3g}")
    ax.set_yscale("log")
    ax.set_xticks(range(len(specs)), [s.replace("+", "\n+") for s in specs], fontsize=8)
    ax.set_ylabel("OF (eq. 18)")
    ax.set_title(f"the ladder: {lad.stop}", fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return finish(fig, path, ax)
