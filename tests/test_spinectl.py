"""The top-level package: its API, and spinectl 0.1's module names kept for one release with a warning."""

from __future__ import annotations

import importlib
import os
import re
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
    promised = {"load_preset", "segment_stability", "SpinectlError", "Model", "delay_margin"}
    assert promised <= set(spinectl.__all__)


@pytest.mark.parametrize(("old", "new"), sorted(spinectl.MOVED.items()))
def test_old_module_names_warn_and_give_the_new_module(old, new):
    message = re.escape(f"spinectl.{old} has moved to {new}")
    with pytest.warns(DeprecationWarning, match=message):
        module = getattr(spinectl, old)
    assert module is importlib.import_module(new)


def test_from_import_of_an_old_name_works():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(DeprecationWarning):
            from spinectl import sweep  # noqa: F401
    with pytest.warns(DeprecationWarning):
        from spinectl import sweep
    assert sweep.sweep is importlib.import_module("spinectl.landscape.sweep").sweep


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


@pytest.mark.parametrize(
    ("statement", "new"),
    [
        ("import spinectl.sweep as m", "spinectl.landscape.sweep"),
        ("from spinectl.config import load_preset as m", "spinectl.model.config"),
        ("from spinectl.study.spec import Study as m", "spinectl.landscape.study.spec"),
        ("import spinectl.calibration.fit as m", "spinectl.paper.calibration.fit"),
    ],
)
def test_import_statements_of_old_names_give_the_new_module_with_a_warning(statement, new):
    """0.1's import statements: the same objects as the new module's (one module, not a second copy
    loaded under the old name), and a DeprecationWarning naming the new module."""
    check = f"{statement}; import sys, importlib; n = importlib.import_module('{new}')"
    check += "; assert m is n or getattr(n, m.__name__, None) is m, m"
    ok = _python(check, "-W", "ignore::DeprecationWarning")
    assert ok.returncode == 0, ok.stderr
    warned = _python(statement, "-W", "error::DeprecationWarning")
    assert warned.returncode != 0 and f"has moved to {new.rsplit('.', 1)[0]}" in warned.stderr


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
