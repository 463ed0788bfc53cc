"""The model drawn: spine line, centres of rotation, vertebrae, muscle fibres, point mass.

The planar model of the paper's Figure 2 at one (E, Lambda), in cm, every point
taken from :mod:`spinectl.model.geometry` (docs/model.md, "Geometry" and "The
muscles"): the spline through P2, P3, P1 with the five CoRs labelled, the
vertebral bodies as quadrilaterals along the line, the symmetry axis x = 0, E
and Lambda dimensioned, every fibre from its upper to its lower attachment
(colour: the pair; solid: ventral, dashed: dorsal; width proportional to its
muscle's PCSA when an activation is given), the point mass with its vertical
line of gravity, and optionally the local counter torque CT_k at each CoR.

Artists carry a ``gid`` (:data:`GIDS`) so that a caller can find them again;
:func:`draw_model` draws into given Axes (the corner insets of Figure 3) or on a
new figure (:func:`spinectl.canvas.new_figure`), and writes nothing.
"""

from __future__ import annotations

import dataclasses
import re

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Polygon
from matplotlib.transforms import Bbox

from ..canvas import laid_out, new_figure
from ..errors import ParameterError
from ..model import geometry
from ..model.checks import expand_pcsa
from ..model.params import Model
from ..model.stability import segment_stability
from ..optimise.reference import solve_point
from ..units import CM_PER_M, m2_to_cm2

FIGURE_SIZE = (5.6, 6.4)
"""Inches."""
PAIR_COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:purple", "tab:brown", "tab:pink")
"""Colour of each muscle pair, in the order of ``model.muscles`` (cycled)."""
SIDE_ALPHA = (1.0, 0.45)
"""Opacity of the ventral (side 0) and the dorsal (side 1) muscle of a pair: the dorsal one paler."""
MAX_WIDTH = 4.0
"""Line width [pt] of the fibres of the muscle with the largest PCSA."""
IDLE_WIDTH = 0.6
"""Line width [pt] of every fibre without an activation, and of an idle muscle (dotted)."""
MIN_WIDTH = 0.3
"""Least line width [pt] of an active muscle, so that a small PCSA stays visible."""
IDLE_FRACTION = 1e-3
"""A muscle whose PCSA is below this fraction of the largest is drawn idle (the optimiser's zeros are ~1e-16)."""
VERTEBRA_WIDTH = 0.035
"""Depth of a vertebral body in the drawing [m] (a lumbar body is about 3.5 cm deep; a sketch only)."""
VERTEBRA_FILL = 0.7
"""Fraction of the height between two CoRs that a vertebral body fills (the rest is the disc)."""
TORQUE_SCALE = 0.002
"""Length of a counter-torque arrow per N m [m/(N m)]: 10 N m are drawn as 2 cm."""

TORQUE_RISE = 0.006
"""Height [m] of a counter-torque arrow's arc above its chord, a quarter of a chord at most: the same for
every torque, so that a long arrow bends as a short one does and its arc stays clear of the labels above it."""
LINE_SAMPLES = 101
"""Points of the drawn spine line."""

_LABEL_BOX = {"boxstyle": "round,pad=0.1", "fc": "white", "ec": "none", "alpha": 0.8}

GIDS = {
    "spine": "spine line",
    "cor": "centres of rotation",
    "spline": "spline points P2 P3 P1",
    "mass": "point mass",
    "gravity": "line of gravity",
    "axis": "symmetry axis",
    "chord": "chord P1 P2",
}
"""The ``gid`` of each single artist; fibres are ``"fibre <muscle> <i>"``, vertebrae ``"vertebra <name>"``,
counter torques ``"counter torque <CoR>"`` and their labels ``"counter torque label <CoR>"``, the CoRs' labels
``"cor label <CoR>"``, the spline points' labels ``"point label P1"`` (P3, P2), dimensions ``"dimension E"``
and ``"dimension Lambda"``."""
TORQUE_LABEL_OFFSET = 3.0
"""Gap [pt] between a counter torque's label and the outermost thing drawn at its height on its arrow's
side: the arrow's tip, a vertebra, the CoR's label, the label of P1, P3 or P2 (:func:`_beyond`). Above
each arrow's middle (before) a label touched a vertebra and the label of P3."""
COR_LABEL_OFFSET = 4.0
"""Gap [pt] between a CoR's label, right of its CoR where its arrow points left, and the CoR or the label of
P1, P3 or P2 at its height (:func:`_label_cors`)."""
TORQUE_LABEL_BAND = 6.0
"""Half the height [pt] of the band about a CoR whose artists a torque label must clear: half its
6 pt line and box, and a point to spare."""


