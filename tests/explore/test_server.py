"""The explorer's server without a browser: what serve() asks Panel for, the guard it puts first, the session bound.

Served over HTTP and the websocket: tests/explore/test_served.py.
"""

from __future__ import annotations

import asyncio
import logging
import sys
from types import SimpleNamespace

import pytest
from tornado.httputil import HTTPHeaders
from tornado.web import Application, HTTPError

from spinectl.explore import server
from spinectl.explore.hosts import MAX_SESSIONS
from spinectl.model.config import load_preset


class _Context:
    """What Sessions uses of Bokeh's ApplicationContext: the live sessions, the maker, the application."""

    def __init__(self):
        self.made: dict[str, SimpleNamespace] = {}
        self.handlers = []
        self.application = SimpleNamespace(add=self.handlers.append)

    @property
    def sessions(self):
        return self.made.values()

    async def create_session_if_needed(self, session_id, request=None, token=None):
        await asyncio.sleep(0)  # Bokeh awaits the app's hooks while it makes a session: others come in meanwhile
        return self.made.setdefault(session_id, SimpleNamespace(id=session_id))


class _Server:
    """What ``pn.serve(start=False)`` returns, as far as serve() uses it: Bokeh's Tornado application, a loop."""

    def __init__(self):
        self._tornado = Application()
        self._tornado.applications = {"/": _Context()}
        self.calls = []
        self.io_loop = SimpleNamespace(start=lambda: self.calls.append("loop"), add_callback=self._callback)

    def start(self):
        self.calls.append("start")

    def _callback(self, function, *args):
        self.calls.append((function, *args))


def test_serve_binds_the_loopback_interface_by_default(monkeypatch, capsys):
    """serve() asks Panel for 127.0.0.1 (no other machine can connect), accepts websockets from there only, and
    puts the guard first in Tornado's routing (so that it sees every request), with the default bound of sessions."""
    calls, stub = [], _Server()
    monkeypatch.setattr(server.pn, "serve", lambda panels, **options: calls.append(options) or stub)
    server.serve(load_preset("default"), "default", 5999, show=False)
    (options,) = calls
    assert options["address"] == "127.0.0.1" and options["port"] == 5999 and options["start"] is False
    assert options["websocket_origin"] == ["127.0.0.1:5999", "localhost:5999"]
    assert options["unused_session_lifetime_milliseconds"] == 15000  # Bokeh's default, said in --help
    first = stub._tornado.default_router.rules[0]
    assert isinstance(first.matcher, server._Guard) and first.target is server._Refused
    assert first.matcher.allowed == {("127.0.0.1", 5999), ("localhost", 5999)}
    assert first.matcher.sessions.limit == MAX_SESSIONS == 8
    assert stub.calls == ["start", "loop"]  # no browser opened
    assert capsys.readouterr().out == "spinectl explore: http://127.0.0.1:5999/ (Ctrl+C stops)\n"


def test_serve_on_ipv6_loopback_writes_the_url_with_brackets(monkeypatch, capsys):
    """--address ::1: Panel binds ::1; the URL printed and opened is http://[::1]:P/ (RFC 3986, 3.2.2); Bokeh's
    origin list, which cannot hold an IPv6 address, gets localhost only; the guard allows [::1] and localhost."""
    calls, stub = [], _Server()
    monkeypatch.setattr(server.pn, "serve", lambda panels, **options: calls.append(options) or stub)
    server.serve(load_preset("default"), "default", 5999, address="::1", show=True, max_sessions=3)
    (options,) = calls
    assert options["address"] == "::1" and options["websocket_origin"] == ["localhost:5999"]
    matcher = stub._tornado.default_router.rules[0].matcher
    assert matcher.allowed == {("::1", 5999), ("localhost", 5999)} and matcher.sessions.limit == 3
    assert stub.calls == ["start", (server.webbrowser.open_new_tab, "http://[::1]:5999/"), "loop"]
    assert capsys.readouterr().out == "spinectl explore: http://[::1]:5999/ (Ctrl+C stops)\n"


