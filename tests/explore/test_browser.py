"""End to end in a real browser: ``spinectl explore`` served on a free loopback port, driven by headless Chromium.

Playwright's Python API drives the system's Chromium (Debian's ``chromium`` package,
installed by ``scripts/setup`` and ``.ci/run``; no browser is downloaded). The test moves
the E slider and clicks a landscape, and checks that the table and the model drawing
become those the library computes for the new point (:func:`spinectl.explore.numbers.point_numbers`,
:func:`spinectl.explore.app.drawing_svg`, byte for byte).

Without Chromium the test fails with a message saying how to install it; a developer
without it can set ``SPINECTL_SKIP_BROWSER=1`` (CI never does).
"""

from __future__ import annotations

import base64
import contextlib
import http.server
import os
import re
import threading
import time
import urllib.parse

import browser_harness
import pytest

from spinectl.explore import app
from spinectl.explore import numbers as nb
from spinectl.explore.state import from_shown, initial_state, replace, slider_for
from spinectl.model.config import load_preset

OPT_OUT = "SPINECTL_SKIP_BROWSER"


@pytest.fixture(scope="module")
def executable():
    """The Chromium binary, or the test fails saying how to install it (or skips, opted out)."""
    if os.environ.get(OPT_OUT):
        pytest.skip(f"{OPT_OUT} is set")
    found = browser_harness.chromium()
    if found is None:
        pytest.fail(
            f"the browser test needs Chromium at {browser_harness.CHROMIUM}: {browser_harness.INSTALL}; "
            f"{OPT_OUT}=1 skips this test"
        )
    return found


REBINDING = "--host-resolver-rules=MAP evil.example 127.0.0.1"
"""Chromium resolves evil.example to 127.0.0.1, as a DNS-rebinding attacker's name server makes it."""


@pytest.fixture(scope="module")
def browser_tab(executable):
    """A blank page of one headless Chromium for the module (Playwright's sync API runs one at a time)."""
    with browser_harness.browser_page(executable, REBINDING) as tab:
        yield tab


@pytest.fixture(scope="module")
def page(served_url, browser_tab):
    """The explorer served from this checkout, open in headless Chromium."""
    browser_tab.goto(served_url)
    browser_tab.wait_for_selector("td[data-key=counter_torque_Nm]")
    return browser_tab


LANDSCAPES_SHOWN = """() => [...Bokeh.documents[0]._all_models.values()].filter(
    m => (m.type == "Title" || m.constructor.__name__ == "Title") && m.text.includes("\\nmass ")).length == 2"""
"""JavaScript: both landscapes' titles in the page give the mass they were solved for (before their solve was
deferred to the page's load, the first solve's views were not sent to about 3 pages in 10)."""


def _table(page) -> list[dict[str, str]]:
    cells = page.locator("td[data-key]")
    rows, row = [], {}
    for i in range(cells.count()):
        key = cells.nth(i).get_attribute("data-key")
        row[key] = cells.nth(i).inner_text().strip()
        if key == app.ROW_KEYS[-1]:
            rows.append(row)
            row = {}
    return rows


def _drawing(page) -> str:
    """The SVG of the model drawing, the page's one SVG image."""
    sources = [s for s in page.locator("img").evaluate_all("els => els.map(e => e.src)") if "image/svg+xml" in s]
    (source,) = sources
    return base64.b64decode(source.split(",", 1)[1]).decode()


def _shown(page, label: str) -> float:
    """A slider's value as its label shows it, e.g. 'E [cm]: 3.60' -> 3.6."""
    text = page.get_by_text(re.compile("^" + re.escape(label) + ":")).first.inner_text()
    return float(text.split(":")[1])


def _expect(page, state):
    """Wait until the table shows the numbers of ``state``; then they, and the drawing, must be the library's."""
    from playwright.sync_api import expect

    expected = nb.point_numbers(load_preset(), state)
    first = expected.rows()[0]["counter_torque_Nm"]
    expect(page.locator("td[data-key=counter_torque_Nm]").first).to_have_text(
        first, timeout=browser_harness.TIMEOUT_S * 1000
    )
    assert _table(page) == expected.rows()
    assert _drawing(page) == app.drawing_svg(expected)