def _line_geometry(model: Model, heights):
    heights = tuple(float(h) for h in heights)
    return dataclasses.replace(
        model.geometry, cor_heights=heights, cor_names=tuple(f"y{i}" for i in range(len(heights)))
    )


def spine_line(model: Model, eccentricity: float, lordosis: float, samples: int = LINE_SAMPLES) -> np.ndarray:
    """Points of the spine line from P1 (top) to P2 (bottom) [m].

    The spline of :func:`spinectl.model.geometry.cor_positions` evaluated at ``samples``
    heights instead of the CoR heights (docs/model.md, "The spine line").

    Parameters
    ----------
    model : Model
        Supplies the geometry (spine length, spline end conditions).
    eccentricity, lordosis : float
        E and Lambda [m].
    samples : int
        Number of points, at least 2.

    Returns
    -------
    numpy.ndarray, shape (samples, 2)
        (x, y) [m], y decreasing from the spine length to 0.
    """
    heights = np.linspace(model.geometry.spine_length, 0.0, samples)
    return geometry.cor_positions(eccentricity, lordosis, _line_geometry(model, heights))


def _vertebrae(model: Model, eccentricity: float, lordosis: float) -> list[tuple[str, np.ndarray]]:
    """One rectangle per vertebral body between consecutive CoRs (and above the top CoR up to P1).

    Centred on the spine line halfway between its two joints, tilted along the line's chord there,
    VERTEBRA_FILL of the gap high and VERTEBRA_WIDTH deep.
    """
    edges = (model.geometry.spine_length, *model.geometry.cor_heights)
    bodies = []
    for name, top, bottom in zip(model.geometry.cor_names, edges[:-1], edges[1:], strict=True):
        middle, half = (top + bottom) / 2, VERTEBRA_FILL * (top - bottom) / 2
        upper, centre, lower = geometry.cor_positions(
            eccentricity, lordosis, _line_geometry(model, (middle + half, middle, middle - half))
        )
        along = (upper - lower) / 2
        across = np.array([along[1], -along[0]]) / np.linalg.norm(along) * VERTEBRA_WIDTH / 2
        corners = [centre + along - across, centre + along + across, centre - along + across, centre - along - across]
        bodies.append((_upper_vertebra(name), np.array(corners)))
    return bodies


def _upper_vertebra(cor_name: str) -> str:
    """The vertebra above a joint: "L1" for "L1L2", "L5" for "L5S1"; else "above <name>"."""
    match = re.match(r"[A-Z]+\d+", cor_name)
    return match.group(0) if match else f"above {cor_name}"


def activation(
    model: Model, eccentricity: float, lordosis: float, pcsa=None, slip_check: bool = True
) -> tuple[np.ndarray | None, np.ndarray | None, str]:
    """The PCSA and counter torques to draw, and a phrase that says where they come from.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    pcsa : None, "optimum" or array_like
        None: no activation; ``"optimum"``: the chosen activation of
        :func:`spinectl.optimise.reference.solve_point`; else PCSA [m^2] per pair or per muscle
        (:func:`spinectl.model.checks.expand_pcsa`).
    slip_check : bool
        True (the default): PCSA values above :data:`spinectl.model.checks.MAX_PLAUSIBLE_PCSA` are refused
        as cm^2 typed where m^2 are meant; False: their unit is checked (``--pcsa``, in cm^2), any size is drawn.

    Returns
    -------
    pcsa : numpy.ndarray, shape (n_muscles,), or None
        PCSA of each muscle [m^2]; None without an activation or where the optimum is infeasible.
    counter_torque : numpy.ndarray, shape (n_cor,), or None
        CT_k [N m] at that activation (paper, Methods, Stability analysis and calculation of counter torques).
    source : str
        E.g. ``"activation: the optimum (solve_point), 35.1 cm²"``.
    """
    if pcsa is None:
        return None, None, "no activation: geometry only"
    if isinstance(pcsa, str):
        if pcsa != "optimum":
            raise ParameterError("pcsa", f"must be None, 'optimum' or PCSA values (got {pcsa!r})")
        best = solve_point(model, eccentricity, lordosis)
        if not best.ok:
            return None, None, f"optimum: none (status {best.status}); geometry only"
        return (
            best.pcsa,
            best.counter_torque,
            f"activation: the optimum (solve_point), {_cm2(best.pcsa.sum())} cm² in all",
        )
    per_muscle = expand_pcsa(model, pcsa, given=slip_check)
    result = segment_stability(model, eccentricity, lordosis, per_muscle, given=slip_check)
    return result.pcsa, result.counter_torque, f"activation: given, {_cm2(per_muscle.sum())} cm² in all"