def test_a_port_that_cannot_be_bound_prints_no_url(monkeypatch, capsys):
    """Bokeh binds when the server is made; its OSError comes before the URL is announced (before: the URL was
    printed, then the error)."""

    def taken(panels, **options):
        raise OSError(98, "Address already in use")

    monkeypatch.setattr(server.pn, "serve", taken)
    with pytest.raises(OSError):
        server.serve(load_preset("default"), "default", 5999, show=False)
    assert capsys.readouterr().out == ""


def _request(path: str = "/", **headers) -> SimpleNamespace:
    """What the guard reads of a Tornado request."""
    return SimpleNamespace(path=path, headers=HTTPHeaders(headers))


def test_sessions_beyond_the_bound_are_refused_with_503_even_when_they_come_together(capsys):
    """Bound 2: four pages at once (each awaits inside Bokeh's maker, so all four are inside it together) make 2
    sessions; the others get 503. A page's websocket for its own session always gets in, another waits; once a
    session ends, a new page gets in. Each session opened and ended is one line with the count."""
    context = _Context()
    sessions = server.Sessions(context, 2)

    async def four_pages():
        return await asyncio.gather(
            *(context.create_session_if_needed(f"s{i}") for i in range(4)), return_exceptions=True
        )

    results = asyncio.run(four_pages())
    assert [getattr(r, "id", None) for r in results] == ["s0", "s1", None, None]
    assert [r.status_code for r in results[2:]] == [503, 503]
    assert "2 sessions are open" in results[2].reason and "--max-sessions" in results[2].reason
    assert asyncio.run(context.create_session_if_needed("s1")).id == "s1"  # its page's websocket: no new session

    (end,) = context.handlers
    assert sessions.admits_websocket(_request("/ws", **{"Sec-WebSocket-Protocol": f"bokeh, {_token('s0')}"}))
    assert not sessions.admits_websocket(_request("/ws", **{"Sec-WebSocket-Protocol": f"bokeh, {_token('new')}"}))
    assert sessions.admits_websocket(_request("/static/js/bokeh.min.js"))  # no session made there

    del context.made["s0"]  # Bokeh drops a session its page left UNUSED_SESSION_S ago, then tells the app
    asyncio.run(end.on_session_destroyed(None))
    assert asyncio.run(context.create_session_if_needed("s4")).id == "s4"
    assert capsys.readouterr().out.splitlines() == [
        "spinectl explore: session opened (2 open, at most 2)",  # the other was being made: counted
        "spinectl explore: session opened (2 open, at most 2)",
        "spinectl explore: session ended (1 open, at most 2)",
        "spinectl explore: session opened (2 open, at most 2)",
    ]
    with pytest.raises(HTTPError):
        asyncio.run(context.create_session_if_needed("s5"))


def _token(session_id: str) -> str:
    from bokeh.util.token import generate_jwt_token

    return generate_jwt_token(session_id, signed=False)


def test_a_refused_value_bokeh_logs_is_one_line():
    """Bokeh's type check of a forged value (a string for a slider) is logged as its error alone; other records of
    that logger keep their traceback."""
    try:
        raise ValueError("failed to validate Slider(id='p1', ...).value: expected a value of type Real, got abc")
    except ValueError:
        record = logging.LogRecord("bokeh", logging.ERROR, "f", 1, "error handling message %r", ("m",), sys.exc_info())
    assert server.ONE_LINE.filter(record) and record.exc_info is None
    assert record.getMessage() == (
        "spinectl explore: refused a value from a page: failed to validate Slider(id='p1', ...).value: "
        "expected a value of type Real, got abc"
    )
    try:
        raise ValueError("a bug")
    except ValueError:
        other = logging.LogRecord("bokeh", logging.ERROR, "f", 1, "error handling message", (), sys.exc_info())
    assert server.ONE_LINE.filter(other) and other.exc_info is not None
