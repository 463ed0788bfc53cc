"""Fixtures of the explorer's tests: one ``spinectl explore`` server for every test that needs a served app."""

from __future__ import annotations

import browser_harness
import pytest


@pytest.fixture(scope="session")
def served_log() -> list[str]:
    """The output of the server of :func:`served_url`, line by line, as it comes."""
    return []


@pytest.fixture(scope="session")
def served_url(served_log) -> str:
    """The URL of ``spinectl explore`` served from this checkout on a free loopback port (preset default).

    Up to 64 sessions: each test opens pages of its own, more than the default 8 within the 15 s a page's
    session outlives it (the bound itself: tests/explore/test_served.py, on a server of its own).
    """
    with browser_harness.served("--max-sessions", "64", log=served_log) as url:
        yield url