def _cm2(area: float) -> str:
    return f"{m2_to_cm2(area):.3g}"


def _widths(pcsa: np.ndarray | None, n_muscles: int) -> np.ndarray:
    """Line width [pt] of each muscle: proportional to its PCSA, the largest MAX_WIDTH; 0 for an idle muscle."""
    if pcsa is None or not np.any(pcsa > 0):
        return np.full(n_muscles, IDLE_WIDTH)
    share = pcsa / pcsa.max()
    return np.where(share < IDLE_FRACTION, 0.0, np.maximum(MAX_WIDTH * share, MIN_WIDTH))


def _draw_fibres(ax, model: Model, pcsa: np.ndarray | None) -> None:
    widths = _widths(pcsa, 2 * len(model.muscles))
    for p, pair in enumerate(model.muscles):
        ups, lows = geometry.pair_fibres(pair)
        colour = PAIR_COLOURS[p % len(PAIR_COLOURS)]
        for side, side_name in enumerate(model.geometry.side_names):
            muscle = 2 * p + side
            idle = pcsa is not None and widths[muscle] == 0
            for i, (up, low) in enumerate(zip(ups[side], lows[side], strict=True)):
                ax.plot(
                    [up[0] * CM_PER_M, low[0] * CM_PER_M],
                    [up[1] * CM_PER_M, low[1] * CM_PER_M],
                    color=colour,
                    linestyle=":" if idle else "-",
                    alpha=SIDE_ALPHA[side],
                    linewidth=IDLE_WIDTH if idle else widths[muscle],
                    gid=f"fibre {pair.name}_{side_name} {i}",
                    label=pair.name if i == 0 and side == 0 else None,
                    solid_capstyle="butt",
                )


def _dimension(ax, start, end, text: str, gid: str, offset) -> None:
    ax.annotate(
        "",
        xy=end,
        xytext=start,
        arrowprops={"arrowstyle": "<->", "lw": 0.8, "shrinkA": 0, "shrinkB": 0},
        gid=gid,
    )
    middle = (np.asarray(start) + np.asarray(end)) / 2
    ax.annotate(
        text, middle, xytext=offset, textcoords="offset points", ha="center", va="center", fontsize=7, bbox=_LABEL_BOX
    )


