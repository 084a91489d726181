"""Frame figures: drift profiles with the series band, damper hysteresis in
the frame, roof drift and damper force histories."""

from __future__ import annotations

import numpy as np

from .save import axes, finish


def _specs(cases):
    return list(dict.fromkeys(c.spec for c in cases if c.spec is not None and c.result is not None))


#: line styles of a damper's upper and lower bound (frame --property-bounds)
BOUND_STYLES = {"upper": ":", "lower": "-."}


def drift_profiles(cases, title: str, path: str | None = None, ax=None):
    """Peak interstory drift ratio per story: the bare frame, per model the
    mean over the series' devices with its min-max band, and (frame
    --property-bounds) the mean of its upper- and lower-bound dampers."""
    fig, ax = axes(ax, 1, 2, figsize=(11, 5), layout="constrained")
    bare = next(c for c in cases if c.spec is None)
    stories = np.arange(1, bare.result.peak_drift_ratio.size + 1)
    for a, attr, label in ((ax[0], "peak_drift_ratio", "peak interstory drift ratio [%]"),
                           (ax[1], "peak_floor_acceleration_g", "peak floor acceleration [g]")):
        a.plot(100 * getattr(bare.result, attr) if attr == "peak_drift_ratio" else getattr(bare.result, attr),
               stories, "k--o", label="bare frame")
        for k, spec in enumerate(_specs(cases)):
            color = f"C{k % 10}"
            for bound in (None, "nominal", "upper", "lower"):
                rows = np.array([getattr(c.result, attr) for c in cases if c.spec == spec and c.result is not None
                                 and getattr(c, "bound", None) == bound])
                if not rows.size:
                    continue
                rows = 100 * rows if attr == "peak_drift_ratio" else rows
                devices = f"{len(rows)} device{'s' if len(rows) > 1 else ''}"
                if bound in BOUND_STYLES:
                    a.plot(rows.mean(axis=0), stories, BOUND_STYLES[bound], marker=".", color=color,
                           label=f"law {spec}, {bound} bound ({devices})")
                    continue
                a.plot(rows.mean(axis=0), stories, "-o", color=color,
                       label=f"law {spec}{', nominal' if bound else ''} ({devices})")
                if len(rows) > 1:
                    a.fill_betweenx(stories, rows.min(axis=0), rows.max(axis=0), color=color, alpha=0.2)
        a.set_xlabel(label)
        a.set_ylabel("story (floor level for accelerations)")
        a.set_yticks(stories)
        a.grid(alpha=0.3)
    ax[0].legend(fontsize=8)
    fig.suptitle(title)
    return finish(fig, path, ax)


def hysteresis(cases, story: int, title: str, path: str | None = None, ax=None):
    """Damper force against deformation in ``story`` (0 = first), first device of each model."""
    fig, ax = axes(ax, figsize=(6.5, 5), layout="constrained")
    for k, spec in enumerate(_specs(cases)):
        c = next(c for c in cases if c.spec == spec and c.result is not None)
        ax.plot(c.result.damper_deformation[:, story], c.result.damper_force[:, story], lw=0.7,
                color=f"C{k % 10}", label=f"law {spec} ({c.device})")
    ax.set_xlabel("damper deformation [mm]")
    ax.set_ylabel("damper force [kN]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title)
    return finish(fig, path, ax)


def histories(cases, title: str, path: str | None = None, ax=None):
    """Roof displacement and first-story damper force against time."""
    fig, ax = axes(ax, 2, 1, figsize=(11, 6), sharex=True, layout="constrained")
    bare = next(c for c in cases if c.spec is None)
    ax[0].plot(bare.result.t, bare.result.floor_displacement[:, -1], "k", lw=0.7, label="bare frame")
    for k, spec in enumerate(_specs(cases)):
        c = next(c for c in cases if c.spec == spec and c.result is not None)
        ax[0].plot(c.result.t, c.result.floor_displacement[:, -1], lw=0.7, color=f"C{k % 10}",
                   label=f"law {spec}")
        ax[1].plot(c.result.t, c.result.damper_force[:, 0], lw=0.7, color=f"C{k % 10}")
    ax[0].set_ylabel("roof displacement [mm]")
    ax[1].set_ylabel("story-1 damper force [kN]")
    ax[1].set_xlabel("time [s]")
    for a in ax:
        a.grid(alpha=0.3)
    ax[0].legend(fontsize=8, ncol=3)
    fig.suptitle(title)
    return finish(fig, path, ax)
