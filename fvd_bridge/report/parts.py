"""The parts every page is built of: figures embedded as base64 PNG with
a caption saying what to look at, and the JSON files a verb wrote."""

from __future__ import annotations

import base64
import json
import os
import re
from html import escape


def image(path: str, caption: str) -> str:
    """A figure embedded as base64 PNG, with its caption: what to look at."""
    with open(path, "rb") as fh:
        data = base64.b64encode(fh.read()).decode("ascii")
    return (f"<figure><img alt='{escape(caption)}' src='data:image/png;base64,{data}'>"
            f"<figcaption>{escape(caption)} ({escape(os.path.basename(path))})</figcaption></figure>")


#: what to look at in each figure a folder may hold, by its file name's pattern
CAPTIONS = (
    (r"loops_(?P<what>.+)_law(?P<spec>.+)\.png",
     "law {spec} over the measured loops of {what}: force against displacement, against velocity and in "
     "time; look where the model's line leaves the measurement (at the reversals, at the peaks, late cycles)"),
    (r"of_bars\.png", "each model's OF per device (top) and its sigma over runs (bottom): a low, even bar is "
                      "a model that fits every device; a tall sigma, a fit that depends on its start"),
    (r"pareto\.png", "mean OF against the robustness index beta_r over the devices: the non-dominated models "
                     "are the choices (lower-left is better)"),
    (r"dispersion_law(?P<spec>.+)\.png", "law {spec}: each parameter's deviation from the series' mean per "
                                         "device: the production scatter of the identified properties"),
    (r"histogram_law(?P<spec>.+)\.png", "law {spec}: the calibrated quantities over the series, with the "
                                        "robust fences: a bar beyond a fence is an outlier device"),
    (r"acceptance\.png", "each device's force at the design velocity against the nominal band: a point outside "
                         "the band fails"),
    (r".*_where(_final)?\.png", "where the model fails: the residual in time, against displacement and velocity, "
                                "on the loops and per cycle, beside the noise band; the candidates' OF (red: "
                                "credited). Look for structure beyond the band"),
    (r".*_ladder\.png", "the ladder: the OF after each effect added, against the noise floor"),
    (r".*_compare\.png", "each calibrated model's force on the record it was not fitted to"),
)


def caption(path: str) -> str:
    """The caption of a figure by its file name (``CAPTIONS``); its name when none fits."""
    name = os.path.basename(path)
    for pattern, text in CAPTIONS:
        found = re.fullmatch(pattern, name)
        if found:
            return text.format(**found.groupdict())
    return name


def figure(path: str) -> str:
    """A figure of the folder, embedded with its caption (``CAPTIONS``)."""
    return image(path, caption(path))


def read_json(path: str) -> dict | None:
    """The JSON file at ``path``; None when it is not there."""
    if not os.path.isfile(path):
        return None
    with open(path) as fh:
        return json.load(fh)
