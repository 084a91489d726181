"""The one exception a user can cause: bad input, reported in one line."""

import math


class InputError(Exception):
    """Bad user input; the message names the file, row, column or parameter.

    The CLI prints ``fvd-bridge: <message>`` and exits with code 2.
    """


class PluginNeeded(InputError):
    """A calibration file's model needs a plugin effect the caller did not
    give (or gave in another version): files name their plugins, never run them."""


class FitWarning(UserWarning):
    """A fit ended but deserves a look: a parameter on its bound, runs that
    disagree, a parameter that is not identified."""


def positive(what: str, value) -> float:
    """``value`` as a finite float > 0, else an InputError naming ``what``."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{what} '{value}' is not a number") from None
    if not (math.isfinite(x) and x > 0.0):
        raise InputError(f"{what} = {value} must be a finite number > 0")
    return x
