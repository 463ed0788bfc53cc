"""The paper's figures from a sweep Dataset: Figures 3, 4 and S1, the ratio S1 / 3 and coupled / per segment.

Filled contours over E (abscissa) and Lambda (ordinate), both in cm, on any
grid: labelled contour lines, positions A-D (:data:`spinectl.paper.grid.POSITIONS`)
where they lie inside the grid and the grid's other corners by their
coordinates, the paper's ridge Lambda = 1.7 E and its optimum (E ~ 3, Lambda ~ 4 cm,
which its Discussion calls position C, beside the corner C). Figure 4 adds the
+-30 N m limit of the local muscles as a contour; Figure 3 optionally the model
drawn at the grid's corners (:mod:`spinectl.paper.drawing`), as the paper's corner panels.
Each figure function draws on a new figure with the Agg
canvas (:func:`spinectl.canvas.new_figure`: no global backend state, no display
needed) and returns it, writing nothing; :func:`~spinectl.paper.figures.files.save_figure`
writes one atomically as PNG, PDF or SVG, :func:`~spinectl.paper.figures.sets.figure_set`
draws the set (:class:`~spinectl.paper.figures.sets.FigureOptions`: format, colour range,
shared scale, ratio map, insets) and :func:`~spinectl.paper.figures.sets.draw_figures` saves
it as a whole.

One module per figure family, on the shared parts below them:

- :mod:`~spinectl.paper.figures.style`: what every landscape shares (size, levels, colour bar, titles);
- :mod:`~spinectl.paper.figures.labels`: labels placed clear of each other on the laid-out canvas;
- :mod:`~spinectl.paper.figures.landscape`: any variable over E x Lambda, A-D, the ridge and the optimum marked;
- :mod:`~spinectl.paper.figures.min_pcsa`: Figures 3 and S1, with the corner insets;
- :mod:`~spinectl.paper.figures.counter_torque`: Figure 4 and the ±30 N m limit;
- :mod:`~spinectl.paper.figures.ratios`: the ratio maps, S1 / 3 and coupled / per segment;
- :mod:`~spinectl.paper.figures.pareto`: the coupled chain's Pareto front;
- :mod:`~spinectl.paper.figures.files`: the save step (PNG, PDF, SVG), resolutions and file names;
- :mod:`~spinectl.paper.figures.sets`: the figures of a landscape as a set, drawn and saved all or none.

Every public name of these modules is also here: ``spinectl.paper.figures.draw_figures``
as before the split.
"""

from __future__ import annotations

from .counter_torque import counter_torque_figure, torque_limit
from .files import (
    DPI,
    FORMATS,
    MAX_DPI,
    MIN_DPI,
    check_dpi,
    coupled_ratio_name,
    figure_names,
    k_in_name,
    ratio_name,
    save_figure,
)
from .labels import LABEL_MARGIN, OFFSETS
from .landscape import grid_marks, landscape_figure
from .min_pcsa import INSET_FIGURE_SIZE, min_pcsa_figure
from .pareto import pareto_figure
from .ratios import COUPLED_VARIABLE, HALVING, RATIO_MARKS, coupled_ratio, coupled_ratio_figure, ratio_figure
from .sets import LORDOSIS_AXES, FigureOptions, angle_ticks, draw_figures, figure_set
from .style import (
    COLOUR_BAR,
    EQUAL_ASPECT,
    FIGURE_SIZE,
    LEVELS,
    LINE_LEVELS,
    NICE_STEPS,
    TITLE_CHARS,
    _wrap,  # noqa: F401  (tests check the title wrapping directly)
    k_unit,
)

__all__ = [
    "COLOUR_BAR",
    "COUPLED_VARIABLE",
    "DPI",
    "EQUAL_ASPECT",
    "FIGURE_SIZE",
    "FORMATS",
    "HALVING",
    "INSET_FIGURE_SIZE",
    "LABEL_MARGIN",
    "LEVELS",
    "LINE_LEVELS",
    "MAX_DPI",
    "MIN_DPI",
    "NICE_STEPS",
    "OFFSETS",
    "RATIO_MARKS",
    "TITLE_CHARS",
    "FigureOptions",
    "LORDOSIS_AXES",
    "angle_ticks",
    "check_dpi",
    "counter_torque_figure",
    "coupled_ratio",
    "coupled_ratio_figure",
    "coupled_ratio_name",
    "draw_figures",
    "figure_names",
    "figure_set",
    "grid_marks",
    "k_in_name",
    "k_unit",
    "landscape_figure",
    "min_pcsa_figure",
    "pareto_figure",
    "ratio_figure",
    "ratio_name",
    "save_figure",
    "torque_limit",
]