def _draw_counter_torques(ax, model: Model, cors: np.ndarray, counter_torque: np.ndarray) -> dict:
    """Each CT_k as a curved arrow from its CoR: the turn it gives the part above; returns the arrows by CoR.

    A positive (counter-clockwise) torque turns the part above CoR k towards -x
    (docs/model.md, "Frame and units"), so its arrow goes from the CoR to -x over an arc that turns
    counter-clockwise (a negative one to +x, clockwise); the chord is TORQUE_SCALE per N m long. Its
    label stands beyond the tip, clear of the spine's parts at that height (:func:`_beyond`).
    """
    arrows = {}
    for name, (x, y), torque in zip(model.geometry.cor_names, cors, counter_torque, strict=True):
        dx = -torque * TORQUE_SCALE * CM_PER_M
        # an arc over the CoR (arc3 bends to the left of the way from start to tip): counter-clockwise for a
        # positive torque, clockwise for a negative one, as a torque is drawn (a straight arrow read as a force)
        bend = min(0.5, 2 * TORQUE_RISE * CM_PER_M / abs(dx)) if dx else 0.0  # the arc rises TORQUE_RISE at most
        bend = bend if dx < 0 else -bend
        arrows[name] = ax.annotate(
            "",
            xy=(x + dx, y),
            xytext=(x, y),
            arrowprops={
                "arrowstyle": "-|>",
                "color": "crimson",
                "lw": 1.4,
                "shrinkA": 0,
                "shrinkB": 0,
                "connectionstyle": f"arc3,rad={bend}",
            },
            gid=f"counter torque {name}",
            zorder=3,
        )
        left = dx < 0
        ax.annotate(
            f"{torque:+.1f} N m",
            (0.0 if left else 1.0, 0.5),
            xycoords=_beyond(arrows[name], _OBSTACLES),
            xytext=(-TORQUE_LABEL_OFFSET if left else TORQUE_LABEL_OFFSET, 0),
            textcoords="offset points",
            ha="right" if left else "left",
            va="center",
            fontsize=6,
            color="crimson",
            bbox=_LABEL_BOX,
            gid=f"counter torque label {name}",
        )
    return arrows


_OBSTACLES = ("vertebra ", "cor label ", "point label ")
"""The ``gid`` prefixes of what a counter torque's label must not touch (besides the arrows)."""


def _beyond(arrow, prefixes: tuple[str, ...]):
    """``xycoords`` of a label: at draw time, the box spanning ``arrow`` and what is drawn at its height.

    What is drawn there: the artists of the axes whose ``gid`` starts with one of ``prefixes``, found
    when drawn (a CoR's label may come after its torque's). Measured on the canvas when drawn (the
    labels sized in points, the drawing in cm), so it holds at any figure size or resolution; the label
    goes on the box's outer side (:func:`_draw_counter_torques`, :func:`_label_cors`).
    """

    def box(renderer):
        own = arrow.get_window_extent(renderer)  # an Annotation places itself first (also in a layout pass)
        band = renderer.points_to_pixels(TORQUE_LABEL_BAND)
        middle = (own.y0 + own.y1) / 2
        obstacles = (a for a in (*arrow.axes.patches, *arrow.axes.texts) if (a.get_gid() or "").startswith(prefixes))
        near = [
            extent
            for extent in (o.get_window_extent(renderer) for o in obstacles)
            if extent.y0 <= middle + band and extent.y1 >= middle - band
        ]
        span = Bbox.union([own, *near]).expanded(1.0, 1.0)
        # the label boxes' padding (0.1 of the font size) lies outside a text's extent
        pad = renderer.points_to_pixels(1.0)
        return Bbox.from_extents(span.x0 - pad, own.y0, span.x1 + pad, own.y1)

    return box


def _label_cors(ax, model: Model, cors: np.ndarray, arrows: dict) -> None:
    """Each CoR's name [cors in cm], on the side its counter torque's arrow leaves free.

    Left of the CoR as a rule; where the arrow points left (a positive torque), right of it and of the
    label of P1, P3 or P2 at its height (:func:`_beyond`): on the left it lay on its own arrow.
    """
    for name, (x, y) in zip(model.geometry.cor_names, cors, strict=True):
        arrow = arrows.get(name)
        right = arrow is not None and arrow.xy[0] < x
        ax.annotate(
            name,
            (1.0, 0.5) if right else (x, y),
            xycoords=_beyond(arrow, ("point label ",)) if right else "data",
            xytext=(COR_LABEL_OFFSET if right else -8, 0),
            textcoords="offset points",
            ha="left" if right else "right",
            va="center",
            fontsize=7,
            bbox=_LABEL_BOX,
            zorder=5,
            gid=f"cor label {name}",
        )


