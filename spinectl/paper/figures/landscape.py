"""The landscape: any variable over E (abscissa) and Lambda (ordinate) as filled contours, A-D marked.

What every map of :mod:`spinectl.paper.figures` is drawn on: the filled contours on round levels
(or a given range) with a colour bar, labelled contour lines, positions A-D
(:data:`spinectl.paper.landmarks.FIGURE_POSITIONS`) where they lie inside the grid and the grid's
other corners by their coordinates, the paper's ridge Lambda = 1.7 E and its optimum.
"""

from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from ...canvas import new_figure
from ...errors import ParameterError
from ...units import CM_PER_M
from .. import landmarks
from .labels import _LINES, _label_lines
from .style import (
    COLOUR_BAR,
    EQUAL_ASPECT,
    FIGURE_SIZE,
    LEVELS,
    LINE_LEVELS,
    NICE_STEPS,
    TITLE_CHARS,
    _round_levels,
    _wrap,
    cm_text,
)

_TOLERANCE = 1e-9
"""[m] A position on a grid's edge counts as inside."""


LAMBDA_LABEL = "lordosis Λ [cm]"
"""The y label of every landscape, which ``FigureOptions(lordosis_axis='angle')`` ticks in degrees."""


def _axes(title: str, fig=None, spec=None):
    fig = fig or new_figure(figsize=FIGURE_SIZE, layout="constrained")
    ax = fig.add_subplot(spec) if spec is not None else fig.add_subplot()
    ax.set_xlabel("eccentricity E [cm]")
    ax.set_ylabel(LAMBDA_LABEL)
    ax.set_title(_wrap(title, TITLE_CHARS[spec is not None]), fontsize=9)  # wider, it crowded the top tick label
    return fig, ax


def _inside(position, e: np.ndarray, lam: np.ndarray) -> bool:
    x, y = position
    return e.min() - _TOLERANCE <= x <= e.max() + _TOLERANCE and lam.min() - _TOLERANCE <= y <= lam.max() + _TOLERANCE


def grid_marks(e: np.ndarray, lam: np.ndarray) -> list[tuple[str, tuple[float, float]]]:
    """The labelled points of a landscape: positions A-D inside the grid, and its corners that are none of them.

    Parameters
    ----------
    e, lam : numpy.ndarray
        The grid's E and Lambda axes [m].

    Returns
    -------
    list of (str, (float, float))
        Label and (E, Lambda) [m]: a letter for a position of
        :data:`spinectl.paper.landmarks.FIGURE_POSITIONS` inside the grid (C at Figure 3's
        interior point), "E, Λ = ... cm" for a corner of the grid that is none of them.
    """
    marks = [(name, p) for name, p in landmarks.FIGURE_POSITIONS.items() if _inside(p, e, lam)]
    for corner in ((e.min(), lam.min()), (e.max(), lam.min()), (e.max(), lam.max()), (e.min(), lam.max())):
        if not any(np.allclose(corner, p, atol=_TOLERANCE) for _, p in marks):
            marks.append((f"{cm_text(corner[0])}, {cm_text(corner[1])} cm", corner))
    return marks


def _mark_positions(ax, e: np.ndarray, lam: np.ndarray) -> None:
    """Positions A-D where they lie inside the grid, the grid's other corners by their coordinates.

    Each label sits on the side of its point that faces the middle of the grid, so it stays inside the axes.
    """
    middle = ((e.min() + e.max()) / 2, (lam.min() + lam.max()) / 2)
    for name, (x, y) in grid_marks(e, lam):
        right, up = x <= middle[0], y <= middle[1]
        ax.plot(x * CM_PER_M, y * CM_PER_M, "o", color="k", markersize=4, clip_on=False, gid=f"position {name}")
        ax.annotate(
            name,
            (x * CM_PER_M, y * CM_PER_M),
            xytext=(6 if right else -6, 6 if up else -6),
            textcoords="offset points",
            ha="left" if right else "right",
            va="bottom" if up else "top",
            fontweight="bold" if len(name) == 1 else "normal",
            fontsize=9 if len(name) == 1 else 7,
            bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "k", "lw": 0.5},
            gid=f"label {name}",
        )


def _mark_readings(ax, e: np.ndarray, lam: np.ndarray) -> None:
    """The paper's ridge Lambda = 1.7 E and its optimum (position C as its Discussion reads it), inside the grid."""
    lo, hi = max(e.min(), lam.min() / landmarks.RIDGE_SLOPE), min(e.max(), lam.max() / landmarks.RIDGE_SLOPE)
    if lo < hi:
        ridge_e = np.array([lo, hi])
        ax.plot(
            ridge_e * CM_PER_M,
            landmarks.RIDGE_SLOPE * ridge_e * CM_PER_M,
            color="white",
            lw=1.0,
            ls=(0, (4, 2)),
            label=f"Λ = {landmarks.RIDGE_SLOPE:g} E (the paper's ridge)",
            gid="ridge",
        )
    if _inside(landmarks.OPTIMUM, e, lam):
        ax.plot(
            *(np.array(landmarks.OPTIMUM) * CM_PER_M),
            "*",
            color="red",
            markersize=10,
            gid="optimum",
            label="C, the physiological situation (Figure 3's caption; Discussion: E ≈ 3, Λ ≈ 4 cm)",
        )
    handles, labels = ax.get_legend_handles_labels()
    if handles:  # below the figure, outside every axes: inside, it covered the label of D and the corner (8, 8) cm
        # grey, so that the white ridge line shows
        ax.figure.legend(handles, labels, loc="outside lower center", fontsize=7, facecolor="0.7", framealpha=1.0)


