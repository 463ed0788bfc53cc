"""The explorer served from this checkout and a headless Chromium page on it: for the browser test and
``scripts/explore_screenshot.py``.

Playwright's Python API drives the system's Chromium (Debian's ``chromium`` package,
installed by ``scripts/setup``); nothing downloads a browser.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import socket
import subprocess
import sys
import threading
import time
import urllib.request
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
CHROMIUM = os.environ.get("SPINECTL_CHROMIUM", "/usr/bin/chromium")
"""The Chromium binary (Debian's package installs it here)."""
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
TIMEOUT_S = 180.0
"""Longest wait for the app (the first page: imports and the first solves; 90 s were too few on a 2-core
machine at a load average of 9)."""
VIEWPORT = {"width": 1440, "height": 960}
INSTALL = "run scripts/setup (or apt-get install -y chromium), or set SPINECTL_CHROMIUM to a Chromium binary"


def chromium() -> str | None:
    """The path of the Chromium binary, or None if there is none."""
    return shutil.which(CHROMIUM)


def free_port(address: str = "127.0.0.1", family: int = socket.AF_INET) -> int:
    """A TCP port free on the loopback interface (``address``) just now."""
    with socket.socket(family) as s:
        s.bind((address, 0))
        return s.getsockname()[1]


@contextlib.contextmanager
def served(*options: str, address: str = "127.0.0.1", log: list[str] | None = None):
    """``python -m spinectl explore --no-browser`` from this checkout on a free port of ``address`` (a loopback
    one); yields its URL. Its output (standard output and error) is read as it comes, line by line into ``log``
    if given (the sessions it opens and ends, the requests it refuses), so that it never fills the pipe."""
    family = socket.AF_INET6 if ":" in address else socket.AF_INET
    port = free_port(address, family)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}
    argv = [sys.executable, "-m", "spinectl", "explore", "--no-browser", "--port", str(port), "--address", address]
    process = subprocess.Popen(
        [*argv, *options], cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True
    )
    lines = [] if log is None else log
    reader = threading.Thread(target=_read_lines, args=(process.stdout, lines), daemon=True)
    reader.start()
    url = f"http://[{address}]:{port}/" if family == socket.AF_INET6 else f"http://{address}:{port}/"
    deadline = time.monotonic() + TIMEOUT_S
    try:
        while True:
            if process.poll() is not None:
                reader.join(timeout=5)
                raise RuntimeError(f"spinectl explore exited with {process.returncode}: {''.join(lines)}")
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
        reader.join(timeout=5)


def _read_lines(stream, lines: list[str]) -> None:
    for line in stream:  # one at a time, so that a test sees each line as it comes
        lines.append(line)


def wait_for_line(log: list[str], text: str, start: int = 0) -> int:
    """Wait until a line of ``log`` from index ``start`` on holds ``text``; its index (AssertionError after
    :data:`TIMEOUT_S`)."""
    deadline = time.monotonic() + TIMEOUT_S
    while True:
        found = [i for i in range(start, len(log)) if text in log[i]]
        if found:
            return found[0]
        assert time.monotonic() < deadline, f"no line with {text!r} in the server's output: {log[start:]}"
        time.sleep(0.1)


@contextlib.contextmanager
def opened(url: str, executable: str):
    """A headless Chromium page at ``url``, once the numbers table is shown."""
    with browser_page(executable) as page:
        page.goto(url)
        page.wait_for_selector("td[data-key=counter_torque_Nm]")
        yield page


@contextlib.contextmanager
def browser_page(executable: str, *args: str):
    """A blank page of a headless Chromium started with :data:`CHROMIUM_ARGS` and ``args``."""
    from playwright.sync_api import sync_playwright  # imported here: collecting the tests needs no browser

    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=executable, args=[*CHROMIUM_ARGS, *args])
        try:
            page = browser.new_context(viewport=VIEWPORT).new_page()  # a context of its own: more pages can open in it
            page.set_default_timeout(TIMEOUT_S * 1000)
            yield page
        finally:
            browser.close()
