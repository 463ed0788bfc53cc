"""The ``spinectl`` command line.

Each sub-command lives in its own module with a ``register(subparsers)``
function; :data:`COMMANDS` lists them. Errors a user can cause
(:class:`~spinectl.errors.SpinectlError`, bad arguments) end as one line on
stderr and exit code 2, without a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import re
import sys
import warnings

from .._validate import printable
from ..errors import SpinectlError

COMMANDS = (
    "config_cmd",
    "stability_cmd",
    "margins_cmd",
    "sweep_cmd",
    "plot_cmd",
    "draw_cmd",
    "explore_cmd",
    "reproduce_cmd",
    "study_cmd",
    "calibrate_cmd",
)
"""Modules of :mod:`spinectl.cli` that each register one sub-command."""

EXIT_USAGE = 2


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line and exit 2, and that never calls ``sys.exit``.

    A word that starts with a minus and a digit is a value, not an option: ``--E -0.02:0.1:25``
    (argparse 3.11 takes only plain negative numbers so, Python 3.13 any such word).
    """

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(r"^-\.?\d")

    def error(self, message):  # noqa: D401 - argparse API
        raise _UsageError(f"{self.prog}: {message}")

    def exit(self, status=0, message=None):  # --help and --version end here
        if message:
            sys.stderr.write(message)
        raise _ParserExit(status)


class _UsageError(Exception):
    pass


class _ParserExit(Exception):
    def __init__(self, status: int):
        super().__init__(status)
        self.status = status


def build_parser() -> argparse.ArgumentParser:
    """The full argument parser with every registered sub-command.

    Returns
    -------
    argparse.ArgumentParser
        ``spinectl`` with the sub-commands of :data:`COMMANDS`; its errors raise instead of exiting.
    """
    from .. import __version__

    parser = _Parser(
        prog="spinectl",
        description="Control-theoretic analysis of spinal stability (Wagner et al. 2012).",
    )
    parser.add_argument("--version", action="version", version=f"spinectl {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for name in COMMANDS:
        importlib.import_module(f"{__name__}.{name}").register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the CLI; return the exit code (0 ok, 2 bad input, 1 other failure).

    Parameters
    ----------
    argv : list of str, optional
        The arguments after ``spinectl``; default ``sys.argv[1:]``.

    Returns
    -------
    int
        0 on success, 2 for an error the user can fix (one line on stderr), 130 on Ctrl-C.
    """
    _printable_streams()
    # matplotlib logs two warnings when it cannot make its configuration folder (a HOME that is not
    # writable, as in many containers) and uses a temporary one: harmless, yet they broke "nothing on stderr"
    logging.getLogger("matplotlib").setLevel(logging.ERROR)
    try:
        with warnings.catch_warnings():
            warnings.showwarning = _one_line_warning
            args = build_parser().parse_args(argv)
            return int(args.func(args) or 0)
    except _ParserExit as exc:
        return exc.status
    except _UsageError as exc:
        print(f"error: {printable(str(exc))}", file=sys.stderr)
        return EXIT_USAGE
    except SpinectlError as exc:
        print(f"spinectl: error: {printable(str(exc))}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print("spinectl: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        return 0


def _one_line_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """A warning as one line on stderr, ``spinectl: warning: ...``, without the source line."""
    print(f"spinectl: warning: {printable(str(message))}", file=sys.stderr)


def _printable_streams() -> None:
    """Let stdout and stderr print any path: characters their encoding lacks come out escaped.

    An output named ``Λ.nc`` on an ASCII terminal (``PYTHONIOENCODING=ascii``, the C locale)
    is written; printing its name must not then fail with a traceback.
    """
    for stream in (sys.stdout, sys.stderr):
        reconfigure = getattr(stream, "reconfigure", None)  # absent on replaced streams (pytest's capture)
        if reconfigure is not None:
            reconfigure(errors="backslashreplace")
