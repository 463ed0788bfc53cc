"""The interactive explorer (``spinectl explore``): the model at one point, live, in a browser.

docs/explore.md; the modules: CONTRIBUTING.md's map. The Panel app (:mod:`~spinectl.explore.app`) is
imported only where Panel is installed (``pip install 'spinectl[explore]'``).
"""

import importlib

_HOMES = {
    "PointNumbers": "numbers",
    "landscapes": "numbers",
    "point_numbers": "numbers",
    "SLIDERS": "state",
    "ExploreState": "state",
    "initial_state": "state",
    "model_at": "state",
    "state_toml": "state",
}
"""Where each re-exported name lives: imported on first use (PEP 562), so that the command line's parser,
which reads :mod:`~spinectl.explore.hosts` for ``--max-sessions``, does not import the numbers' solvers."""


def __getattr__(name: str):
    """A name of :data:`__all__`, from its module on first use."""
    if name not in _HOMES:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f"{__name__}.{_HOMES[name]}"), name)


__all__ = [
    "SLIDERS",
    "ExploreState",
    "PointNumbers",
    "initial_state",
    "landscapes",
    "model_at",
    "point_numbers",
    "state_toml",
]
