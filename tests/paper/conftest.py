"""Fixtures of the paper's tests: the wagner2012 preset's landscapes on the paper's grid, solved once per session."""

from __future__ import annotations

import pytest

from spinectl.model import config
from spinectl.paper import grid, verdicts


@pytest.fixture(scope="session")
def wagner2012_landscapes():
    """K = 0 and K = 15 N m/rad (both conventions) of wagner2012 on the paper's 81 x 81 grid (a few seconds)."""
    preset = config.load_preset(verdicts.PRESET)
    return grid.paper_landscapes(preset, grid.PAPER_POINTS, progress=False)
