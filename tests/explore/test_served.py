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


async def _forged_mass(url: str, value) -> list[tuple[str, str]]:
    """Open a session, set the mass slider's value_throttled to ``value`` as a forged PATCH-DOC, and collect the
    server's messages (type, content) until the status line answers or 60 s pass."""
    page = urllib.request.urlopen(url, timeout=60).read().decode()
    token = re.search(r'"token":"([^"]+)"', page).group(1)
    request = HTTPRequest(f"ws://127.0.0.1:{_port(url)}/ws", headers={"Origin": url.rstrip("/")})
    socket = await websocket_connect(request, subprotocols=["bokeh", token])
    try:
        await _frames(socket)  # ACK
        await _send(socket, "PULL-DOC-REQ", {})
        _, document = await _frames(socket)
        objects = _objects(json.loads(document))
        (mass,) = (o["id"] for o in objects if o.get("attributes", {}).get("title") == "mass [kg]")
        event = {"kind": "ModelChanged", "model": {"id": mass}, "attr": "value_throttled", "new": value}
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
    answers = asyncio.run(_forged_mass(served_url, {"type": "number", "value": "nan"}))
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
