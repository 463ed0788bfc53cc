"""The ``spinectl`` command line.

Each sub-command lives in its own module with a ``register(subparsers)``
function; :data:`COMMANDS` lists them. Building the parser imports every
command module, so their tops import nothing heavy: a command imports its
library in its ``run``, and options whose defaults come from a heavy module
are added when that command is used (:meth:`_Parser.defer`), so that
``spinectl --help`` imports no heavy stack (xarray, matplotlib, cvxpy, Dask). Errors a user can cause
(:class:`~spinectl.errors.SpinectlError`, bad arguments) end as one line on
stderr and exit code 2, without a traceback.
"""

from __future__ import annotations

import argparse
import contextlib
import difflib
import importlib
import logging
import os
import re
import shlex
import sys
import warnings

from .._threads import one_blas_thread
from .._validate import printable
from ..errors import SpinectlError

COMMANDS = (
    "config_cmd",
    "stability_cmd",
    "margins_cmd",
    "design_cmd",
    "sweep_cmd",
    "plot_cmd",
    "draw_cmd",
    "explore_cmd",
    "reproduce_cmd",
    "study_cmd",
    "calibrate_cmd",
    "anatomy_cmd",
    "motion_cmd",
    "atlas_cmd",
    "export_cmd",
)
"""Modules of :mod:`spinectl.cli` that each register one sub-command."""