def test_slider_and_click_move_the_point_to_the_librarys_numbers(page):
    """Start: the README's point; drag E: the numbers and the drawing of the new E; click the minimum-PCSA
    landscape: those of the clicked point (read back from the page)."""
    state = initial_state(load_preset())
    page.wait_for_function(LANDSCAPES_SHOWN)
    assert _table(page) == nb.point_numbers(load_preset(), state).rows()
    assert _drawing(page) == app.drawing_svg(nb.point_numbers(load_preset(), state))

    handle = page.locator(".noUi-handle").first  # the first slider is E
    box = handle.bounding_box()
    x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    page.mouse.move(x, y)
    page.mouse.down()
    page.mouse.move(x + 40, y, steps=5)
    page.mouse.up()
    moved = _point_shown(page, state, state)
    assert moved.eccentricity > state.eccentricity and moved.lordosis == state.lordosis
    _expect(page, moved)

    canvases = page.locator(".bk-Canvas")  # the Bokeh plots: eigenvalues, CT, margins, then the two landscapes
    landscape = canvases.nth(canvases.count() - 2).bounding_box()  # the minimum-PCSA landscape
    page.mouse.click(landscape["x"] + 0.3 * landscape["width"], landscape["y"] + 0.25 * landscape["height"])
    clicked = _point_shown(page, moved, moved)
    assert clicked.eccentricity < moved.eccentricity and clicked.lordosis > moved.lordosis  # left of it, higher
    _expect(page, clicked)


def _point_shown(page, state, before):
    """``state`` at the point the page shows once it differs from ``before``: (E, Lambda) [m] as the status
    line above the table gives it (set with the table, at once), and the sliders' labels must agree."""
    fields = ("eccentricity", "lordosis")
    before = tuple(getattr(before, f) for f in fields)
    deadline = time.monotonic() + browser_harness.TIMEOUT_S
    while True:
        status = page.locator("[data-key=status]").first.inner_text()
        point = tuple(float(x) / 100 for x in re.match(r"E = (\S+) cm, Λ = (\S+) cm", status).groups())
        labels = tuple(from_shown(slider_for(f), _shown(page, slider_for(f).label)) for f in fields)
        if (point != before and labels == point) or time.monotonic() > deadline:
            assert labels == point and point != before
            return replace(state, **dict(zip(fields, point, strict=True)))
        time.sleep(0.2)


def test_a_dns_rebinding_page_gets_no_session(served_url, browser_tab):
    """Chromium resolves evil.example to 127.0.0.1 (:data:`REBINDING`): http://evil.example:P/ is the explorer's
    port under another site's name. The page is refused (403) and no websocket opens (before the Host check it
    got a session: sliders, table and the TOML export)."""
    port = urllib.parse.urlsplit(served_url).port
    tab = browser_tab.context.new_page()
    tab.set_default_timeout(browser_harness.TIMEOUT_S * 1000)
    try:
        sockets = []
        tab.on("websocket", lambda socket: sockets.append(socket.url))
        response = tab.goto(f"http://evil.example:{port}/")
        assert response.status == 403 and "not the address the explorer is bound to" in tab.content()
        tab.wait_for_timeout(1000)  # a script of the page, had it been served, would have opened the socket
        assert sockets == [] and tab.locator("td[data-key]").count() == 0
    finally:
        tab.close()


@contextlib.contextmanager
def _page_of_another_site(body: str):
    """A page served on a free loopback port of its own, to be opened as http://evil.example:Q/ (:data:`REBINDING`:
    another site to the browser, a local address, so that Chromium lets it load from the loopback interface)."""
    page = body.encode()

    class Page(http.server.BaseHTTPRequestHandler):
        def do_GET(self):  # noqa: N802 (the standard library's name)
            self.send_response(200)
            self.send_header("Content-Type", "text/html")
            self.end_headers()
            self.wfile.write(page)

        def log_message(self, *args):
            pass

    with http.server.ThreadingHTTPServer(("127.0.0.1", 0), Page) as site:
        thread = threading.Thread(target=site.serve_forever, daemon=True)
        thread.start()
        try:
            yield f"http://evil.example:{site.server_address[1]}/"
        finally:
            site.shutdown()


