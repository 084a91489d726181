"""The one exception a user can cause: bad input, reported in one line,
in the words of whoever called: a command-line option on the command
line, the Python argument that means the same in Python (``option``)."""

import contextlib
import contextvars
import math

#: "api" (the default: the package is called from Python) or "cli" (``fvd_bridge.cli`` sets it)
_WORDS = contextvars.ContextVar("fvd_bridge_words", default="api")

#: each command-line option and the Python argument that means the same ({v}: its value)
API_ARGUMENT = {
    "--plugin": "plugins=[{v!r}]",
    "--bounds": "bounds={v!r}",
    "--optimizer": "optimizer={v!r}",
    "--per-test": "per_test=[{v!r}]",
    "--test": "test={v!r}",
    "--runs": "runs={v}",
    "--dt": "dt={v}",
    "--sg-window": "sg_window={v}",
    "--sg-order": "sg_order={v}",
    "--force-sign": "force_sign={v!r}",
    "--devices": "devices={v!r}",
    "--protocol": "protocol={v!r}",
    "--laws": "laws={v!r}",
    "--plot": "path={v!r}",
}


def option(flag: str, value=None) -> str:
    """``flag`` with ``value`` as its reader gave it: '--plugin x.py' on the
    command line, "plugins=['x.py']" from Python (``API_ARGUMENT``)."""
    template = API_ARGUMENT.get(flag) if _WORDS.get() == "api" else None
    if template is None:
        return flag if value is None else f"{flag} {value}"
    return template.format(v=value)


def words() -> str:
    """Whose words messages speak here: "api" or "cli"."""
    return _WORDS.get()


def speak(who: str) -> None:
    """Messages speak ``who``'s words from now on (a worker process takes its campaign's)."""
    _WORDS.set(who)


@contextlib.contextmanager
def command_line_words():
    """Within: messages name command-line options (``fvd_bridge.cli``)."""
    token = _WORDS.set("cli")
    try:
        yield
    finally:
        _WORDS.reset(token)


class InputError(ValueError):
    """Bad user input; the message names the file, row, column or parameter
    (in the caller's words, ``option``).  A ValueError, which Python callers
    catch; the CLI prints ``fvd-bridge: <message>`` and exits with code 2.
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
