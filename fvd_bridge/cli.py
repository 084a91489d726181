"""The ``fvd-bridge`` command: one verb per job.

Each verb lives in ``fvd_bridge/commands/<verb>.py`` with ``add_parser(sub)``
that registers its options and sets ``func(args) -> int``.  Bad input
(InputError) prints one line and exits with code 2, never a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import os
import signal
import sys
import time
import warnings

# figures are written to files, never shown: matplotlib's file backend unless the user chose one
os.environ.setdefault("MPLBACKEND", "Agg")

from . import kernel_cache, timing  # noqa: E402
from ._version import __version__  # noqa: E402
from .errors import InputError, command_line_words  # noqa: E402

VERBS = ("laws", "inspect", "rig", "calibrate", "campaign", "effects", "diagnose", "compare", "export", "frame",
         "report", "demo")


#: the verbs that run the compiled kernels (their first run compiles them)
COMPILING = ("rig", "calibrate", "campaign", "diagnose", "compare", "export", "frame", "report", "demo")


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """All verbs, or only ``only`` (imports stay light: a verb pulls in what it needs)."""
    parser = argparse.ArgumentParser(prog="fvd-bridge", description="Calibrate fluid-viscous damper laws on test records, explain their misfit, export them (kN, mm, s).")
    parser.add_argument("--version", action="version", version=f"fvd_bridge {__version__}")
    sub = parser.add_subparsers(dest="verb", metavar="VERB")
    for verb in ([only] if only else VERBS):
        try:
            module = importlib.import_module(f"fvd_bridge.commands.{verb}")
        except ModuleNotFoundError as exc:
            if exc.name == f"fvd_bridge.commands.{verb}":
                continue  # verb not built yet
            raise
        module.add_parser(sub)
    return parser


def _show_warning(message, category, filename, lineno, file=None, line=None):
    print(f"warning: {message}", file=sys.stderr)


def verb_first(argv: list) -> tuple[str | None, list]:
    """The verb and argv with the verb first, so that options given before it
    (`fvd-bridge --runs 2 calibrate ...`) belong to the verb."""
    at = next((k for k, a in enumerate(argv) if a in VERBS), None)
    if at is None:
        return None, argv
    return argv[at], [argv[at]] + argv[:at] + argv[at + 1:]


def main(argv=None) -> int:
    """Run one verb; its messages name command-line options."""
    with command_line_words():
        return _main(argv)


def _main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    verb, argv = verb_first(argv)
    if verb is None:
        first = next((a for a in argv if not a.startswith("-")), None)
        if first is not None:
            print(f"fvd-bridge: unknown verb '{first}' (verbs: {', '.join(VERBS)}; see fvd-bridge --help)",
                  file=sys.stderr)
            return 2
    parser = build_parser(verb)
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    warnings.showwarning = _show_warning
    if verb in COMPILING:
        kernel_cache.announce(lambda text: print(f"fvd-bridge: {text}", file=sys.stderr, flush=True))
    previous = _on_sigterm()
    timing.reset()
    t0 = time.perf_counter()
    try:
        rc = int(args.func(args) or 0)
        if getattr(args, "profile", False):
            print(timing.report(time.perf_counter() - t0), file=sys.stderr)
        return rc
    except InputError as exc:
        print(f"fvd-bridge: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # output piped into e.g. `head`
        sys.stderr.close()
        return 0
    except Terminated:
        print("fvd-bridge: terminated (SIGTERM): workers stopped, no partial output left (a campaign keeps its "
              "finished units for the next start)", file=sys.stderr)
        return 143
    except KeyboardInterrupt:
        print("fvd-bridge: interrupted", file=sys.stderr)
        return 130
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


class Terminated(KeyboardInterrupt):
    """SIGTERM (a batch system's time limit, a kill): raised in the main
    thread so that every worker pool stops and every staged output is
    removed on the way out, as on Ctrl-C."""


def _raise_terminated(signum, frame):
    raise Terminated()


def _on_sigterm():
    """Turn SIGTERM into ``Terminated`` while a verb runs; the previous
    handler (None off the main thread, where signals cannot be set)."""
    try:
        return signal.signal(signal.SIGTERM, _raise_terminated)
    except ValueError:
        return None


def entry() -> None:
    """The console command: main(), then, where OpenSees was loaded, an exit
    that skips its C++ teardown, which prints 'Process 0 Terminating' on
    stderr after the verb's own output (every output is written by then)."""
    rc = main()
    if "openseespy.opensees" in sys.modules:
        logging.shutdown()
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(rc)
    sys.exit(rc)


if __name__ == "__main__":
    entry()
