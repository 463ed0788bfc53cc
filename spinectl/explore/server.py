"""The explorer's server: Panel's Bokeh server, one :class:`~spinectl.explore.app.Explorer` per browser tab, guarded.

:func:`serve` starts it. Every request first meets :func:`guard`, the first rule of the
server's Tornado routing: a request that does not address the server as bound (DNS
rebinding) or that a page of another site makes (``Sec-Fetch-Site``: an ``<img>``, an
``<iframe>``, a script, a link or a redirect to the explorer) gets ``403``
(:func:`spinectl.explore.hosts.refusal`). Then :class:`Sessions` bounds the sessions alive
at once: each costs a core for a second or two to build and lives until its page has been
gone for :data:`~spinectl.explore.hosts.UNUSED_SESSION_S`; one more than the bound gets ``503`` until one ends.
docs/explore.md, "Who can reach it".
"""

from __future__ import annotations

import logging
import webbrowser

import panel as pn
from bokeh.application.handlers.handler import Handler
from bokeh.util.token import get_session_id
from tornado.log import app_log
from tornado.routing import Matcher, Rule
from tornado.web import HTTPError, RequestHandler

from .._validate import printable
from ..model.params import Model
from .app import Explorer
from .hosts import MAX_SESSIONS, UNUSED_SESSION_S, allowed_hosts, refusal, url_host

CHECK_UNUSED_S = 1.0
"""How often the server ends such sessions [s] (Bokeh's default is 17 s: a freed place would wait that long)."""
WEBSOCKET_PATH = "/ws"
"""The path of Bokeh's websocket for the app at ``/``."""
PROTOCOL_LOGGER = "bokeh.server.protocol_handler"
"""The logger of Bokeh's handling of the pages' messages."""


def serve(
    model: Model,
    preset: str,
    port: int,
    address: str = "127.0.0.1",
    show: bool = True,
    max_sessions: int = MAX_SESSIONS,
) -> None:
    """Serve the explorer at ``http://address:port/`` until interrupted; one :class:`Explorer` per browser tab.

    The URL is printed once the server listens (a port taken raises before anything is printed).

    Parameters
    ----------
    model : Model
        The model to start from.
    preset : str
        Its entry in the preset selector (a preset's name or :data:`spinectl.explore.app.CONFIG_CHOICE`).
    port : int
        TCP port.
    address : str
        Interface to bind; the loopback interface by default, so that no other machine can connect.
    show : bool
        Open the app in the default browser.
    max_sessions : int
        Sessions alive at once; one more gets ``503`` (:class:`Sessions`).

    Raises
    ------
    ParameterError
        An address that names no one interface (:func:`spinectl.explore.hosts.allowed_hosts`).
    OSError
        The address and port cannot be bound.
    """
    allowed = allowed_hosts(address, port)
    server = pn.serve(
        {"/": lambda: Explorer(model, preset).layout},
        port=port,
        address=address.strip().strip("[]"),
        websocket_origin=bokeh_origins(allowed),
        show=False,  # Bokeh's own opener writes an IPv6 address without brackets
        start=False,
        title="spinectl explore",
        location=False,  # the app reads no URL; Panel's Location cannot parse an IPv6 Host
        verbose=False,
        unused_session_lifetime_milliseconds=int(UNUSED_SESSION_S * 1000),
        check_unused_sessions_milliseconds=int(CHECK_UNUSED_S * 1000),
    )  # bound and listening from here: Bokeh's Server binds its sockets when it is made
    tornado = server._tornado  # Bokeh's Tornado application (Panel reads it by this name too)
    sessions = Sessions(tornado.applications["/"], max_sessions)
    guard(tornado, allowed, sessions)
    logging.getLogger(PROTOCOL_LOGGER).addFilter(ONE_LINE)
    server.start()
    url = f"http://{url_host(address)}:{port}/"
    print(f"spinectl explore: {url} (Ctrl+C stops)", flush=True)
    if show:
        server.io_loop.add_callback(webbrowser.open_new_tab, url)
    server.io_loop.start()


def bokeh_origins(allowed: frozenset[tuple[str, int]]) -> list[str]:
    """The allowed pairs as Bokeh's websocket origins, ``host:port``, sorted.

    Bokeh's list cannot hold an IPv6 address (it splits at every colon); for those the guard
    (:func:`guard`) is the only check, as Tornado skips Bokeh's for a same-origin websocket.

    Parameters
    ----------
    allowed : frozenset of (str, int)
        :func:`spinectl.explore.hosts.allowed_hosts`.

    Returns
    -------
    list of str
        E.g. ``['127.0.0.1:5006', 'localhost:5006']``.
    """
    return sorted(f"{host}:{port}" for host, port in allowed if ":" not in host)


