"""The top-level package: its API, and spinectl 0.1's module names kept for one release with a warning."""

from __future__ import annotations

import importlib
import re
import warnings

import pytest

import spinectl


def test_top_level_api_is_importable():
    for name in spinectl.__all__:
        assert getattr(spinectl, name) is not None


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
