"""The Examples sections of the main public functions run and print what their docstrings say.

Each module below is run with :mod:`doctest` (the numbers printed are rounded, so that the last
digit of a platform's arithmetic does not decide). A module whose examples need an optional extra
is skipped, with the reason, where that extra is not installed. The list is explicit, not every
module of the package: a doctest run imports the module, and the extras' modules stay optional.
"""

from __future__ import annotations

import doctest
import importlib

import pytest

MODULES = {
    "spinectl.landscape.atlas": ("SALib",),
    "spinectl.model.config": (),
    "spinectl.model.chain": (),
    "spinectl.model.contributions": (),
    "spinectl.model.operating_point": (),
    "spinectl.model.stability": (),
    "spinectl.optimise.reference": ("cvxpy",),
    "spinectl.optimise.stabilising": (),
    "spinectl.reflex.delay.margin": (),
    "spinectl.reflex.siso": ("control",),
    "spinectl.reflex.mimo": (),
    "spinectl.reflex.design.curve": (),
}
"""Module -> the optional modules its examples import (skipped with a reason where one is missing)."""


@pytest.mark.parametrize("name", sorted(MODULES))
def test_the_examples_of_a_module_run(name):
    """Every example of the module runs and prints what it says; at least one example is there to run."""
    for extra in MODULES[name]:
        pytest.importorskip(extra, reason=f"{name}'s examples need {extra} (an optional extra)")
    module = importlib.import_module(name)
    flags = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE
    found = doctest.testmod(module, optionflags=flags, verbose=False, report=True)
    assert found.attempted > 0, f"{name} has no examples"
    assert found.failed == 0, f"{found.failed} of {found.attempted} examples of {name} failed (printed above)"