class Sessions:
    """The bound on the sessions alive at once, kept where Bokeh makes every session.

    Bokeh makes a session in its application context's ``create_session_if_needed``: for a page
    (``GET /``) and for a websocket whose token names no live session. That method is wrapped:
    one session more than ``limit`` is refused there with ``503`` (counted with those being made,
    so that requests arriving together cannot pass it together). A websocket is refused before
    its upgrade instead (:meth:`admits_websocket`, by :func:`guard`), as Bokeh opens it before
    it makes the session; the websocket of a page already served always gets in.
    Each session opened and ended is one line on standard output, with the count.

    Parameters
    ----------
    context : bokeh.server.contexts.ApplicationContext
        The app's context (``BokehTornado.applications["/"]``).
    limit : int
        Sessions alive at once, in :data:`spinectl.explore.hosts.SESSIONS_RANGE`.
    """

    def __init__(self, context, limit: int):
        self.context, self.limit = context, limit
        self._making: set[str] = set()
        self._make = context.create_session_if_needed
        context.create_session_if_needed = self._create
        context.application.add(_SessionEnd(self))

    def live(self) -> set[str]:
        """The ids of the sessions alive and of those being made.

        Returns
        -------
        set of str
        """
        return {session.id for session in self.context.sessions} | self._making

    def admits(self, session_id: str) -> bool:
        """Whether a request for ``session_id`` may go on: its session lives, or there is room for one more.

        Parameters
        ----------
        session_id : str
            Bokeh's session id.

        Returns
        -------
        bool
        """
        live = self.live()
        return session_id in live or len(live) < self.limit

    def admits_websocket(self, request) -> bool:
        """Whether a request may go on unless it is a websocket that would make one session too many.

        Parameters
        ----------
        request : tornado.httputil.HTTPServerRequest
            The request, before its upgrade (its path and ``Sec-WebSocket-Protocol``).

        Returns
        -------
        bool
        """
        if request.path != WEBSOCKET_PATH:
            return True
        protocols = [p.strip() for p in request.headers.get("Sec-WebSocket-Protocol", "").split(",")]
        try:  # Bokeh's client sends "bokeh, <token>"; Bokeh itself refuses any other
            session_id = get_session_id(protocols[1])
        except (IndexError, ValueError):
            return True
        return self.admits(session_id)

    def refusal(self) -> str:
        """The one line that refuses a session: how many live, what to do.

        Returns
        -------
        str
        """
        return (
            f"refused: {self.limit} sessions are open, the most the explorer serves at once (--max-sessions); "
            f"one ends {UNUSED_SESSION_S:g} s after its tab is closed"
        )

    async def _create(self, session_id, request=None, token=None):
        if not self.admits(session_id):
            app_log.warning("spinectl explore: %s", self.refusal())
            raise HTTPError(503, reason=self.refusal())  # Tornado's page shows it
        new = session_id not in self.live()  # a page's websocket comes for the session its page made
        self._making.add(session_id)
        try:
            session = await self._make(session_id, request, token)
        finally:
            self._making.discard(session_id)
        if new:
            self.report("opened")
        return session

    def report(self, event: str) -> None:
        """One line on standard output: a session ``event`` and how many are alive.

        Parameters
        ----------
        event : str
            ``"opened"`` or ``"ended"``.
        """
        print(f"spinectl explore: session {event} ({len(self.live())} open, at most {self.limit})", flush=True)


class _OneLine(logging.Filter):
    """A page's value refused by Bokeh's own type check (a forged message: a string for a slider) in one line.

    Bokeh answers the sending page with an ``ERROR`` message and goes on, but logs the message, the
    error and its traceback; the error alone says what was refused. Any other record passes as it is.
    """

    def filter(self, record: logging.LogRecord) -> bool:
        error = record.exc_info[1] if record.exc_info else None
        if isinstance(error, ValueError) and str(error).startswith("failed to validate"):
            record.msg, record.args = "spinectl explore: refused a value from a page: %s", (printable(str(error)),)
            record.exc_info = record.exc_text = None
        return True


ONE_LINE = _OneLine()
"""The filter on :data:`PROTOCOL_LOGGER` (one instance: adding it again changes nothing)."""


class _SessionEnd(Handler):
    """A Bokeh handler of the app that reports each session's end (after Bokeh has dropped it)."""

    def __init__(self, sessions: Sessions):
        super().__init__()
        self.sessions = sessions

    def modify_document(self, doc) -> None:  # the app's document is the Explorer's; nothing to add
        pass

    async def on_session_destroyed(self, session_context) -> None:
        self.sessions.report("ended")


class _Guard(Matcher):
    """Tornado's routing: matches a request to refuse, with its status and one-line reason."""

    def __init__(self, allowed: frozenset[tuple[str, int]], sessions: Sessions | None):
        self.allowed, self.sessions = allowed, sessions

    def match(self, request) -> dict | None:
        reason = refusal(request.headers, self.allowed)
        if reason is not None:
            return {"target_kwargs": {"status": 403, "reason": f"refused: {reason}"}}
        if self.sessions is not None and not self.sessions.admits_websocket(request):
            return {"target_kwargs": {"status": 503, "reason": self.sessions.refusal()}}
        return None


class _Refused(RequestHandler):
    """Answers ``status``, whatever the method, and says why in one line (in the page and the server's log)."""

    def initialize(self, status: int, reason: str) -> None:
        self.status, self.reason = status, reason

    def prepare(self) -> None:
        app_log.warning("spinectl explore: %s", self.reason)
        self.set_status(self.status)
        self.finish(self.reason + "\n")


def guard(application, allowed: frozenset[tuple[str, int]], sessions: Sessions | None = None) -> None:
    """Route every request to refuse to a ``403`` (or ``503``), before any of Bokeh's handlers.

    The first rule of the Tornado application's router (Tornado's own ``add_handlers`` inserts its
    host rules into the same list): it sees each request, the websocket's upgrade included, before
    Bokeh's handlers. Tornado lets a websocket whose Origin equals its Host skip Bokeh's origin list,
    so a DNS-rebinding page would pass that list; the Host check stops it.

    Parameters
    ----------
    application : tornado.web.Application
        The Bokeh server's Tornado application.
    allowed : frozenset of (str, int)
        :func:`spinectl.explore.hosts.allowed_hosts`.
    sessions : Sessions, optional
        The bound on the sessions: a websocket that would make one too many gets ``503``.
    """
    application.default_router.rules.insert(0, Rule(_Guard(allowed, sessions), _Refused))
