"""Campaign figures: loops (paper Fig. 3, App. B), OF bars (Fig. 4),
parameter dispersion (Figs. 5-13), Pareto front (Fig. 14); for a production
series: histograms of the calibrated quantities with their outlier fences,
and the acceptance chart (force at the design velocity against the band)."""

from __future__ import annotations

import numpy as np

from .record import loop
from .save import axes, finish


#: the loop figure's fixed margins: a constrained layout took half its drawing time
LOOPS_MARGINS = {"left": 0.055, "right": 0.99, "bottom": 0.13, "top": 0.88, "wspace": 0.22}


def loops(record, F_model: np.ndarray, title: str, path: str | None = None, ax=None):
    """Measured vs model: F-d and F-v loops and F-t history (three panels;
    ``ax``: three Axes or a Figure, ``save.axes``)."""
    fig, ax = axes(ax, 1, 3, figsize=(14, 4), gridspec_kw=LOOPS_MARGINS)
    for a, x in zip(ax, "dvt"):
        loop(record, F_model, ax=a, x=x)
    fig.suptitle(title)
    return finish(fig, path, ax, tight=False)


def of_bars(specs, devices, mean: np.ndarray, sigma: np.ndarray, path: str | None = None, ax=None):
    """OF mean (a) and sigma on a log scale (b) per model and device; arrays (n_spec, n_dev)."""
    fig, ax = axes(ax, 2, 1, figsize=(max(8, 1.1 * len(specs)), 7), sharex=True)
    width = 0.8 / max(len(devices), 1)
    x = np.arange(len(specs))
    for k, dev in enumerate(devices):
        ax[0].bar(x + k * width, mean[:, k], width, label=dev)
        ax[1].bar(x + k * width, np.maximum(sigma[:, k], 1e-16), width, label=dev)
    ax[0].set_ylabel("OF mean (a)")
    ax[1].set_ylabel("OF sigma over runs (b)")
    ax[1].set_yscale("log")
    ax[1].set_xticks(x + 0.4 - width / 2, [f"law {s}" for s in specs], rotation=30)
    ax[0].legend(fontsize=8, ncol=min(len(devices), 5))
    for a in ax:
        a.grid(axis="y", alpha=0.3)
    return finish(fig, path, ax)


def dispersion(spec: str, names, devices, means: np.ndarray, sigmas: np.ndarray, path: str | None = None,
               ax=None):
    """Per parameter: each device's mean as % variation from the mean over devices,
    with its run-to-run sigma as an error bar (normalised by the same mean)."""
    n = len(names)
    fig, ax = axes(ax, 1, n, figsize=(3.2 * n + 1, 3.4), squeeze=False)
    for j, name in enumerate(names):
        ref = means[:, j].mean()
        a = ax[0, j]
        if ref != 0:
            a.errorbar(np.arange(len(devices)), 100 * (means[:, j] / ref - 1), yerr=100 * sigmas[:, j] / abs(ref),
                       fmt="o", capsize=4)
        a.axhline(0.0, ls=":", color="tab:red")
        a.set_xticks(range(len(devices)), devices, rotation=45, fontsize=7)
        a.set_title(f"{name} (mean {ref:.4g})", fontsize=9)
        if j == 0:
            a.set_ylabel("variation from mean [%]")
        a.grid(alpha=0.3)
    fig.suptitle(f"law {spec}: identified parameters across devices")
    fig.tight_layout()
    return finish(fig, path, ax)


def pareto(specs, of_mean, beta, front, path: str | None = None, ax=None):
    """Mean OF against robustness index beta; the non-dominated models joined."""
    fig, ax = axes(ax, figsize=(6.5, 5))
    of_mean, beta, front = map(np.asarray, (of_mean, beta, front))
    ax.scatter(beta[~front], of_mean[~front], color="grey", label="dominated")
    ax.scatter(beta[front], of_mean[front], color="tab:red", label="non-dominated")
    order = np.argsort(beta[front])
    ax.plot(beta[front][order], of_mean[front][order], "--", color="tab:red", lw=0.8)
    for s, b, f in zip(specs, beta, of_mean):
        ax.annotate(f"law {s}", (b, f), textcoords="offset points", xytext=(4, 4), fontsize=8)
    ax.set_xlabel("robustness index beta [-] (lower = more robust)")
    ax.set_ylabel("mean OF [-] (lower = more accurate)")
    ax.grid(alpha=0.3)
    ax.legend()
    return finish(fig, path, ax)