def _fit_labels(ax, labels, tries: int = 6) -> None:
    """Widen the limits until ``labels`` lie inside the axes, measured on the canvas after the layout.

    The labels are sized in points, the limits in cm (:func:`_limits` holds the arrows' tips):
    the label of a long arrow (60 N m at E = Lambda = 8 cm) crossed the frame. Each widening
    shrinks the scale, so the labels are measured again.
    """
    for _ in range(tries):
        renderer = laid_out(ax.figure)
        frame = ax.get_window_extent(renderer)
        # a text's extent places it (its xycoords measured, :func:`_beyond`); its box's padding lies outside
        boxes = Bbox.union([t.get_window_extent(renderer) for t in labels]).padded(renderer.points_to_pixels(1.0))
        if frame.x0 <= boxes.x0 and boxes.x1 <= frame.x1 and frame.y0 <= boxes.y0 and boxes.y1 <= frame.y1:
            return
        (x0, y0), (x1, y1) = ax.transData.inverted().transform([[boxes.x0, boxes.y0], [boxes.x1, boxes.y1]])
        (low_x, high_x), (low_y, high_y) = ax.get_xlim(), ax.get_ylim()
        pad = 0.02 * max(high_x - low_x, high_y - low_y)
        ax.set_xlim(min(low_x, x0 - pad), max(high_x, x1 + pad))
        ax.set_ylim(min(low_y, y0 - pad), max(high_y, y1 + pad))


def _draw_spine(ax, model: Model, eccentricity: float, lordosis: float, annotate: bool) -> np.ndarray:
    for name, corners in _vertebrae(model, eccentricity, lordosis):
        ax.add_patch(Polygon(corners * CM_PER_M, closed=True, fc="0.85", ec="0.4", lw=0.6, gid=f"vertebra {name}"))
    line = spine_line(model, eccentricity, lordosis) * CM_PER_M
    ax.plot(line[:, 0], line[:, 1], color="k", lw=1.2, gid=GIDS["spine"])
    length = model.geometry.spine_length
    points = geometry.cor_positions(eccentricity, lordosis, _line_geometry(model, (length, length / 2, 0.0)))
    ax.plot(*(points * CM_PER_M).T, "s", color="k", ms=3, gid=GIDS["spline"])
    cors = geometry.cor_positions(eccentricity, lordosis, model.geometry)
    ax.plot(*(cors * CM_PER_M).T, "o", mfc="white", mec="k", ms=5 if annotate else 3, gid=GIDS["cor"], zorder=4)
    if annotate:  # the CoRs' labels come with the torques' arrows (_label_cors)
        for label, (x, y) in zip(("P1", "P3", "P2"), points * CM_PER_M, strict=True):
            ax.annotate(
                label, (x, y), xytext=(6, 0), textcoords="offset points", va="center", fontsize=7,
                gid=f"point label {label}",
            )  # fmt: skip
    return cors


def _draw_body(ax, model: Model, eccentricity: float, lordosis: float, annotate: bool) -> None:
    mass = geometry.mass_position(model) * CM_PER_M
    ax.axvline(0.0, color="0.5", lw=0.8, ls="-.", gid=GIDS["axis"])
    ax.plot([mass[0], mass[0]], [mass[1], 0.0], color="0.3", lw=0.8, ls=(0, (1, 2)), gid=GIDS["gravity"])
    ax.plot(*mass, "o", color="k", ms=10 if annotate else 5, gid=GIDS["mass"])
    if not annotate:
        return
    ax.annotate(
        f"m = {model.body.mass:.3g} kg", mass, xytext=(9, 0), textcoords="offset points", va="center", fontsize=8
    )
    length = model.geometry.spine_length * CM_PER_M
    e, lam = eccentricity * CM_PER_M, lordosis * CM_PER_M
    ax.plot([-e, -e], [0.0, length], color="0.5", lw=0.6, ls=":", gid=GIDS["chord"])
    _dimension(ax, (-e, length + 3.0), (0.0, length + 3.0), f"E = {e:g} cm", "dimension E", (0, 8))
    _dimension(ax, (-e, length / 2), (-e + lam, length / 2), f"Λ = {lam:g} cm", "dimension Lambda", (-30, 0))


