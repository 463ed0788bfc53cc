"""The interactive explorer (``spinectl explore``): the model at one point, live, in a browser.

docs/explore.md. The explorer's state (E, Lambda, mass, K, reflex delay, activation
and its lag; :mod:`~spinectl.explore.state`), the numbers each view shows, computed
as pure functions of that state (:mod:`~spinectl.explore.numbers`), the views' data
and the views drawn with matplotlib for a PNG export (:mod:`~spinectl.explore.views`),
and the Panel app itself, whose Bokeh views show the same data (:mod:`~spinectl.explore.app`,
imported only where Panel is installed: ``pip install 'spinectl[explore]'``).
"""

from .numbers import PointNumbers, landscapes, point_numbers
from .state import SLIDERS, ExploreState, initial_state, model_at, state_toml

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
