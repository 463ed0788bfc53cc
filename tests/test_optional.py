"""spinectl._optional.require_module: the one import of an optional extra's module."""

from __future__ import annotations

import json
import sys

import pytest

from spinectl._optional import require_module
from spinectl.errors import SpinectlError


class Missing(SpinectlError):
    """An extra's own kind of error, as AnatomyUnavailable or AtlasUnavailable."""


def test_an_installed_module_is_returned():
    assert require_module("json", Missing, "unused") is json


def test_a_missing_module_is_the_callers_error_with_its_one_line(monkeypatch):
    """A module blocked in sys.modules (as the extras' tests block mujoco, opensim, panel), or one that does not
    exist: the caller's SpinectlError kind with its message, and no ImportError chained to it."""
    monkeypatch.setitem(sys.modules, "json", None)
    for name in ("json", "spinectl_no_such_extra"):
        with pytest.raises(Missing, match="needs the extra: pip install") as caught:
            require_module(name, Missing, "this needs the extra: pip install 'spinectl[x]'")
        assert caught.value.__cause__ is None and caught.value.__suppress_context__
