"""The served explorer answers only requests that address it as bound: a DNS-rebinding page gets no session.

A page of another site (``http://evil.example:P/``) whose name its owner makes resolve to
127.0.0.1 is, to the browser, of that site: its requests reach the explorer with
``Host: evil.example:P`` and, for the websocket, ``Origin: http://evil.example:P``. Tornado
lets a websocket whose Origin equals its Host skip Bokeh's origin list, so only a check of
the Host stops it (:func:`spinectl.explore.app.guard`). These tests send the headers such a
page sends, over HTTP and over Bokeh's websocket (with a valid session token, so that only
the headers differ), and the explorer's own pair, which must work. The same in Chromium:
tests/explore/test_browser.py.
"""

from __future__ import annotations

import asyncio
import html
import http.client
import json
import re
import urllib.parse
import urllib.request
import uuid

import browser_harness
import pytest
from tornado.httpclient import HTTPClientError, HTTPRequest
from tornado.websocket import websocket_connect

EVIL = "evil.example"


def _port(url: str) -> int:
    return urllib.parse.urlsplit(url).port


def _pairs(url: str) -> dict[str, tuple[str, str | None]]:
    """(Host, Origin) of a rebinding page, of a foreign page calling the explorer, of the explorer's pages."""
    port = _port(url)
    return {
        "rebinding": (f"{EVIL}:{port}", f"http://{EVIL}:{port}"),
        "rebinding, no Origin": (f"{EVIL}:{port}", None),
        "foreign Origin": (f"127.0.0.1:{port}", f"http://{EVIL}:{port}"),
        "other port": (f"127.0.0.1:{port + 1}", None),
        "own": (f"127.0.0.1:{port}", f"http://127.0.0.1:{port}"),
        "own, localhost": (f"localhost:{port}", f"http://localhost:{port}"),
    }


def _get(url: str, host: str, origin: str | None, path: str = "/") -> int:
    connection = http.client.HTTPConnection("127.0.0.1", _port(url), timeout=60)
    try:
        connection.putrequest("GET", path, skip_host=True)
        connection.putheader("Host", host)
        if origin:
            connection.putheader("Origin", origin)
        connection.endheaders()
        return connection.getresponse().status
    finally:
        connection.close()


PAIRS = ("rebinding", "rebinding, no Origin", "foreign Origin", "other port", "own", "own, localhost")


@pytest.mark.parametrize("pair", PAIRS)
def test_http_requests_must_address_the_server_as_bound(served_url, pair):
    """The page and a static file: 403 for every forged pair, 200 for the explorer's own two."""
    host, origin = _pairs(served_url)[pair]
    expected = 200 if pair.startswith("own") else 403
    assert _get(served_url, host, origin) == expected
    assert _get(served_url, host, origin, "/static/js/bokeh.min.js") == expected


async def _websocket(url: str, host: str, origin: str | None) -> str:
    """Bokeh's websocket opened with a fresh session's token and these headers: its first message type or the
    HTTP status that refused it."""
    page = urllib.request.urlopen(url, timeout=60).read().decode()
    token = re.search(r'"token":"([^"]+)"', page).group(1)
    headers = {"Host": host} | ({"Origin": origin} if origin else {})
    request = HTTPRequest(f"ws://{urllib.parse.urlsplit(url).netloc}/ws", headers=headers, request_timeout=60)
    try:
        socket = await websocket_connect(request, subprotocols=["bokeh", token])
    except HTTPClientError as exc:
        return f"HTTP {exc.code}"
    try:
        return json.loads(await socket.read_message())["msgtype"]  # a Bokeh message's header comes first
    finally:
        socket.close()


def test_the_websocket_refuses_a_rebinding_page_and_serves_the_explorers_own(served_url):
    """With a valid token, the rebinding pair and a foreign Origin get 403; the explorer's own pair gets Bokeh's
    ACK, the start of a session (before the guard the rebinding pair got it too)."""
    pairs = _pairs(served_url)
    names = ("rebinding", "foreign Origin", "own")
    answers = {name: asyncio.run(_websocket(served_url, *pairs[name])) for name in names}
    assert answers == {"rebinding": "HTTP 403", "foreign Origin": "HTTP 403", "own": "ACK"}


async def _frames(socket) -> tuple[dict, str]:
    """One Bokeh message: its header and its content's text (header, metadata, content, then each buffer as two
    frames: its id and its bytes)."""
    header = json.loads(await socket.read_message())
    await socket.read_message()
    content = await socket.read_message()
    for _ in range(2 * header.get("num_buffers", 0)):
        await socket.read_message()
    return header, content