def test_a_page_of_another_site_cannot_load_the_explorer(served_url, served_log, browser_tab):
    """A page of another site embeds the explorer as an image and in a frame, as any page the user visits could:
    Chromium sends Sec-Fetch-Site: cross-site (and no Origin); both loads get 403 and the server builds no session
    for them (before: 200 each and a session, a core busy for one to two seconds, for every such page). The
    explorer's own page keeps working (:func:`test_slider_and_click_move_the_point_to_the_librarys_numbers`)."""
    start = len(served_log)
    html = f'<img src="{served_url}?img"><iframe src="{served_url}?frame"></iframe>'
    tab = browser_tab.context.new_page()
    tab.set_default_timeout(browser_harness.TIMEOUT_S * 1000)
    statuses = {}
    tab.on("response", lambda response: statuses.update({response.url: response.status}))
    try:
        with _page_of_another_site(html) as evil:
            tab.goto(evil)
            for kind in ("image", "iframe"):
                browser_harness.wait_for_line(served_log, f"'cross-site' (Sec-Fetch-Dest '{kind}')", start)
    finally:
        tab.close()
    assert statuses[f"{served_url}?img"] == 403 and statuses[f"{served_url}?frame"] == 403
    assert [line for line in served_log[start:] if "session opened" in line] == []


def _words(text: str) -> str:
    """Text with its whitespace as a browser lays it out: runs of it as one space (the command's two spaces too)."""
    return " ".join(text.split())


def test_a_design_in_the_browser_reads_as_spinectl_design(served_url, browser_tab):
    """A new tab at the opening state: its first screen gives the chain's verdict with its criterion (above the
    fold, the library's words, PointNumbers.verdicts); the button *design for this delay* shows, line by line,
    the words of spinectl design's table (numbers.design_rows of the library's answer at the same state), among
    them the reflex each answer assumes and the boundary lines; the line under the button says where; the
    command that prints the same is last (design_panel.design_command)."""
    from playwright.sync_api import expect

    from spinectl.explore.design_panel import design_command

    base = load_preset()
    state = initial_state(base)
    tab = browser_tab.context.new_page()
    tab.set_default_timeout(browser_harness.TIMEOUT_S * 1000)
    try:
        tab.goto(served_url)
        chain = tab.locator("[data-verdict=chain]")
        expect(chain).to_have_text(nb.point_numbers(base, state).verdicts()[1])
        assert chain.bounding_box()["y"] + chain.bounding_box()["height"] < browser_harness.VIEWPORT["height"]
        answer = nb.design_numbers(base, state)  # the library's, at the same state
        rows = nb.design_rows(answer)
        tab.get_by_role("button", name=app.DESIGN_LABEL).click()
        tab.locator("[data-design=command]").wait_for()
        for key in ("headline", "joint_title", "joint", "chain_title", "chain"):
            shown = [_words(text) for text in tab.locator(f"[data-design={key}]").all_inner_texts()]
            assert shown == [_words(line) for line, _ in rows[key]], key
        table = tab.locator("[data-design=joint_table]").inner_text()
        assert table.splitlines() == [line for line, _ in rows["joint_table"]]
        assumed = [line for key in ("joint", "chain") for line, _ in rows[key] if line.startswith("reflex assumed:")]
        bounds = [line for key in ("joint", "chain") for line, _ in rows[key] if line.startswith("boundary:")]
        assert len(assumed) == 2 and len(bounds) == 2  # one each per criterion, in the library's answer
        page_text = _words(tab.locator(".spinectl-design").inner_text())
        assert all(_words(line) in page_text for line in assumed + bounds)
        assert tab.locator("[data-design=command]").inner_text() == design_command(state)
        expect(tab.get_by_text(f"design: status {answer.status}, {app.DESIGN_PLACE}")).to_be_visible()
    finally:
        tab.close()
