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
    "--target": "target={v!r}",
    "--runs": "runs={v}",
    "--pop": "pop={v}",
    "--gens": "gens={v}",
    "--stall": "stall={v}",
    "--dt": "dt={v}",
    "--sg-window": "sg_window={v}",
    "--sg-order": "sg_order={v}",
    "--force-sign": "force_sign={v!r}",
    "--devices": "devices={v!r}",
    "--protocol": "protocol={v!r}",
    "--laws": "laws={v!r}",
    "--columns": "columns={v!r}",
    "--units": "units={v!r}",
    "--plot": "path={v!r}",
    "--bound": "bounds={{{name!r}: ({lo}, {hi})}}",
    "--fix": "fixed={{{name!r}: {v}}}",
    "--start-value": "start={{{name!r}: {v}}}",
    "--all-runs": "all_runs=True",
    "--max-rungs": "max_rungs={v}",
    "--mat-var": "mat_var={v!r}",
    "--window": "fvd_bridge.records.readers.cut(record, {t0}, {t1})",
    "--test-weights": "weights=[{v}]",
    "--gap-figure": "path={v!r}",
    "--intervals": "intervals={v}",
    "--amplitude": "amplitude={v}",
    "--frequency": "frequency={v}",
    "--name": "name={v!r}",
    "--spring-deflection": "deflection={v}",
}

#: each verb and the Python call that does its job (``command``)
API_CALL = {
    "laws": "fvd_bridge.laws.LAWS",
    "effects": "fvd_bridge.catalog.catalog().effects",
    "calibrate": "fvd_bridge.calibrate()",
    "diagnose": "fvd_bridge.diagnose()",
    "export opensees": "Calibration.to_opensees()",
    "export fmu": "Calibration.to_fmu()",
}


def option(flag: str, value=None, **fields) -> str:
    """``flag`` with ``value`` as its reader gave it: '--plugin x.py' on the
    command line, "plugins=['x.py']" from Python (``API_ARGUMENT``; ``fields``:
    the template's other parts, e.g. a bound's name, lo and hi).  Without a
    value, the option alone: '--runs' / 'runs='."""
    template = API_ARGUMENT.get(flag) if _WORDS.get() == "api" else None
    if template is None:
        return flag if value is None else f"{flag} {value}"
    if value is None and not fields and "{" in template:
        return template.split("=", 1)[0] + "="
    return template.format(v=value, **fields)


def repeated(flag: str, values) -> str:
    """'--per-test a --per-test b' on the command line, "per_test=['a', 'b']"
    from Python (a list argument of ``API_ARGUMENT``)."""
    template = API_ARGUMENT.get(flag) if _WORDS.get() == "api" else None
    if template is None:
        return " ".join(option(flag, v) for v in values)
    return f"{template.split('=', 1)[0]}={list(values)!r}"


def bound_option(name: str, lo: float, hi: float, spec: str | None = None) -> str:
    """'--bound 9:alpha=0,2' on the command line, "bounds={'alpha': (0, 2)}" from Python."""
    lo, hi = f"{lo:.4g}", f"{hi:.4g}"
    return option("--bound", f"{spec + ':' if spec else ''}{name}={lo},{hi}", name=name, lo=lo, hi=hi)


def parameter_option(flag: str, name: str, value=None) -> str:
    """One parameter's option as given: '--fix C=40' on the command line,
    "fixed={'C': 40}" from Python; a --bound's value is (lower, upper),
    a --per-test has none."""
    if flag == "--bound":
        return bound_option(name, *value)
    if value is None:
        return option(flag, name)
    template = API_ARGUMENT.get(flag) if _WORDS.get() == "api" else None
    return template.format(v=value, name=name) if template else f"{flag} {name}={value}"


def command(verb: str) -> str:
    """'fvd-bridge export fmu' on the command line, 'Calibration.to_fmu()'
    from Python (``API_CALL``)."""
    call = API_CALL.get(verb) if _WORDS.get() == "api" else None
    return call or f"fvd-bridge {verb}"


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
