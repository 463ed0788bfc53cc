"""Start the explorer's server, or say in one line what is missing (Panel) or in the way (the port, the address).

Kept apart from :mod:`spinectl.explore.server` so that the command line can import it
without Panel installed. What the server checks on every request (the guard against
DNS rebinding and other sites' pages) is :mod:`spinectl.explore.hosts`.
"""

from __future__ import annotations

from .._validate import integer
from ..errors import OutputError, SpinectlError
from ..model.params import Model
from .hosts import MAX_SESSIONS, SESSIONS_RANGE, allowed_hosts, url_host

EXTRA = "pip install 'spinectl[explore]'"
"""How to install the explorer's dependencies."""


def serve_explorer(
    model: Model,
    preset: str,
    port: int,
    address: str = "127.0.0.1",
    show: bool = True,
    max_sessions: int = MAX_SESSIONS,
) -> None:
    """Serve the explorer (:func:`spinectl.explore.server.serve`) until interrupted.

    Parameters
    ----------
    model : Model
        The model to start from.
    preset : str
        Its entry in the preset selector (a preset's name, or '--config').
    port : int
        TCP port.
    address : str
        Interface to bind (default the loopback one).
    show : bool
        Open the default browser.
    max_sessions : int
        Sessions alive at once, in :data:`~spinectl.explore.hosts.SESSIONS_RANGE`.

    Raises
    ------
    ParameterError
        An address that names no one interface (:func:`~spinectl.explore.hosts.allowed_hosts`), a bound of
        sessions out of range.
    SpinectlError
        Panel (the ``explore`` extra) is not installed.
    OutputError
        The address and port cannot be bound (in use, not this machine's).
    """
    allowed_hosts(address, port)  # a bad address or bound is refused before Panel is imported
    integer("--max-sessions", max_sessions, *SESSIONS_RANGE)
    try:
        from . import server
    except ModuleNotFoundError as exc:
        if exc.name not in ("panel", "bokeh"):
            raise
        raise SpinectlError(f"spinectl explore needs Panel ({exc.name} is missing): {EXTRA}") from None
    try:
        server.serve(model, preset, port, address, show, max_sessions)
    except OSError as exc:
        where = f"{url_host(address)}:{port}"
        raise OutputError(f"--port: cannot listen on {where} ({exc.strerror or exc})") from None