EXIT_USAGE = 2


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line and exit 2, that never calls ``sys.exit``, and that
    adds the options of :meth:`defer` when it is first used.

    A word that starts with a minus and a digit is a value, not an option: ``--E -0.02:0.1:25``
    (argparse 3.11 takes only plain negative numbers so, Python 3.13 any such word).
    """

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(r"^-\.?\d")
        self._deferred = []

    def defer(self, add_options) -> None:
        """Call ``add_options(self)`` before this parser first parses or prints its help.

        For a command whose options take their defaults from a module that is slow to
        import (xarray, matplotlib, cvxpy): only that command, when it runs, pays for it.

        Parameters
        ----------
        add_options : callable
            Adds the options to the parser it is given.
        """
        self._deferred.append(add_options)

    def complete(self) -> None:
        """Add the deferred options now (the docs' walk of the parser needs every option)."""
        while self._deferred:
            self._deferred.pop(0)(self)

    def parse_known_args(self, args=None, namespace=None):
        self.complete()
        return super().parse_known_args(args, namespace)

    def format_usage(self):
        self.complete()
        return super().format_usage()

    def format_help(self):
        self.complete()
        return super().format_help()

    def parse_args(self, args=None, namespace=None):
        """As argparse's, but an unknown option is reported by the command that was used, with a "did you mean"."""
        try:
            parsed, extras = self.parse_known_args(args, namespace)
        except _UsageError as exc:  # options before the command: say so instead of "invalid choice: '35'"
            raise _UsageError(self._misplaced(sys.argv[1:] if args is None else list(args)) or str(exc)) from None
        if extras:
            command = self._command(parsed) or self
            command.error(f"unrecognized arguments: {' '.join(extras)}{command.suggestion(extras)}")
        return parsed

    def _command(self, parsed):
        """The sub-command's parser that ``parsed`` went through, or None."""
        for action in self._actions:
            if isinstance(action, argparse._SubParsersAction):
                return action.choices.get(getattr(parsed, action.dest, None))
        return None

    def _misplaced(self, argv: list[str]) -> str:
        """``"options go after the command: spinectl stability --set ..."`` where options precede it, else ``""``.

        ``spinectl --set body.mass=35 stability`` read ``body.mass=35`` as the command ("invalid choice").

        Parameters
        ----------
        argv : list of str
            The arguments after ``spinectl``.

        Returns
        -------
        str
            The hint, with the command line reordered where a command is among ``argv``.
        """
        commands = next((a.choices for a in self._actions if isinstance(a, argparse._SubParsersAction)), {})
        first = next((k for k, word in enumerate(argv) if word in commands), None)
        before = argv[:first] if first is not None else argv
        if not any(word.startswith("-") and word not in ("-h", "--help", "--version") for word in before):
            return ""
        if first is None:
            return "options go after the command: spinectl COMMAND [OPTIONS] (spinectl --help lists the commands)"
        return f"options go after the command: {shlex.join(['spinectl', argv[first], *before, *argv[first + 1 :]])}"

    def suggestion(self, words) -> str:
        """``"; did you mean --delay?"`` for the first of ``words`` close to an option of this parser, else ``""``.

        Parameters
        ----------
        words : list of str
            The arguments argparse did not recognise (``--delya``, ``--delya=3``, values).

        Returns
        -------
        str
            The hint (the option that differs only in case, else difflib's closest option string), or an
            empty string.
        """
        options = [o for o in self._option_string_actions if o.startswith("--")]
        for word in words:
            if word.startswith("-") and not self._negative_number_matcher.match(word):
                given = word.split("=", 1)[0]
                same = [o for o in options if o.casefold() == given.casefold()]  # --e for --E before --set
                close = same or difflib.get_close_matches(given, options, n=1, cutoff=0.75)
                if close:
                    return f"; did you mean {close[0]}?"
        return ""

    def error(self, message):  # noqa: D401 - argparse API
        """One line, ``spinectl: error: <command>: <message>`` (printed by :func:`main`), with a "did you mean"."""
        match = re.search(r"invalid choice: '([^']*)' \(choose from (.*)\)$", message)
        if match:
            choices = re.findall(r"'([^']*)'", match.group(2))
            close = difflib.get_close_matches(match.group(1), choices, n=1, cutoff=0.6)
            message += f"; did you mean {close[0]}?" if close else ""
        command = self.prog.removeprefix("spinectl").strip()
        raise _UsageError(f"{command}: {message}" if command else message)

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


def build_parser(*, lazy: bool = False) -> argparse.ArgumentParser:
    """The full argument parser with every registered sub-command.

    Parameters
    ----------
    lazy : bool
        Leave the deferred options (:meth:`_Parser.defer`) until a command is used, as
        :func:`main` does; the default adds every option now (the docs walk the parser).

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
    if not lazy:
        for command in sub.choices.values():
            command.complete()
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
        0 on success, 2 for an error the user can fix (one line on stderr; also standard output that
        cannot be written, e.g. a full device), 130 on Ctrl-C; 0 when the reader of a pipe stops reading.
    """
    _printable_streams()
    # matplotlib logs two warnings when it cannot make its configuration folder (a HOME that is not
    # writable, as in many containers) and uses a temporary one: harmless, yet they broke "nothing on stderr"
    logging.getLogger("matplotlib").setLevel(logging.ERROR)
    stdout, sys.stdout = sys.stdout, _Stdout(sys.stdout)
    try:
        with one_blas_thread():  # many small matrices: one BLAS thread is faster (spinectl._threads)
            return _run(argv)
    except _StdoutError as exc:
        return _stdout_failed(exc.error, stdout)
    finally:
        sys.stdout = stdout


NOTES: list[str] = []
"""Notes for the user that :func:`main` prints on stderr after a command's answer (a failed run prints its
one-line error alone; :func:`spinectl.cli._common.note_after`); emptied at the start of every command."""


def _run(argv) -> int:
    """Parse, run the command, flush standard output: the exit code, or :class:`_StdoutError`."""
    NOTES.clear()
    try:
        with warnings.catch_warnings():
            warnings.showwarning = _one_line_warning
            args = build_parser(lazy=True).parse_args(argv)
            code = int(args.func(args) or 0)
    except _ParserExit as exc:
        code = exc.status
    except (_UsageError, SpinectlError) as exc:  # argparse's and the library's errors read alike
        print(f"spinectl: error: {printable(str(exc))}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt as exc:  # a study's or an atlas's says what is saved (landscape.study.interrupt)
        print(f"spinectl: {printable(str(exc)) or 'interrupted'}", file=sys.stderr)
        return 130
    sys.stdout.flush()  # a full device shows here, not in the interpreter's exit (a traceback, exit 120)
    for note in NOTES if code == 0 else ():  # after the answer: a failed run says its error alone
        print(f"spinectl: warning: {printable(note)}", file=sys.stderr)
    return code


class _StdoutError(Exception):
    """Writing standard output failed (a full device, a closed pipe): not an ``OSError``, which argparse swallows."""

    def __init__(self, error: OSError):
        super().__init__(error)
        self.error = error


class _Stdout:
    """``sys.stdout`` whose failed writes raise :class:`_StdoutError`, told apart from a file's ``OSError``."""

    def __init__(self, stream):
        self._stream = stream

    def write(self, text):
        try:
            return self._stream.write(text)
        except OSError as exc:
            raise _StdoutError(exc) from None

    def flush(self):
        try:
            return self._stream.flush()
        except OSError as exc:
            raise _StdoutError(exc) from None

    def __getattr__(self, name):
        return getattr(self._stream, name)


def _stdout_failed(error: OSError, stream) -> int:
    """One line and exit 2 for standard output that cannot be written; a closed pipe (``| head``) ends quietly, 0.

    What could not be written is dropped (standard output pointed at the null device), so that
    the interpreter's own flush at exit has nothing left to fail on.
    """
    with contextlib.suppress(OSError, ValueError, AttributeError):  # a replaced stream has no descriptor
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, stream.fileno())
        os.close(null)
    if isinstance(error, BrokenPipeError):  # the reader stopped reading: it had what it wanted
        return 0
    print(f"spinectl: error: cannot write to standard output: {error.strerror or error}", file=sys.stderr)
    return EXIT_USAGE


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
