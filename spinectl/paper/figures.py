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
needed) and returns it, writing nothing; :func:`save_figure` writes one
atomically as PNG, PDF or SVG, :func:`figure_set` draws the set (:class:`FigureOptions`:
format, colour range, shared scale, ratio map, insets) and :func:`draw_figures` saves it
as a whole.
"""

from __future__ import annotations

import re
import textwrap
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from ..canvas import laid_out, new_figure, save_figures, save_file
from ..errors import ParameterError
from ..landscape import netcdf
from ..model.chain import local_stiffness_per_pcsa
from ..model.params import Model
from ..model.source import stiffness_unit
from ..optimise.coupled import ParetoFront
from ..units import CM_PER_M, M2_PER_CM2
from . import drawing, grid, landmarks

FIGURE_SIZE = (6.4, 5.2)
"""Inches."""
INSET_FIGURE_SIZE = (8.4, 8.0)
"""Inches, Figure 3 with the model drawn at its four corners."""
DPI = 150
MIN_DPI, MAX_DPI = 10, 1200
"""Resolutions [dots per inch] that :func:`save_figure` accepts: legible, and an image of tens of megapixels at most."""
FORMATS = ("png", "pdf", "svg")
"""File formats of :func:`save_figure`, named by the file's suffix."""
LEVELS = 16
"""Number of filled contour levels."""
EQUAL_ASPECT = 2.0
"""E and Lambda share one scale unless one axis spans more than this many times the other."""
HALVING = 0.5
"""The paper's ratio of minimum PCSA with and without K = 15 N m/rad (Additional file 1: "halves")."""
LABEL_MARGIN = 0.08
"""Least distance of a placed contour label from the axes' edges, as a fraction of their span."""
_TOLERANCE = 1e-9
"""[m] A position on a grid's edge counts as inside."""
NICE_STEPS = (1, 2, 5, 10)
"""Steps of round contour levels and colour-bar ticks (matplotlib's MaxNLocator ``steps``)."""
LINE_LEVELS = 6
"""At most about this many labelled contour lines (round values) on a landscape."""
TITLE_CHARS = 56, 46
"""Characters a title line holds at fontsize 9: on the landscape axes (about 4 in wide) and on those of
Figure 3 with the model drawn at its corners (about 3.4 in)."""
_LINES = "contour lines"
"""gid of a landscape's labelled contour lines."""

_CONVENTION = {"paper": "eq. 2 as printed", "physical": "physical, -K in dM/dα"}
"""How a title names the passive-stiffness convention (docs/model.md, "Passive stiffness: two conventions")."""


@dataclass(frozen=True)
class FigureOptions:
    """How :func:`draw_figures` draws and saves.

    Attributes
    ----------
    format : str
        One of :data:`FORMATS`.
    dpi : float
        Resolution of PNG files [dots per inch].
    vmin, vmax : float, optional
        Colour range of the minimum-PCSA figures [cm²]; default each figure's own.
    shared_scale : bool
        Figures 3 and S1 on one colour scale, the range over every K.
    ratio : bool
        Also the map of minimum PCSA at K > 0 over K = 0 (the paper's "halving").
    insets : bool
        The model drawn at the grid's four corners around Figure 3 and S1.
    """

    format: str = "png"
    dpi: float = DPI
    vmin: float | None = None
    vmax: float | None = None
    shared_scale: bool = False
    ratio: bool = False
    insets: bool = False

    def __post_init__(self):
        if self.format not in FORMATS:
            raise ParameterError("--format", f"must be one of {', '.join(FORMATS)} (got {self.format!r})")
        check_dpi(self.dpi)


def check_dpi(dpi: float) -> None:
    """Raise :class:`~spinectl.errors.ParameterError` unless ``dpi`` is a resolution matplotlib can render.

    Parameters
    ----------
    dpi : float
        Dots per inch: finite, 10 to :data:`MAX_DPI`.
    """
    if not (np.isfinite(dpi) and MIN_DPI <= dpi <= MAX_DPI):
        raise ParameterError("--dpi", f"must be {MIN_DPI} to {MAX_DPI} dots per inch (got {dpi:g})")


