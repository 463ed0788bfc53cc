"""Fixtures of the explorer's tests: one ``spinectl explore`` server for every test that needs a served app."""

from __future__ import annotations

import browser_harness
import pytest


@pytest.fixture(scope="session")
def served_url() -> str:
    """The URL of ``spinectl explore`` served from this checkout on a free loopback port (preset default)."""
    with browser_harness.served() as url:
        yield url
