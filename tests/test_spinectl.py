"""The top-level package: its API and its lazily imported subpackages."""

from __future__ import annotations

import os
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

import spinectl

ROOT = Path(__file__).resolve().parents[1]


def test_top_level_api_is_importable():
    """The top-level names of the README's Python example and the errors of CONTRIBUTING's rules."""
    for name in spinectl.__all__:
        assert getattr(spinectl, name) is not None
    promised = {"load_preset", "segment_stability", "SpinectlError", "Model", "loop_delay_margin"}
    assert promised <= set(spinectl.__all__)


def test_the_new_packages_need_no_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        from spinectl import optimise, reflex

    assert callable(optimise.solve_point) and callable(reflex.delay_margin)


def test_an_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'nonsense'"):
        spinectl.nonsense  # noqa: B018


def _python(code: str, *flags: str) -> subprocess.CompletedProcess:
    """``code`` in a fresh interpreter (the import system's caches start empty), this checkout first."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run([sys.executable, *flags, "-c", code], capture_output=True, text=True, env=env, check=False)


def test_the_subpackages_are_reachable_after_import_spinectl_and_imported_on_first_use():
    """``import spinectl`` then ``spinectl.paper``, ``.optimise``, ... (the README's inline API): each layer is an
    attribute, imported only when first used, so that ``import spinectl`` loads none but the two its own API comes
    from (model, reflex), nor cvxpy or xarray, and ``spinectl.explore`` loads no Panel (only its app module does)."""
    check = (
        "import sys, spinectl; names = spinectl.SUBPACKAGES\n"
        "lazy = {f'spinectl.{n}' for n in names if n not in ('model', 'reflex')}\n"
        "assert not lazy & set(sys.modules), sorted(lazy & set(sys.modules))\n"
        "assert not {'cvxpy', 'xarray', 'matplotlib'} & set(sys.modules)\n"
        "assert set(names) <= set(dir(spinectl))\n"
        "assert callable(spinectl.paper.reproduce) and callable(spinectl.optimise.solve_point)\n"
        "assert spinectl.landscape.__name__ == 'spinectl.landscape' and spinectl.explore.point_numbers\n"
        "assert 'panel' not in sys.modules\n"
    )
    done = _python(check, "-W", "error::DeprecationWarning")
    assert done.returncode == 0, done.stderr
