"""The package's messages in the words of the Python API.

Checks and warnings are written once, in the command line's words
("widen it, e.g. --bound 9:alpha=0,2"); a message raised through the Python
API (``fvd_bridge.api``) names the API's arguments instead
("bounds={'alpha': (0, 2)}").  ``in_api_words`` rewrites one message;
``api_errors`` rewrites the InputErrors and warnings raised inside a call.
"""

from __future__ import annotations

import contextlib
import re
import warnings

from .errors import InputError

_NUMBER = r"[-+]?[\d.]+(?:e[-+]?\d+)?"
_QUANTITY = {"t": "time", "d": "length", "F": "force", "v": "velocity"}

#: (pattern, replacement) applied in order
REWRITES = (
    (re.compile(rf"--bound (?:[\w+.]+:)?([\w.@]+)=({_NUMBER}),({_NUMBER})"), r"bounds={'\1': (\2, \3)}"),
    (re.compile(r"--bound ([\w.@]+)(?=[:\s])"), r"bounds={'\1': ...}"),
    (re.compile(r"\(--bound\)"), "(bounds=)"),
    (re.compile(r"--bounds (auto|paper)"), r"bounds='\1'"),
    (re.compile(r"--optimizer '?([\w+]+)'?"), r"optimizer='\1'"),
    (re.compile(r"\(--runs\)"), "(runs=)"),
    (re.compile(r"--per-test ([\w.]+)"), r"per_test=['\1']"),
    (re.compile(r"\(--max-rungs\)"), "(max_rungs=)"),
    (re.compile(r"--units ([tdFv])=(\w+)"), lambda m: f"units with the {_QUANTITY[m[1]]} in '{m[2]}'"),
    (re.compile(r"--units (\w)=UNIT or the sidecar"), "units="),
    (re.compile(rf"with --window ({_NUMBER}),({_NUMBER})"), r"keeping only t from \1 to \2 s"),
)


def in_api_words(message: str) -> str:
    """``message`` with its command-line options named as the API's arguments."""
    for pattern, replacement in REWRITES:
        message = pattern.sub(replacement, message)
    return message


@contextlib.contextmanager
def api_errors():
    """Within: an InputError or a warning of the package speaks the API's words."""
    caught: list = []
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            yield
    except InputError as exc:
        raise InputError(in_api_words(str(exc))) from None
    finally:
        for w in caught:  # issued again outside the recording block, each once
            ours = getattr(w.category, "__module__", "").startswith("fvd_bridge")
            warnings.warn_explicit(in_api_words(str(w.message)) if ours else w.message, w.category,
                                   w.filename, w.lineno)
