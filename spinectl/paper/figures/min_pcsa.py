"""Figures 3 (K = 0) and S1 (K > 0): the minimum PCSA for self-stability, optionally with the corner insets.

With the insets the model is drawn at the grid's four corners (:mod:`spinectl.paper.drawing`),
each with its chosen activation, as the paper's small corner panels around Figure 3.
"""

from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.figure import Figure

from ...canvas import new_figure
from ...landscape import netcdf
from ...units import M2_PER_CM2
from .. import drawing
from .labels import _label_lines
from .landscape import _TOLERANCE, _landscape, grid_marks
from .style import _k_label, cm_text

INSET_FIGURE_SIZE = (8.4, 8.0)
"""Inches, Figure 3 with the model drawn at its four corners."""


def min_pcsa_figure(
    dataset: xr.Dataset, vmin: float | None = None, vmax: float | None = None, insets: bool = False
) -> Figure:
    """Figure 3 (K = 0) or S1 (K > 0): minimum PCSA for self-stability of every segment.

    Parameters
    ----------
    dataset : xarray.Dataset
        One landscape (scalar K).
    vmin, vmax : float, optional
        Colour range [cm²]; default the data's.
    insets : bool
        The model drawn at the grid's four corners (:func:`spinectl.paper.drawing.draw_model`),
        the fibres' widths the chosen activation there (the paper's small corner panels).

    Returns
    -------
    matplotlib.figure.Figure
        Filled contours over E and Lambda [cm]; nothing is written.

    Raises
    ------
    ParameterError
        ``vmin`` not below ``vmax``.
    """
    name = "Fig. 3" if float(dataset["K"]) == 0 else "Fig. S1"
    title = f"{name}: minimum PCSA for self-stability, {_k_label(dataset)}"
    if not insets:
        fig, _ = _landscape(dataset["min_pcsa_cm2"], title, "minimum PCSA [cm²]", vmin, vmax)
        return fig
    fig = new_figure(figsize=INSET_FIGURE_SIZE, layout="constrained")
    spec = fig.add_gridspec(3, 3, width_ratios=(1, 2.4, 1), height_ratios=(1, 2.4, 1))
    _, ax = _landscape(dataset["min_pcsa_cm2"], title, "minimum PCSA [cm²]", vmin, vmax, fig, spec[1, 1], False)
    _draw_corners(fig, spec, dataset)
    _label_lines(ax)  # after the corners: the layout they change decides where the labels fall
    return fig


def _draw_corners(fig, spec, dataset: xr.Dataset) -> None:
    """The model at each corner of the grid, in the figure's corner cells, with its chosen activation."""
    model = netcdf.model_of(dataset)
    e, lam = dataset["E"].values, dataset["Lambda"].values
    labels = {p: name for name, p in grid_marks(e, lam)}
    cells = {(0, 0): (2, 0), (1, 0): (2, 2), (1, 1): (0, 2), (0, 1): (0, 0)}
    for (i, j), (row, col) in cells.items():
        position = ((e.min(), e.max())[i], (lam.min(), lam.max())[j])
        pcsa = dataset["pcsa_cm2"].sel(E=position[0], Lambda=position[1], method="nearest").values * M2_PER_CM2
        ax = fig.add_subplot(spec[row, col])
        drawing.draw_model(model, *position, pcsa=pcsa if np.all(np.isfinite(pcsa)) else None, ax=ax, annotate=False)
        label = next(name for p, name in labels.items() if np.allclose(p, position, atol=_TOLERANCE))
        coordinates = f"E = {cm_text(position[0])}, Λ = {cm_text(position[1])} cm"
        ax.set_title(coordinates if label[0].isdigit() else f"{label}: {coordinates}", fontsize=7)