def _shape(ax, e: np.ndarray, lam: np.ndarray) -> None:
    """Limits at the grid; equal scales unless that would squeeze one axis (:data:`.style.EQUAL_ASPECT`)."""
    ax.set_xlim(e.min() * CM_PER_M, e.max() * CM_PER_M)
    ax.set_ylim(lam.min() * CM_PER_M, lam.max() * CM_PER_M)
    spans = np.ptp(e), np.ptp(lam)
    if min(spans) > 0 and max(spans) <= EQUAL_ASPECT * min(spans):
        ax.set_aspect("equal")


def _levels(values: np.ma.MaskedArray, vmin: float | None, vmax: float | None):
    """Filled levels: about LEVELS round steps over the data, or LEVELS steps over [vmin, vmax] (extended past it)."""
    if vmin is None and vmax is None:
        return _round_levels(values.min(), values.max(), LEVELS), "neither"
    low = values.min() if vmin is None else vmin
    high = values.max() if vmax is None else vmax
    if not high > low:
        raise ParameterError("--vmin/--vmax", f"need vmin < vmax (got {low:g} and {high:g})")
    extend = {(False, False): "neither", (True, False): "min", (False, True): "max", (True, True): "both"}
    return np.linspace(low, high, LEVELS + 1), extend[(bool(values.min() < low), bool(values.max() > high))]


def _landscape(
    field: xr.DataArray,
    title: str,
    label: str,
    vmin=None,
    vmax=None,
    fig=None,
    spec=None,
    label_lines=True,
    blank: str | None = None,
):
    """A filled contour of ``field`` (dims E, Lambda), contour lines labelled, A-D marked; returns (figure, axes).

    Infeasible points (NaN) stay white, and the title says how many there are (``blank``: the caller's
    line on what its white points are, instead). ``label_lines=False``
    leaves the lines' values to :func:`.labels._label_lines`, once everything else of the figure is drawn.
    """
    if field.sizes["E"] < 2 or field.sizes["Lambda"] < 2:  # a contour needs an area
        raise ParameterError(
            "grid",
            f"a landscape figure needs at least 2 values of E and 2 of Lambda (got {field.sizes['E']} x "
            f"{field.sizes['Lambda']})",
        )
    values = np.ma.masked_invalid(field.transpose("Lambda", "E").values)
    infeasible = int(values.mask.sum()) if np.ma.is_masked(values) else 0
    if infeasible:
        title += "\n" + (
            blank or f"white: no self-stable activation within the bounds ({infeasible} of {values.size} points)"
        )
    fig, ax = _axes(title, fig, spec)
    e_m, lam_m = field["E"].values, field["Lambda"].values
    e, lam = e_m * CM_PER_M, lam_m * CM_PER_M
    if infeasible < values.size:
        levels, extend = _levels(values, vmin, vmax)
        filled = ax.contourf(e, lam, values, levels=levels, cmap="viridis", extend=extend)
        bar = fig.colorbar(filled, cax=ax.inset_axes(COLOUR_BAR))  # as tall as the axes, not the figure
        bar.set_label(label)
        bar.locator = MaxNLocator(8, steps=NICE_STEPS)  # round ticks also on a given or shared range
        if values.max() > values.min():
            at = [v for v in _round_levels(values.min(), values.max(), LINE_LEVELS) if values.min() < v < values.max()]
            ax.contour(e, lam, values, levels=at or None, colors="k", linewidths=0.4, alpha=0.6, gid=_LINES)
    _shape(ax, e_m, lam_m)
    _mark_positions(ax, e_m, lam_m)
    _mark_readings(ax, e_m, lam_m)
    if label_lines:
        _label_lines(ax)
    return fig, ax


def landscape_figure(field: xr.DataArray, title: str, label: str, blank: str | None = None) -> Figure:
    """Any variable over E and Lambda drawn as the landscape figures are: filled contours, A-D marked.

    Parameters
    ----------
    field : xarray.DataArray
        Dimensions ``E`` and ``Lambda`` [m], at least 2 values each; NaN points stay white.
    title : str
        The figure's title.
    label : str
        The colour bar's label, with the unit.
    blank : str, optional
        The title's line on what the white (NaN) points are, if there are any; default: no self-stable
        activation, with their count.

    Returns
    -------
    matplotlib.figure.Figure
        Nothing is written.

    Raises
    ------
    ParameterError
        Fewer than 2 values of E or of Lambda (field ``grid``).
    """
    return _landscape(field, title, label, blank=blank)[0]