async def _send(socket, msgtype: str, content: dict) -> None:
    await socket.write_message(json.dumps({"msgid": uuid.uuid4().hex, "msgtype": msgtype}))
    await socket.write_message("{}")
    await socket.write_message(json.dumps(content))


def _objects(tree):
    """Every Bokeh model object in a document's JSON."""
    if isinstance(tree, dict):
        if tree.get("type") == "object":
            yield tree
        for value in tree.values():
            yield from _objects(value)
    elif isinstance(tree, list):
        for value in tree:
            yield from _objects(value)


async def _forged(url: str, title: str, attr: str, value) -> list[tuple[str, str]]:
    """Open a session, set ``attr`` of the widget titled ``title`` to ``value`` as a forged PATCH-DOC, and collect
    the server's messages (type, content) until the status line refuses it, an ERROR comes, or 60 s pass."""
    page = urllib.request.urlopen(url, timeout=60).read().decode()
    token = re.search(r'"token":"([^"]+)"', page).group(1)
    request = HTTPRequest(f"ws://127.0.0.1:{_port(url)}/ws", headers={"Origin": url.rstrip("/")})
    socket = await websocket_connect(request, subprotocols=["bokeh", token])
    try:
        await _frames(socket)  # ACK
        await _send(socket, "PULL-DOC-REQ", {})
        _, document = await _frames(socket)
        objects = _objects(json.loads(document))
        (widget,) = (o["id"] for o in objects if o.get("attributes", {}).get("title") == title)
        event = {"kind": "ModelChanged", "model": {"id": widget}, "attr": attr, "new": value}
        await _send(socket, "PATCH-DOC", {"events": [event]})
        answers = []
        while not any("refused" in content or kind == "ERROR" for kind, content in answers):
            header, content = await asyncio.wait_for(_frames(socket), 60)
            answers.append((header["msgtype"], content))
        return answers
    finally:
        socket.close()


def test_a_forged_slider_value_is_answered_in_the_page_not_with_a_traceback(served_url):
    """NaN for the mass (Bokeh's encoding of a NaN number; its type check lets NaN through): no ERROR message
    back (before: the ValueError of the server, with its traceback), and the status line says in one line what
    was refused."""
    answers = asyncio.run(_forged(served_url, "mass [kg]", "value_throttled", {"type": "number", "value": "nan"}))
    assert [kind for kind, _ in answers if kind == "ERROR"] == []
    assert any("mass [kg]: must be finite (got nan)" in content for _, content in answers)


def test_ipv6_loopback_is_served_and_guarded():
    """``--address ::1``: the page and the websocket at http://[::1]:P/ work; Host evil.example is refused."""
    with browser_harness.served(address="::1") as url:
        port = _port(url)
        with urllib.request.urlopen(url, timeout=60) as response:
            assert response.status == 200
        own, evil = f"[::1]:{port}", f"{EVIL}:{port}"
        assert asyncio.run(_websocket(url, own, f"http://{own}")) == "ACK"
        assert asyncio.run(_websocket(url, evil, f"http://{evil}")) == "HTTP 403"


def _get_with(url: str, headers: dict[str, str], path: str = "/") -> tuple[int, str]:
    """GET with these headers (and the explorer's own Host): the status and the body."""
    connection = http.client.HTTPConnection("127.0.0.1", _port(url), timeout=60)
    try:
        connection.request("GET", path, headers=headers)
        response = connection.getresponse()
        return response.status, response.read().decode(errors="replace")
    finally:
        connection.close()


def _opened(log: list[str]) -> int:
    return sum("session opened" in line for line in log)


OTHER_SITES = {  # what Chromium sends for these loads by a page of another site (none sends an Origin)
    "<img src>": {"Sec-Fetch-Site": "cross-site", "Sec-Fetch-Mode": "no-cors", "Sec-Fetch-Dest": "image"},
    "<iframe src>": {"Sec-Fetch-Site": "cross-site", "Sec-Fetch-Mode": "navigate", "Sec-Fetch-Dest": "iframe"},
    "a link": {"Sec-Fetch-Site": "cross-site", "Sec-Fetch-Mode": "navigate", "Sec-Fetch-Dest": "document"},
    "<script>, another port": {"Sec-Fetch-Site": "same-site", "Sec-Fetch-Mode": "no-cors", "Sec-Fetch-Dest": "script"},
}


