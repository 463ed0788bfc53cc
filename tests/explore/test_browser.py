"""End to end in a real browser: ``spinectl explore`` served on a free loopback port, driven by headless Chromium.

Playwright's Python API drives the system's Chromium (Debian's ``chromium`` package,
installed by ``scripts/setup`` and ``.ci/run``; no browser is downloaded). The test moves
the E slider and clicks a landscape, and checks that the table and the model drawing
become those the library computes for the new point (:func:`spinectl.explore.numbers.point_numbers`,
:func:`spinectl.explore.app.drawing_png`, byte for byte).

Without Chromium the test fails with a message saying how to install it; a developer
without it can set ``SPINECTL_SKIP_BROWSER=1`` (CI never does).
"""

from __future__ import annotations

import base64
import os
import re
import shutil
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

from spinectl.explore import app
from spinectl.explore import numbers as nb
from spinectl.explore.state import from_shown, initial_state, replace, slider_for
from spinectl.model.config import load_preset

ROOT = Path(__file__).resolve().parents[2]
CHROMIUM = os.environ.get("SPINECTL_CHROMIUM", "/usr/bin/chromium")
OPT_OUT = "SPINECTL_SKIP_BROWSER"
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]
TIMEOUT_MS = 90_000
"""Longest wait for the app (first page: imports and the first solve, on a loaded 2-core machine)."""


def _chromium() -> str:
    if os.environ.get(OPT_OUT):
        pytest.skip(f"{OPT_OUT} is set")
    path = shutil.which(CHROMIUM)
    if path is None:
        pytest.fail(
            f"the browser test needs Chromium at {CHROMIUM}: run scripts/setup (or apt-get install -y chromium), "
            f"or set SPINECTL_CHROMIUM to a Chromium binary; {OPT_OUT}=1 skips this test"
        )
    return path


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def server():
    """``python -m spinectl explore`` from this checkout on a free loopback port; stopped afterwards."""
    port = _free_port()
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}
    argv = [sys.executable, "-m", "spinectl", "explore", "--no-browser", "--port", str(port)]
    process = subprocess.Popen(argv, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    url = f"http://127.0.0.1:{port}/"
    deadline = time.monotonic() + TIMEOUT_MS / 1000
    try:
        while True:
            if process.poll() is not None:
                pytest.fail(f"spinectl explore exited with {process.returncode}: {process.stdout.read()}")
            try:
                urllib.request.urlopen(url, timeout=5).close()
                break
            except OSError:
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.3)
        yield url
    finally:
        process.terminate()
        try:
            process.wait(timeout=20)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


@pytest.fixture(scope="module")
def page(server):
    from playwright.sync_api import sync_playwright  # imported here: collecting the suite needs no browser

    executable = _chromium()
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=executable, args=CHROMIUM_ARGS)
        tab = browser.new_page(viewport={"width": 1440, "height": 1000})
        tab.set_default_timeout(TIMEOUT_MS)
        tab.goto(server)
        tab.wait_for_selector("td[data-key=counter_torque_Nm]")
        yield tab
        browser.close()


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


def _drawing(page) -> bytes:
    """The PNG of the model drawing, the widest image of the page."""
    sources = [s for s in page.locator("img").evaluate_all("els => els.map(e => e.src)") if "image/png" in s]
    return base64.b64decode(max(sources, key=len).split(",", 1)[1])


def _shown(page, label: str) -> float:
    """A slider's value as its label shows it, e.g. 'E [cm]: 3.60' -> 3.6."""
    text = page.get_by_text(re.compile("^" + re.escape(label) + ":")).first.inner_text()
    return float(text.split(":")[1])


def _expect(page, state):
    """Wait until the table shows the numbers of ``state``; then they, and the drawing, must be the library's."""
    from playwright.sync_api import expect

    expected = nb.point_numbers(load_preset("default"), state)
    first = expected.rows()[0]["counter_torque_Nm"]
    expect(page.locator("td[data-key=counter_torque_Nm]").first).to_have_text(first, timeout=TIMEOUT_MS)
    assert _table(page) == expected.rows()
    assert _drawing(page) == app.drawing_png(expected)


def test_slider_and_click_move_the_point_to_the_librarys_numbers(page):
    """Start: the README's point; drag E: the numbers and the drawing of the new E; click the minimum-PCSA
    landscape: those of the clicked point (both read back from the sliders' labels)."""
    state = initial_state(load_preset("default"))
    assert _table(page) == nb.point_numbers(load_preset("default"), state).rows()
    assert _drawing(page) == app.drawing_png(nb.point_numbers(load_preset("default"), state))

    handle = page.locator(".noUi-handle").first  # the first slider is E
    box = handle.bounding_box()
    x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    page.mouse.move(x, y)
    page.mouse.down()
    page.mouse.move(x + 40, y, steps=5)
    page.mouse.up()
    moved = _point_shown(page, state, lambda point: point[0] != state.eccentricity)
    assert moved.eccentricity > state.eccentricity and moved.lordosis == state.lordosis
    _expect(page, moved)

    landscape = page.locator(".bk-Canvas").first.bounding_box()  # the minimum-PCSA landscape
    page.mouse.click(landscape["x"] + 0.3 * landscape["width"], landscape["y"] + 0.25 * landscape["height"])
    clicked = _point_shown(page, moved, lambda point: point[1] != moved.lordosis)
    assert clicked.eccentricity < moved.eccentricity and clicked.lordosis > moved.lordosis  # left of it, higher
    _expect(page, clicked)


def _point_shown(page, state, changed):
    """``state`` at the (E, Lambda) the sliders' labels show, once ``changed((E, Lambda))`` holds [m]."""
    fields = ("eccentricity", "lordosis")
    deadline = time.monotonic() + TIMEOUT_MS / 1000
    while True:
        point = tuple(from_shown(slider_for(f), _shown(page, slider_for(f).label)) for f in fields)
        if changed(point) or time.monotonic() > deadline:
            return replace(state, **dict(zip(fields, point, strict=True)))
        time.sleep(0.2)
