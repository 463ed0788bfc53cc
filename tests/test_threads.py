"""spinectl._threads: one BLAS thread inside the CLI and the design functions, unless the user chose a number."""

from __future__ import annotations

import numpy as np
import pytest
from threadpoolctl import threadpool_info, threadpool_limits

from spinectl import _threads
from spinectl.cli import main


def _blas_threads() -> list[int]:
    return [lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas"]


@pytest.fixture
def no_choice(monkeypatch):
    """No thread count in the environment, and two BLAS threads to start from (the suite runs with one)."""
    for name in _threads.CHOICE_VARIABLES:
        monkeypatch.delenv(name, raising=False)
    with threadpool_limits(limits=2, user_api="blas"):
        yield


def test_one_thread_inside_and_restored_after(no_choice):
    """threadpoolctl's own report: 1 thread per BLAS inside the block, the process's number again after.

    The fixture starts from two threads, so the first check fails without the limit on any machine.
    """
    before = _blas_threads()
    assert 2 in before, "a BLAS is loaded at the fixture's two threads (a single-threaded build stays at 1)"
    with _threads.one_blas_thread():
        assert _blas_threads() == [1] * len(before)
    assert _blas_threads() == before


def test_a_users_choice_is_kept(monkeypatch):
    """OPENBLAS_NUM_THREADS set: the block changes nothing (the user's number stands)."""
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "2")
    with threadpool_limits(limits=2, user_api="blas"):
        before = _blas_threads()
        with _threads.one_blas_thread():
            assert _blas_threads() == before and 2 in before


class _Seen(Exception):
    """Stops a function once the threads inside it are recorded."""


def test_the_cli_and_the_design_run_with_one_thread(no_choice, monkeypatch):
    """A command runs inside the limit (main wraps it), and so does the design's curve (its decorator)."""
    from spinectl.cli import config_cmd
    from spinectl.model import config
    from spinectl.reflex import design
    from spinectl.reflex.design import curve

    seen = []

    def record(*args, **kwargs):
        seen.append(set(_blas_threads()))
        raise _Seen

    monkeypatch.setattr(config_cmd, "_presets", record)
    with pytest.raises(_Seen):
        main(["config", "presets"])
    monkeypatch.setattr(curve, "_curve_at_lag", record)
    with pytest.raises(_Seen):
        design.delay_curve(config.load_preset("default"), 0.03, 0.04, np.array([0.1]))
    assert seen == [{1}, {1}]