def histograms(spec: str, names, units, values: np.ndarray, columns, k: float, path: str | None = None,
               ax=None):
    """One histogram per quantity over the series' devices (values (n_dev, n_q)),
    the median (solid) and the outlier fences median -+ k 1.4826 MAD (dashed);
    outlying devices drawn as red ticks under the axis."""
    n = len(names)
    ncol = min(n, 4)
    nrow = -(-n // ncol)
    fig, ax = axes(ax, nrow, ncol, figsize=(3.6 * ncol, 3.0 * nrow), squeeze=False)
    for j, (name, unit, c) in enumerate(zip(names, units, columns)):
        a = ax[j // ncol, j % ncol]
        x = values[:, j]
        x = x[np.isfinite(x)]
        if x.size:
            a.hist(x, bins=max(5, min(40, int(np.sqrt(x.size)) + 3)), color="tab:blue", alpha=0.75)
            a.axvline(c["median"], color="k", lw=1)
            if c["judged"] and c["robust_sigma"] > 0:
                for s in (-1, 1):
                    a.axvline(c["median"] + s * k * c["robust_sigma"], color="tab:red", ls="--", lw=0.8)
            out = values[c["flags"], j]
            out = out[np.isfinite(out)]
            if out.size:
                a.plot(out, np.zeros_like(out), "|", color="tab:red", ms=14, mew=2, clip_on=False)
        a.set_title(f"{name} [{unit}] ({int(c['flags'].sum())} outliers)", fontsize=9)
        a.grid(alpha=0.3)
        if j % ncol == 0:
            a.set_ylabel("devices")
    for j in range(n, nrow * ncol):
        ax[j // ncol, j % ncol].axis("off")
    fig.suptitle(f"law {spec}: calibrated quantities over {values.shape[0]} devices "
                 f"(median, fences at {k:g} x 1.4826 MAD)")
    fig.tight_layout()
    return finish(fig, path, ax)


def acceptance(accept: dict, path: str | None = None, ax=None):
    """Per model: each device's force at the design velocity (tension, compression)
    against the nominal force and its tolerance band; failures in red."""
    models = accept["models"]
    F0, tol = accept["nominal_force"], accept["settings"]["tolerance"]
    fig, ax = axes(ax, len(models), 1, figsize=(9, 2.8 * len(models) + 0.6), squeeze=False, sharex=True)
    for a, (spec, m) in zip(ax[:, 0], models.items()):
        idx = np.arange(len(m["passed"]))
        a.axhspan(F0 * (1 - tol), F0 * (1 + tol), color="tab:green", alpha=0.12, label=f"nominal +-{tol:.0%}")
        a.axhline(F0, color="tab:green", lw=0.8)
        for col, marker, color, lab in ((0, "^", "tab:blue", "tension"), (1, "v", "tab:orange", "compression")):
            ok = m["passed"]
            a.scatter(idx[ok], m["F"][ok, col], marker=marker, s=14, color=color, label=f"{lab}, pass")
            if not ok.all():
                a.scatter(idx[~ok], m["F"][~ok, col], marker=marker, s=22, color="tab:red", label=f"{lab}, fail")
        a.set_ylabel("force [kN]")
        a.set_title(f"law {spec}: {int(m['passed'].sum())}/{len(idx)} pass", fontsize=9)
        a.grid(alpha=0.3)
    ax[0, 0].legend(fontsize=7, ncol=3, loc="lower right")
    ax[-1, 0].set_xlabel("device (series order)")
    fig.suptitle(f"force at the design velocity {accept['settings']['velocity']:g} mm/s")
    fig.tight_layout()
    return finish(fig, path, ax)