def _limits(ax, model: Model, cors: np.ndarray, tips: np.ndarray) -> None:
    """Limits around the fibres, CoRs, point mass and the counter torques' tips ``tips`` [m], shape (n, 2)."""
    upper, lower, _ = geometry.all_fibres(model)
    # the tips too: an arrow whose tip lay outside the axes was not drawn, and its label had no place
    points = np.concatenate([upper, lower, cors, tips, geometry.mass_position(model)[None]]) * CM_PER_M
    low, high = points.min(axis=0), points.max(axis=0)
    pad = 0.08 * (high - low).max()
    ax.set_xlim(low[0] - pad, high[0] + pad)
    ax.set_ylim(low[1] - pad, high[1] + pad)
    ax.set_aspect("equal")


def draw_model(
    model: Model,
    eccentricity: float,
    lordosis: float,
    pcsa=None,
    counter_torque: bool = False,
    ax=None,
    annotate: bool = True,
    slip_check: bool = True,
) -> Figure:
    """Draw the model at one (E, Lambda): the paper's Figure 2, to scale [cm].

    Parameters
    ----------
    model : Model
        Geometry, muscles and point mass.
    eccentricity, lordosis : float
        E and Lambda [m].
    pcsa : None, "optimum" or array_like
        The activation that sets the fibres' widths (see :func:`activation`); None: all alike.
    counter_torque : bool
        Draw CT_k at each CoR as an arrow, :data:`TORQUE_SCALE` per N m (needs an activation).
    ax : matplotlib.axes.Axes, optional
        Draw into these Axes; default a new figure (:func:`spinectl.canvas.new_figure`).
    annotate : bool
        Labels, dimensions, legend, title and axis labels; False for a small inset.
    slip_check : bool
        True (the default): PCSA values above :data:`spinectl.model.checks.MAX_PLAUSIBLE_PCSA` are refused
        as cm^2 typed where m^2 are meant; False: their unit is checked (``--pcsa``, in cm^2), any size is drawn.

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn on (that of ``ax`` if given); nothing is written.

    Raises
    ------
    ParameterError
        E or Lambda outside the modelled range, a bad ``pcsa``, or ``counter_torque``
        without an activation.
    """
    pcsa_used, torques, source = activation(model, eccentricity, lordosis, pcsa, slip_check)
    if counter_torque and pcsa is None:
        raise ParameterError("counter_torque", "needs an activation: give pcsa ('optimum' or values)")
    if ax is None:
        ax = new_figure(figsize=FIGURE_SIZE, layout="constrained").add_subplot()
    _draw_fibres(ax, model, pcsa_used)
    cors = _draw_spine(ax, model, eccentricity, lordosis, annotate)
    _draw_body(ax, model, eccentricity, lordosis, annotate)
    tips, arrows = np.empty((0, 2)), {}
    if counter_torque and torques is not None:
        arrows = _draw_counter_torques(ax, model, cors * CM_PER_M, torques)
        tips = cors - np.column_stack([torques * TORQUE_SCALE, np.zeros_like(torques)])
    if annotate:
        _label_cors(ax, model, cors * CM_PER_M, arrows)
    _limits(ax, model, cors, tips)
    if annotate:
        ax.set_xlabel(f"x [cm] ({model.geometry.side_names[0]} →)")  # the plane's own +x side: right if coronal
        ax.set_ylabel("y [cm] (above P2)")
        lines = [f"E = {eccentricity * CM_PER_M:g} cm, Λ = {lordosis * CM_PER_M:g} cm; {source}"]
        if pcsa_used is not None:
            widest = _cm2(pcsa_used.max())
            lines.append(f"line width ∝ PCSA (widest: {widest} cm² per muscle); paler: {model.geometry.side_names[1]}")
        if counter_torque and torques is not None:
            lines.append(f"arrows: counter torques CT_k, {TORQUE_SCALE * CM_PER_M:g} cm per N m (+: counter-clockwise)")
        ax.set_title("\n".join(lines), fontsize=7)
        ax.legend(loc="upper left", ncols=1, fontsize=6, framealpha=0.8)
    else:
        ax.set_xticks([])
        ax.set_yticks([])
    if arrows:  # after the title and axis labels: the layout they take decides the scale
        _fit_labels(ax, [t for t in ax.texts if (t.get_gid() or "").startswith(("counter torque label", "cor label"))])
    return ax.figure
