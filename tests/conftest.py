"""Shared fixtures of the spinectl test suite."""

from __future__ import annotations

import numpy as np
import pytest

from spinectl.params import Geometry, Model, MusclePair


@pytest.fixture
def model() -> Model:
    """The built-in default model (dataclass defaults = preset 'default')."""
    return Model()


@pytest.fixture
def rng() -> np.random.Generator:
    """A seeded generator so that 'random' configurations are repeatable."""
    return np.random.default_rng(20120313)


@pytest.fixture
def vertical_model() -> Model:
    """One pair of single vertical fibres at x = +-d, for closed-form checks.

    Fibres run from (+-0.12, 0.24) to (+-0.12, 0.0); CoRs are the paper's.
    """
    return Model(muscles=(MusclePair("straight", (0.12, 0.24), (0.12, 0.0), 0.0, 1),), geometry=Geometry())