COLOUR_BAR = (1.03, 0.0, 0.045, 1.0)
"""Left, bottom, width, height of a landscape's colour bar in its axes' coordinates: beside them, as tall."""


def _axes(title: str, fig=None, spec=None):
    fig = fig or new_figure(figsize=FIGURE_SIZE, layout="constrained")
    ax = fig.add_subplot(spec) if spec is not None else fig.add_subplot()
    ax.set_xlabel("eccentricity E [cm]")
    ax.set_ylabel("lordosis Λ [cm]")
    ax.set_title(_wrap(title, TITLE_CHARS[spec is not None]), fontsize=9)  # wider, it crowded the top tick label
    return fig, ax


_UNBROKEN = re.compile(r"\([^()\n]{1,40}\)|(?:[\w.]+ = )?[\d.]+ (?:N m(?:/rad)?|1/s²|kg|cm|m|s)\b|N m/rad|N m")
"""Spans a title line is not broken inside: a short parenthesis, a setting with its value and unit, a unit."""


def _wrap(title: str, width: int) -> str:
    """``title`` broken into lines of at most ``width`` characters, its own line breaks kept, never inside a
    value with its unit or a short parenthesis (:data:`_UNBROKEN`; "K = 0 N / m/rad" read oddly)."""

    def glued(match):
        return match.group(0).replace(" ", "\u00a0")

    lines = (textwrap.fill(_UNBROKEN.sub(glued, line), width, break_long_words=False) for line in title.split("\n"))
    return "\n".join(lines).replace("\u00a0", " ")


def _round_levels(low: float, high: float, count: int) -> np.ndarray:
    """About ``count`` round values (steps of :data:`NICE_STEPS` times a power of ten) from ``low`` to ``high``."""
    return MaxNLocator(count, steps=NICE_STEPS).tick_values(low, high)


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
            marks.append((f"{corner[0] * CM_PER_M:g}, {corner[1] * CM_PER_M:g} cm", corner))
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
    """Limits at the grid; equal scales unless that would squeeze one axis (:data:`EQUAL_ASPECT`)."""
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
    leaves the lines' values to :func:`_label_lines`, once everything else of the figure is drawn.
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


def _label_lines(ax) -> None:
    """Each contour line's value, clear of the labels of A-D and the corners as drawn.

    matplotlib places a value where its line is straight enough, blind to other artists: the 20 cm²
    of Figure 3 (K = 0) lay under B's label. So, as for the ±30 N m label (:func:`_label_place`), the
    places are measured on the canvas after the layout (the labels' offsets are in points, the lines
    in data units that the layout scales): a value whose box meets a mark's label, or is cut by the
    axes' edge, moves along its own line to the nearest vertex where it is whole and meets no mark's
    label and no other value, or is left out.
    """
    lines = next((c for c in ax.collections if c.get_gid() == _LINES), None)
    if lines is None:
        return
    renderer = laid_out(ax.figure)  # the layout sizes the axes
    pad = renderer.points_to_pixels(2.0)  # their boxes' padding (0.2 of a 9 pt font) lies outside a text's extent
    labels = (t for t in ax.texts if (t.get_gid() or "").startswith("label"))  # A-D and the corners
    marks = [t.get_window_extent(renderer).padded(pad) for t in labels]
    ax.clabel(lines, fmt="%.3g", fontsize=6, inline=False)  # matplotlib's places, to be checked
    frame = ax.get_window_extent(renderer)
    places, boxes = [], []
    for text in list(lines.labelTexts):
        place = text.get_position()
        if not _clear(text.get_window_extent(renderer), marks, frame):
            place = _clear_place(lines, place, marks + boxes, frame, renderer)
        if place is not None:
            places.append(place)
            boxes.append(_label_box(lines, *place, renderer))
    while lines.labelTexts:
        lines.pop_label()
    for text in ax.clabel(lines, fmt="%.3g", fontsize=6, manual=places):  # the lines broken where labelled
        text.set_clip_on(True)  # a label near the edge is cut, never drawn outside the axes


