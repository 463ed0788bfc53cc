"""``spinectl explore``: the interactive explorer in the browser (needs the ``explore`` extra).

Panel is imported only when the command runs, so that every other command starts
without it, and a missing extra is one line saying how to install it.
"""

from __future__ import annotations

import argparse

from ..explore.hosts import MAX_SESSIONS, SESSIONS_RANGE, UNUSED_SESSION_S
from ..model.config import DEFAULT_PRESET
from ._common import add_model_options, load_model

PORT = 5006
"""Default TCP port (Bokeh's and Panel's)."""
ADDRESS = "127.0.0.1"
"""Default interface: the loopback one, reachable from this machine only."""


def _integer(option: str, low: int, high: int):
    """An argparse ``type``: an integer from ``low`` to ``high``, or one line naming ``option``."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = low - 1
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"{option} must be an integer from {low} to {high} (got {text!r})")
        return value

    return parse


def register(sub) -> None:
    """Add the ``explore`` sub-command to the ``spinectl`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command action of :func:`spinectl.cli.build_parser`.
    """
    parser = sub.add_parser(
        "explore",
        help="the interactive explorer in the browser (sliders, live drawing, margins, landscapes)",
        description="A local web app (Panel): sliders for E, Lambda, mass, K, the reflex delay, the activation "
        "and its lag; the model drawing, per-segment eigenvalues, counter torques and delay margins at the "
        "current point; the minimum-PCSA and ||CT|| landscapes, clickable. Export the state as a TOML config "
        "or a PNG. Needs pip install 'spinectl[explore]'. See docs/explore.md.",
    )
    parser.add_argument("--port", type=_integer("--port", 1, 65535), default=PORT, help=f"TCP port (default {PORT})")
    parser.add_argument(
        "--address", default=ADDRESS, help=f"interface to listen on (default {ADDRESS}: this machine only)"
    )
    parser.add_argument(
        "--max-sessions",
        type=_integer("--max-sessions", *SESSIONS_RANGE),
        default=MAX_SESSIONS,
        help=f"browser tabs served at once, each a session (default {MAX_SESSIONS}); one more gets 503 until one "
        f"ends, {UNUSED_SESSION_S:g} s after its tab is closed",
    )
    parser.add_argument("--no-browser", action="store_true", help="do not open a browser; print the address only")
    add_model_options(parser)
    parser.set_defaults(func=run)


def run(args) -> int:
    """Run ``spinectl explore``: serve the explorer until interrupted.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments: ``port``, ``address``, ``max_sessions``, ``no_browser`` and the model options.

    Returns
    -------
    int
        Exit code 0 once the server stops.
    """
    model = load_model(args)  # a bad preset or config fails here, before Panel is imported
    from ..explore.launch import serve_explorer

    preset = "--config" if args.config else (args.preset or DEFAULT_PRESET)
    serve_explorer(model, preset, args.port, args.address, show=not args.no_browser, max_sessions=args.max_sessions)
    return 0
