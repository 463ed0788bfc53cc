"""Shared fixtures of the spinectl test suite."""

from __future__ import annotations

import os
import tempfile

import numpy as np
import pytest
from hypothesis import settings

from spinectl.model.params import Geometry, Model, MusclePair

settings.register_profile("repeatable", derandomize=True, database=None, print_blob=True)
settings.register_profile("explore", derandomize=False, print_blob=True)
settings.load_profile(os.environ.get("SPINECTL_HYPOTHESIS", "repeatable"))

# The anatomy layer caches compiled MuJoCo models (docs/anatomy.md, "Speed"): the suite, and the commands it
# runs as subprocesses, keep theirs in a folder of their own, never in the user's cache.
os.environ.setdefault("SPINECTL_CACHE_DIR", tempfile.mkdtemp(prefix="spinectl-test-cache-"))
# The README's test command (and CI) draws the same examples on every run, so a
# merge is never blocked by a random new find; SPINECTL_HYPOTHESIS=explore draws
# fresh ones and keeps failures in .hypothesis/ (CONTRIBUTING.md, "Commands").


@pytest.fixture(autouse=True, scope="session")
def _one_blas_thread():
    """The library's calls in the tests run as the commands run them, with one BLAS thread (spinectl._threads):
    a multi-threaded BLAS may round differently, and tests compare a command's output with the library's bit
    for bit. tests/test_threads.py raises the threads itself to check the limit."""
    from spinectl._threads import one_blas_thread

    with one_blas_thread():
        yield


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
