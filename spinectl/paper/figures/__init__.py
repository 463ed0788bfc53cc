"""The paper's figures from a sweep Dataset: Figures 3, 4 and S1, the ratio S1 / 3 and coupled / per segment.

Filled contours over E and Lambda [cm] on any grid, positions A-D, the ridge Lambda = 1.7 E and the
optimum marked (docs/figures.md). Each figure function draws on a new Agg figure
(:func:`spinectl.canvas.new_figure`) and returns it, writing nothing;
:func:`~spinectl.paper.figures.files.save_figure` writes one atomically,
:func:`~spinectl.paper.figures.sets.draw_figures` a set as a whole. One module per figure family
(CONTRIBUTING.md's map), every public name re-exported here.
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
