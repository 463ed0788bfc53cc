"""The interactive explorer (``spinectl explore``): the model at one point, live, in a browser.

docs/explore.md. The explorer's state (E, Lambda, mass, K, reflex delay, activation
and its lag; :mod:`~spinectl.explore.state`), the numbers each view shows, computed
as pure functions of that state (:mod:`~spinectl.explore.numbers`), the views' data
and the views drawn with matplotlib for a PNG export (:mod:`~spinectl.explore.views`),
and the Panel app itself, whose Bokeh views show the same data (:mod:`~spinectl.explore.app`,
imported only where Panel is installed: ``pip install 'spinectl[explore]'``).
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