def _clear(box, others, frame) -> bool:
    """``box`` inside ``frame`` (not cut by the axes' edge) and meeting none of ``others`` (window extents)."""
    inside = frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0 and box.y1 <= frame.y1
    return inside and not any(box.overlaps(other) for other in others)


def _label_box(lines, x: float, y: float, renderer):
    """The window extent of a value label at the point of ``lines`` nearest (x, y) [cm], as clabel draws it."""
    lines.add_label_near(x, y, inline=False)
    box = lines.labelTexts[-1].get_window_extent(renderer)
    lines.pop_label()
    return box


def _clear_place(lines, start, keep_clear, frame, renderer, tries: int = 60):
    """The vertex of the line through ``start`` [cm] nearest it whose value label meets nothing of ``keep_clear``
    and lies inside ``frame``, away from the axes' edges (:data:`LABEL_MARGIN`); None if none does within
    ``tries`` vertices. The same connected line only: matplotlib labels each of a level's lines once."""
    segments = [segment for level in lines.allsegs for segment in level if len(segment)]
    vertices = min(segments, key=lambda v: np.linalg.norm(v - np.asarray(start), axis=1).min())
    ax = lines.axes
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    scaled = (vertices - (x0, y0)) / (x1 - x0, y1 - y0)
    vertices = vertices[np.all((scaled >= LABEL_MARGIN) & (scaled <= 1 - LABEL_MARGIN), axis=1)]
    order = np.argsort(np.linalg.norm(vertices - np.asarray(start), axis=1))
    for x, y in vertices[order][:: max(1, len(order) // tries)]:
        if _clear(_label_box(lines, x, y, renderer), keep_clear, frame):
            return float(x), float(y)
    return None


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


def k_unit(convention: str) -> str:
    """The unit of K under a ``passive.convention`` as a figure writes it (``N m/rad``, ``1/s²``).

    Parameters
    ----------
    convention : str
        ``"physical"`` or ``"paper"`` (a landscape's ``passive_convention`` attribute).

    Returns
    -------
    str
        :func:`spinectl.model.source.stiffness_unit` with a superscript square.
    """
    return stiffness_unit(convention).replace("^2", "²")


def _k_label(dataset: xr.Dataset) -> str:
    stiffness = float(dataset["K"])
    if stiffness == 0:
        return "K = 0"
    convention = dataset.attrs.get("passive_convention", "?")
    return f"K = {stiffness:g} {k_unit(convention)} (K convention: {_CONVENTION.get(convention, convention)})"


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
        coordinates = f"E = {position[0] * CM_PER_M:g}, Λ = {position[1] * CM_PER_M:g} cm"
        ax.set_title(coordinates if label[0].isdigit() else f"{label}: {coordinates}", fontsize=7)


def ratio_figure(dataset: xr.Dataset, stiffness: float = grid.PAPER_STIFFNESS) -> Figure:
    """Minimum PCSA at K = ``stiffness`` over that at K = 0: the paper's "halving" (Additional file 1) as a map.

    Parameters
    ----------
    dataset : xarray.Dataset
        With a K dimension holding 0 and ``stiffness``
        (:func:`~spinectl.landscape.sweep.stiffness_sweep`).
    stiffness : float
        K [N m/rad] of the numerator.

    Returns
    -------
    matplotlib.figure.Figure
        Filled contours of the ratio [1] on round levels over its range, over E and Lambda [cm], labelled contour
        lines; the paper's 0.5 and 1 (equal) as white contours where the ratio reaches them;
        white where either landscape is infeasible or the K = 0 minimum is 0.

    Raises
    ------
    ParameterError
        ``dataset`` lacks K = 0 or K = ``stiffness``.
    """
    if "K" not in dataset.dims or not {0.0, float(stiffness)} <= {float(k) for k in dataset["K"].values}:
        raise ParameterError("K", f"the ratio map needs landscapes at K = 0 and K = {stiffness:g} N m/rad")
    pcsa = dataset["min_pcsa_cm2"]
    base = pcsa.sel(K=0.0)
    ratio = (pcsa.sel(K=float(stiffness)) / base).where(base > 0)
    part = dataset.sel(K=float(stiffness))
    title = f"Fig. S1 / Fig. 3: minimum PCSA at {_k_label(part)}\nover that at K = 0 (the paper: 0.5, a halving)"
    return _ratio_map(ratio, title, "ratio of minimum PCSA [1]")


RATIO_MARKS = {HALVING: f"{HALVING:g}: halved", 1.0: "1: equal"}
"""The ratios a ratio map marks, with their labels: the paper's halving and no change."""


def _ratio_map(ratio: xr.DataArray, title: str, label: str) -> Figure:
    """A ratio over E and Lambda on round levels over its range; each of :data:`RATIO_MARKS` inside that range a
    labelled white contour and a white line on the colour bar, the others named in the title as not reached."""
    values = np.ma.masked_invalid(ratio.transpose("Lambda", "E").values)
    inside = {v: text for v, text in RATIO_MARKS.items() if values.count() and values.min() < v < values.max()}
    if values.count():
        outside = [text.split(":")[0] for v, text in RATIO_MARKS.items() if v not in inside]
        if outside:
            title += f"\n(range {values.min():.2f} to {values.max():.2f}: {' and '.join(outside)} not reached)"
    fig, ax = _landscape(ratio, title, label)
    e, lam = ratio["E"].values * CM_PER_M, ratio["Lambda"].values * CM_PER_M
    for level, text in inside.items():
        line = ax.contour(e, lam, values, levels=[level], colors="white", linewidths=1.5)
        ax.clabel(line, fmt=lambda _, text=text: text, fontsize=8)
        ax.child_axes[0].axhline(level, color="white", lw=1.5, gid=f"ratio {level:g}")
    return fig


COUPLED_VARIABLE = "joint_global_pcsa_cm2"
"""The sweep variable (``sweep --coupled``) whose presence draws :func:`coupled_ratio_figure`."""


def coupled_ratio(dataset: xr.Dataset) -> xr.DataArray:
    """Global PCSA of the coupled chain's joint optimum over the per-segment minimum PCSA, over E x Lambda.

    The joint optimum (docs/chain.md) stabilises the coupled chain with global and local
    muscle together; the per-segment minimum (paper, Figure 3) needs each segment stable on
    global muscle alone. Below 1, the local muscles and the coupling take over part of the
    global muscles' work.

    Parameters
    ----------
    dataset : xarray.Dataset
        A sweep with ``joint_global_pcsa_cm2`` and ``min_pcsa_cm2`` (``spinectl sweep --coupled``),
        dims (E, Lambda[, K]).

    Returns
    -------
    xarray.DataArray
        The ratio [1], same dims; NaN where either is infeasible or the per-segment minimum is 0.

    Raises
    ------
    ParameterError
        ``dataset`` lacks ``joint_global_pcsa_cm2``.
    """
    if COUPLED_VARIABLE not in dataset:
        raise ParameterError("dataset", f"the coupled ratio needs {COUPLED_VARIABLE} (spinectl sweep --coupled)")
    per_segment = dataset["min_pcsa_cm2"]
    return (dataset[COUPLED_VARIABLE] / per_segment).where(per_segment > 0).rename("coupled_ratio")


def coupled_ratio_figure(dataset: xr.Dataset) -> Figure:
    """:func:`coupled_ratio` as a map: the coupled chain's global PCSA over the per-segment minimum.

    Parameters
    ----------
    dataset : xarray.Dataset
        As for :func:`coupled_ratio`, with a scalar K.

    Returns
    -------
    matplotlib.figure.Figure
        Filled contours of the ratio [1] over E and Lambda [cm] on round levels over its range, labelled contour
        lines; 0.5 and 1 (no saving) as white contours where the ratio reaches them.

    Raises
    ------
    ParameterError
        As :func:`coupled_ratio`.
    """
    ratio = coupled_ratio(dataset)
    title = f"coupled / per segment: global PCSA of the joint optimum over the minimum PCSA, {_k_label(dataset)}"
    return _ratio_map(ratio, title, "ratio of global PCSA [1]")


def counter_torque_figure(dataset: xr.Dataset, specific_tension: float) -> Figure:
    """Figure 4: ||CT|| at the chosen activation, the +-30 N m limit and the paper's optimum.

    The colour bar's label converts ||CT|| into the PCSA of a local muscle
    with the paper's 7 cm lever arm.

    Parameters
    ----------
    dataset : xarray.Dataset
        One landscape (scalar K).
    specific_tension : float
        f_iso per PCSA [N/m^2].

    Returns
    -------
    matplotlib.figure.Figure
        Filled contours over E and Lambda [cm]; nothing is written.
    """
    title = f"Fig. 4: local counter torques ‖CT‖, {_k_label(dataset)}"
    field = dataset["counter_torque_norm_Nm"]
    limit_pcsa = landmarks.local_pcsa_equivalent(landmarks.CT_LIMIT, specific_tension) / M2_PER_CM2
    label = (
        f"‖CT‖ [N m]\n({landmarks.CT_LIMIT:g} N m = {limit_pcsa:.0f} cm² of local muscle "
        f"at {landmarks.LOCAL_LEVER_ARM * CM_PER_M:g} cm lever arm)"
    )
    fig, ax = _landscape(field, title, label)
    torque_limit(ax, field)
    return fig


def torque_limit(ax, field: xr.DataArray) -> None:
    """The ±30 N m limit of the local muscles (paper, Figure 4) as a dashed white contour on a landscape of ‖CT‖.

    Its label keeps clear of A-D, the corners, C's star, the ridge and the other contour labels
    (:func:`_label_place`); C's label moves to a side of its point off the line. Nothing is drawn
    where ‖CT‖ does not cross the limit.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The axes of :func:`landscape_figure` of ``field``.
    field : xarray.DataArray
        ‖CT‖ [N m], dimensions ``E`` and ``Lambda`` [m].
    """
    e, lam = field["E"].values * CM_PER_M, field["Lambda"].values * CM_PER_M
    values = np.ma.masked_invalid(field.transpose("Lambda", "E").values)
    if values.count() and values.min() < landmarks.CT_LIMIT < values.max():
        limit = ax.contour(e, lam, values, levels=[landmarks.CT_LIMIT], colors="white", linestyles="--")
        _clear_of(ax, "label C", limit)
        marks = [np.asarray(p) * CM_PER_M for _, p in grid_marks(field["E"].values, field["Lambda"].values)]
        contour_labels = [t.get_position() for t in ax.texts if not t.get_gid()]  # the lines' values
        ridge = [line for line in ax.lines if line.get_gid() == "ridge"]  # on it, the label hid the ridge
        along = np.linspace(0.0, 1.0, 40)[:, None]
        ridge = [p for line in ridge for p in (1 - along) * line.get_xydata()[0] + along * line.get_xydata()[-1]]
        optimum = np.asarray(landmarks.OPTIMUM) * CM_PER_M
        place = _label_place(limit, [*marks, optimum, *contour_labels, *ridge], ax)
        text = f"±{landmarks.CT_LIMIT:g} N m"
        ax.clabel(limit, fmt=lambda _: text, fontsize=8, manual=None if place is None else [place])


OFFSETS = ((6, 6), (-6, 6), (6, -6), (-6, -6))
"""Offsets [points] of a position's label from its point, in the order tried: right and up first."""


def _clear_of(ax, gid: str, contour) -> None:
    """Move the label ``gid`` of a position to the first side of its point (:data:`OFFSETS`) where its box
    neither touches ``contour`` nor leaves the axes; where none is, it stays. Measured on the laid-out canvas."""
    label = next((t for t in ax.texts if t.get_gid() == gid), None)
    if label is None:
        return
    renderer = laid_out(ax.figure)  # the layout first: the label's offset is in points, the line in data
    paths = [ax.transData.transform_path(p) for p in contour.get_paths()]
    frame = ax.get_window_extent(renderer)
    first = label.xyann
    for dx, dy in (first, *OFFSETS, first):  # none clear: back where it was
        label.set(position=(dx, dy), ha="left" if dx > 0 else "right", va="bottom" if dy > 0 else "top")
        box = label.get_window_extent(renderer).padded(3)  # the round box around the text
        inside = frame.contains(box.x0, box.y0) and frame.contains(box.x1, box.y1)
        if inside and not any(p.intersects_bbox(box, filled=False) for p in paths):
            return


def _label_place(contour, marks, ax) -> tuple[float, float] | None:
    """Where a contour's one label goes [cm]: its vertex farthest from every mark (A-D, the corners, C's star,
    the other contour lines' labels).

    matplotlib's own choice can fall on C, which the ±30 N m line passes close by. Distances are measured
    in fractions of the axes' spans; vertices within :data:`LABEL_MARGIN` of the edges are skipped (the
    label would be cut). None if no vertex qualifies (matplotlib's choice then).

    Parameters
    ----------
    contour : matplotlib.contour.QuadContourSet
        A contour of one level.
    marks : list of (float, float)
        Points to keep clear of [cm].
    ax : matplotlib.axes.Axes
        The axes, their limits set.

    Returns
    -------
    (float, float) or None
        (E, Lambda) [cm] of the label.
    """
    vertices = np.concatenate([s for s in contour.allsegs[0] if len(s)] or [np.empty((0, 2))])
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    span = np.array([x1 - x0, y1 - y0])
    scaled = (vertices - (x0, y0)) / span
    inside = np.all((scaled >= LABEL_MARGIN) & (scaled <= 1 - LABEL_MARGIN), axis=1)
    if not inside.any():
        return None
    points = (np.array(marks, float).reshape(-1, 2) - (x0, y0)) / span
    distance = np.linalg.norm(scaled[inside, None, :] - points[None], axis=-1).min(axis=1)
    return tuple(float(c) for c in vertices[inside][np.argmax(distance)])


def pareto_figure(front: ParetoFront, model: Model) -> Figure:
    """The Pareto front of the chain: global PCSA total against local stiffness total (docs/chain.md).

    One marker per point of :func:`spinectl.optimise.coupled.joint.pareto_front`; infeasible
    points are left out, the global-only point (budget 0), where it exists, is ringed; the top
    axis reads the local stiffness as local-muscle PCSA (:func:`spinectl.model.chain.local_pcsa`).

    Parameters
    ----------
    front : ParetoFront
        The computed front.
    model : Model
        The model it was computed with (``local``: kappa for the top axis).

    Returns
    -------
    matplotlib.figure.Figure
        Nothing is written.
    """
    fig = new_figure(figsize=FIGURE_SIZE, layout="constrained")
    ax = fig.add_subplot()
    ok = np.array([p.ok for p in front.points])
    local, global_ = front.local_total[ok], front.global_total[ok] / M2_PER_CM2
    ax.plot(local, global_, "o-", color="C0", label="least global PCSA within the budget")
    if ok[0]:
        ax.plot(local[:1], global_[:1], "o", mfc="none", ms=12, color="C3", label="global muscles only")
    ax.set_xlabel("local stiffness total Σk [N m/rad]")
    ax.set_ylabel("global PCSA total [cm²]")
    ax.set_title(
        f"Pareto front, E = {front.eccentricity * CM_PER_M:.1f} cm, Λ = {front.lordosis * CM_PER_M:.1f} cm", fontsize=9
    )
    ax.legend(fontsize=7)
    per_cm2 = local_stiffness_per_pcsa(model) * M2_PER_CM2  # kappa [N m/rad per cm^2]: A = k / kappa
    top = ax.secondary_xaxis("top", functions=(lambda k: k / per_cm2, lambda a: a * per_cm2))
    top.set_xlabel("local-muscle PCSA total [cm²]")
    return fig


def save_figure(fig: Figure, path: str | Path, dpi: float = DPI) -> Path:
    """The save step: write ``fig`` atomically (:func:`spinectl.atomic.atomic_path`), its format named by the suffix.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        A figure of this module or of :mod:`spinectl.paper.drawing`.
    path : str or Path
        The file: ``.png``, ``.pdf`` or ``.svg`` (:data:`FORMATS`).
    dpi : float
        Resolution of a PNG [dots per inch]; default :data:`DPI`.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ParameterError
        Another suffix, or ``dpi`` out of range (:func:`check_dpi`).
    OutputError
        The file cannot be written; a previous file of that name is left as it was.
    """
    check_dpi(dpi)
    suffix = Path(path).suffix.lower().lstrip(".")
    if suffix not in FORMATS:
        raise ParameterError("--out", f"must end in .png, .pdf or .svg (got {str(path)!r})")
    return save_file(fig, path, dpi)


def figure_names(stiffness: float, format: str = "png") -> tuple[str, str]:
    """File names of the minimum-PCSA and counter-torque figures.

    Parameters
    ----------
    stiffness : float
        Passive stiffness K [N m/rad]; 0 gives Figures 3 and 4, else S1 and 4 with K in the name.
    format : str
        The suffix, one of :data:`FORMATS`.

    Returns
    -------
    tuple of str
        The names of the minimum-PCSA and the counter-torque figure: K short (``K15``)
        where that reads back as K, else every digit of K (``K15.000001``), so that
        distinct stiffnesses never share a file.
    """
    if stiffness == 0:
        return f"fig3_min_pcsa.{format}", f"fig4_counter_torque.{format}"
    k = k_in_name(stiffness)
    return f"figS1_min_pcsa_K{k}.{format}", f"fig4_counter_torque_K{k}.{format}"


def k_in_name(stiffness: float) -> str:
    """K as file names write it: short where that reads back as K, else every digit.

    Parameters
    ----------
    stiffness : float
        K [N m/rad].

    Returns
    -------
    str
        E.g. ``"15"``, or ``"15.000000000000002"``.
    """
    short = f"{stiffness:g}"
    return short if float(short) == stiffness else repr(float(stiffness))


def ratio_name(stiffness: float, format: str = "png") -> str:
    """File name of :func:`ratio_figure`.

    Parameters
    ----------
    stiffness : float
        K [N m/rad] of the numerator.
    format : str
        The suffix, one of :data:`FORMATS`.

    Returns
    -------
    str
        E.g. ``figS1_over_fig3_K15.png``.
    """
    return f"figS1_over_fig3_K{k_in_name(stiffness)}.{format}"


def coupled_ratio_name(stiffness: float, format: str = "png") -> str:
    """File name of :func:`coupled_ratio_figure`.

    Parameters
    ----------
    stiffness : float
        K [N m/rad].
    format : str
        File format and extension.

    Returns
    -------
    str
        E.g. ``coupled_over_per_segment_K0.png``.
    """
    return f"coupled_over_per_segment_K{k_in_name(stiffness)}.{format}"


def _pcsa_range(dataset: xr.Dataset, options: FigureOptions) -> tuple[float | None, float | None]:
    """The colour range of the minimum-PCSA figures: the options', else with shared_scale that over every K."""
    vmin, vmax = options.vmin, options.vmax
    if options.shared_scale:
        values = dataset["min_pcsa_cm2"].values
        if np.isfinite(values).any():
            vmin = float(np.nanmin(values)) if vmin is None else vmin
            vmax = float(np.nanmax(values)) if vmax is None else vmax
    return vmin, vmax


def _ratio_stiffnesses(dataset: xr.Dataset) -> list[float]:
    """The K > 0 of a dataset that also holds K = 0; checked before anything is drawn."""
    stiffnesses = [float(k) for k in np.atleast_1d(dataset["K"].values)]
    if "K" not in dataset.dims or 0.0 not in stiffnesses or max(stiffnesses) <= 0:
        raise ParameterError("--ratio", "needs a landscape with K = 0 and a K > 0 (spinectl sweep --K 0,15)")
    return [k for k in stiffnesses if k > 0]


def figure_set(
    dataset: xr.Dataset, specific_tension: float | None = None, options: FigureOptions | None = None
) -> dict[str, Figure]:
    """Figures 3 and 4 for every K of ``dataset`` (Figure S1 for K > 0), by file name; nothing written.

    Parameters
    ----------
    dataset : xarray.Dataset
        From :func:`~spinectl.landscape.sweep.sweep` (scalar K) or
        :func:`~spinectl.landscape.sweep.stiffness_sweep` (a K dimension).
    specific_tension : float, optional
        f_iso per PCSA [N/m^2], for the local-PCSA scale of Figure 4; default: that of
        the model the dataset was computed with (:func:`spinectl.landscape.netcdf.model_of`).
    options : FigureOptions, optional
        Format, resolution, colour range, ratio map, insets; default PNG at :data:`DPI`.

    Returns
    -------
    dict of str to matplotlib.figure.Figure
        :func:`figure_names` of each K -> its figure, K in the dataset's order.

    Raises
    ------
    ConfigError, ParameterError
        ``specific_tension`` not given and the dataset's ``config_toml`` is not a valid model.
    """
    options = options or FigureOptions()
    if specific_tension is None:
        specific_tension = netcdf.model_of(dataset).fibre.specific_tension
    parts = [dataset.sel(K=k) for k in dataset["K"].values] if "K" in dataset.dims else [dataset]
    vmin, vmax = _pcsa_range(dataset, options)
    stiffnesses = _ratio_stiffnesses(dataset) if options.ratio else []
    drawn = {}
    for part in parts:
        pcsa_name, ct_name = figure_names(float(part["K"]), options.format)
        drawn[pcsa_name] = min_pcsa_figure(part, vmin, vmax, options.insets)
        drawn[ct_name] = counter_torque_figure(part, specific_tension)
        if COUPLED_VARIABLE in part:
            drawn[coupled_ratio_name(float(part["K"]), options.format)] = coupled_ratio_figure(part)
    for k in stiffnesses:
        drawn[ratio_name(k, options.format)] = ratio_figure(dataset, k)
    return drawn


def draw_figures(
    dataset: xr.Dataset,
    out_dir: str | Path,
    specific_tension: float | None = None,
    options: FigureOptions | None = None,
) -> list[Path]:
    """Draw :func:`figure_set` and save it into ``out_dir``: all or none (:func:`spinectl.canvas.save_figures`).

    Parameters
    ----------
    dataset : xarray.Dataset
        As for :func:`figure_set`.
    out_dir : str or Path
        Folder for the files (created if missing), named by :func:`figure_names` (and
        :func:`ratio_name`); its other files are kept.
    specific_tension : float, optional
        As for :func:`figure_set`.
    options : FigureOptions, optional
        As for :func:`figure_set`; its ``dpi`` is the resolution of PNG files.

    Returns
    -------
    list of Path
        The files written.

    Raises
    ------
    ConfigError, ParameterError
        ``specific_tension`` not given and the dataset's ``config_toml`` is not a valid model;
        a bad colour range, or the ratio map without K = 0 and a K > 0; fewer than 2 values
        of E or of Lambda (field ``grid``), before any file is written.
    OutputError
        ``out_dir`` cannot take the files; nothing is written.
    """
    options = options or FigureOptions()
    return save_figures(figure_set(dataset, specific_tension, options), out_dir, options.dpi)