@pytest.mark.parametrize("load", OTHER_SITES)
def test_a_page_of_another_site_gets_403_and_builds_no_session(served_url, served_log, load):
    """Refused before any session is built: then the user's own navigation (Sec-Fetch-Site: none) opens exactly one
    session, the first after the refusal in the server's output (before: 200 and a session each, about 0.4 s of a
    core at a load of 0.4, 2 s under load, for any page the user visited)."""
    start = len(served_log)
    status, body = _get_with(served_url, OTHER_SITES[load])
    assert status == 403 and "a page of another site made this request" in body
    dest = OTHER_SITES[load]["Sec-Fetch-Dest"]
    refused = browser_harness.wait_for_line(served_log, f"(Sec-Fetch-Dest '{dest}')", start)
    before = _opened(served_log[:refused])  # the server writes in order: every earlier line is in by now
    assert _get_with(served_url, {"Sec-Fetch-Site": "none", "Sec-Fetch-Dest": "document"})[0] == 200
    browser_harness.wait_for_line(served_log, "session opened", refused)
    assert _opened(served_log) == before + 1  # the user's page only


def test_the_explorers_own_loads_get_in(served_url):
    """Its page's scripts (same-origin) and a page load without Sec-Fetch headers (an older browser, curl)."""
    script = {"Sec-Fetch-Site": "same-origin", "Sec-Fetch-Dest": "script"}
    assert _get_with(served_url, script, "/static/js/bokeh.min.js")[0] == 200
    assert _get_with(served_url, {})[0] == 200


def test_a_forged_preset_is_refused_in_the_page_and_not_logged(served_url, served_log):
    """A PATCH-DOC setting the preset selector to a name that is no option: the status line refuses it, no ERROR
    goes back, and the server's output gets no line (before: Panel's "nope not in list" traceback, twice)."""
    start = len(served_log)
    answers = asyncio.run(_forged(served_url, "preset", "value", "nope"))
    assert [kind for kind, _ in answers if kind == "ERROR"] == []
    assert any("preset: must be one of" in html.unescape(content) for _, content in answers)
    assert [line for line in served_log[start:] if "session" not in line] == []


def test_a_value_of_the_wrong_type_is_one_line_in_the_log(served_url, served_log):
    """A string for the mass slider: Bokeh's own type check refuses it (an ERROR back to the forging page) and the
    server's output gets one line, not Bokeh's traceback (before: 30 lines)."""
    start = len(served_log)
    answers = asyncio.run(_forged(served_url, "mass [kg]", "value_throttled", "abc"))
    assert [kind for kind, _ in answers][-1] == "ERROR"
    index = browser_harness.wait_for_line(served_log, "refused a value from a page", start)
    assert "expected a value of type Real, got abc" in served_log[index]
    assert [line for line in served_log[start:] if "session" not in line] == [served_log[index]]


def _token_of(page: str) -> str:
    return re.search(r'"token":"([^"]+)"', page).group(1)


async def _ack(url: str, token: str) -> str:
    """Bokeh's websocket opened with ``token`` by the explorer's own page: its first message type or the HTTP status
    that refused it."""
    request = HTTPRequest(f"ws://127.0.0.1:{_port(url)}/ws", headers={"Origin": url.rstrip("/")}, request_timeout=60)
    try:
        socket = await websocket_connect(request, subprotocols=["bokeh", token])
    except HTTPClientError as exc:
        return f"HTTP {exc.code}"
    try:
        return json.loads(await socket.read_message())["msgtype"]
    finally:
        socket.close()


def test_sessions_beyond_the_bound_get_503_until_one_ends():
    """``--max-sessions 2``: two pages get sessions, the third 503 saying why; the second page's websocket still
    connects (its session exists), a websocket for a session that does not gets 503; once the unconnected
    sessions have ended (15 s after they were made: Bokeh's lifetime of a session without page) a page gets
    in again (before: no bound; each page a session, a core for a second or two)."""
    log: list[str] = []
    with browser_harness.served("--max-sessions", "2", log=log) as url:  # the harness's own first GET: one session
        second = urllib.request.urlopen(url, timeout=60).read().decode()
        status, body = _get_with(url, {})
        assert status == 503 and "2 sessions are open, the most the explorer serves at once (--max-sessions)" in body
        assert asyncio.run(_ack(url, _token_of(second))) == "ACK"
        from bokeh.util.token import generate_jwt_token

        assert asyncio.run(_ack(url, generate_jwt_token("no-such-session", signed=False))) == "HTTP 503"
        browser_harness.wait_for_line(log, "session ended (1 open, at most 2)")
        assert _get_with(url, {})[0] == 200
    opened = [line.strip() for line in log if "session opened" in line]
    assert opened[:2] == [f"spinectl explore: session opened ({n} open, at most 2)" for n in (1, 2)]
    # the third: 2 open, or 1 where the other unconnected session ended too before it (both expire 15 s after
    # they were made, a few ms apart; a loaded machine can order the lines either way)
    assert len(opened) == 3 and opened[2] in {f"spinectl explore: session opened ({n} open, at most 2)" for n in (1, 2)}
