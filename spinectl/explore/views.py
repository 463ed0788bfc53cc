"""The explorer's views: their data as pure functions, and drawn with matplotlib.

:func:`eigenvalue_data`, :func:`counter_torque_data` and :func:`delay_margin_data` map the
numbers of a point to what a view shows (columns, limits, title): the one source of the
numbers both for the matplotlib views here (the PNG export) and for the explorer's live
Bokeh views (:mod:`spinectl.explore.app`), which only map them to glyphs.
Each ``*_plot`` function draws into given Axes or on a new figure (:func:`spinectl.canvas.new_figure`)
and writes nothing; :func:`state_figure` puts them, with the model drawing
(:func:`spinectl.paper.drawing.draw_model`), on one figure: the explorer's PNG export.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr
from matplotlib.figure import Figure

from ..canvas import new_figure
from ..paper.drawing import PAIR_COLOURS, draw_model
from ..paper.landmarks import CT_LIMIT
from ..units import CM_PER_M
from .numbers import PointNumbers

VIEW_SIZE = (3.6, 2.8)
"""Size of one view [in]."""
VIEW_MARGINS = {"left": 0.19, "right": 0.97, "bottom": 0.16, "top": 0.9}
"""Fixed margins of a view, as fractions of the figure: a constrained layout would double its drawing time."""
DRAWING_SIZE = (4.6, 5.2)
"""Size of the model drawing [in]."""
DRAWING_AXES = (0.14, 0.08, 0.83, 0.77)
"""Left, bottom, width, height of the drawing's axes, as fractions of the figure (room for its title above)."""
STATE_FIGURE_SIZE = (13.0, 8.0)
"""Size of the PNG export [in]."""
LANDSCAPE_LABELS = {
    "min_pcsa_cm2": "minimum PCSA [cm²]",
    "counter_torque_norm_Nm": "‖CT‖ [N m] at the minimum PCSA (Fig. 4)",
}
"""The landscapes shown and their colour-bar labels."""


MS_PER_S = 1000.0
"""Milliseconds per second: the delay margins are shown in ms."""


@dataclass(frozen=True)
class ViewData:
    """What one small view shows, ready for any plotting library.

    Attributes
    ----------
    columns : dict of str to list
        Equal-length columns, one row per glyph (a marker or a bar): ``segment`` and ``colour``
        and the view's values (see each ``*_data`` function).
    limits : tuple of float
        (low, high) of the value axis (both axes for the eigenvalues).
    title : str
    line : float or None
        A level drawn across the view (the delay [ms]), or None.
    """

    columns: dict
    limits: tuple[float, float]
    title: str
    line: float | None = None


def eigenvalue_data(numbers: PointNumbers) -> ViewData:
    """Both eigenvalues of each segment alone, the others fixed (paper eq. 1), as markers.

    Parameters
    ----------
    numbers : PointNumbers

    Returns
    -------
    ViewData
        Columns ``segment``, ``colour``, ``re`` and ``im`` [1/s], two rows per segment; limits
        symmetric about 0 and at least +-1.1 1/s, for both axes.
    """
    names = numbers.segment_names
    colours = _colours(len(names))
    eigs = numbers.eigenvalues
    finite = eigs[np.isfinite(eigs)]
    reach = 1.1 * max(
        1.0, float(np.max(np.abs(finite.real), initial=0.0)), float(np.max(np.abs(finite.imag), initial=0.0))
    )
    columns = {
        "segment": [name for name in names for _ in range(eigs.shape[1])],
        "colour": [colour for colour in colours for _ in range(eigs.shape[1])],
        "re": eigs.real.ravel().tolist(),
        "im": eigs.imag.ravel().tolist(),
    }
    return ViewData(columns, (-reach, reach), "eigenvalues, no reflex, joint by joint (shaded: unstable)")


def _bar_columns(names, values, colours) -> dict:
    """Bars of finite height (0 where a value is not finite) and a mark for those: '∞' or 'n/a'."""
    values = np.asarray(values, float)
    return {
        "segment": list(names),
        "colour": list(colours),
        "value": np.where(np.isfinite(values), values, 0.0).tolist(),
        "mark": ["" if np.isfinite(v) else ("∞" if v > 0 else "n/a") for v in values],
    }


def counter_torque_data(numbers: PointNumbers) -> ViewData:
    """CT_k of each segment [N m] as bars, with room for the +-30 N m band.

    Parameters
    ----------
    numbers : PointNumbers

    Returns
    -------
    ViewData
        Columns ``segment``, ``colour``, ``value`` [N m] and ``mark``; limits symmetric, at least
        1.15 x :data:`spinectl.paper.landmarks.CT_LIMIT` (paper, Discussion); the title gives ||CT||.
    """
    names = numbers.segment_names
    finite = numbers.counter_torque[np.isfinite(numbers.counter_torque)]
    reach = 1.15 * max(CT_LIMIT, float(np.max(np.abs(finite), initial=0.0)))
    title = f"CT at activation {numbers.state.activation:g}, ‖CT‖ = {np.linalg.norm(numbers.counter_torque):.3g} N m"
    return ViewData(_bar_columns(names, numbers.counter_torque, _colours(len(names))), (-reach, reach), title)


def delay_margin_data(numbers: PointNumbers) -> ViewData:
    """The exact delay margin of each segment alone [ms] as bars, green where stable at the delay, and the delay.

    Joint by joint (each CoR alone, the others fixed; the paper's criterion); the chain's margin,
    every CoR free, is in the explorer's table (:meth:`~spinectl.explore.numbers.PointNumbers.chain_row`).

    Parameters
    ----------
    numbers : PointNumbers

    Returns
    -------
    ViewData
        Columns ``segment``, ``colour``, ``value`` [ms] and ``mark`` ('∞': any delay); ``line`` the
        delay tau [ms], which the title gives; limits from 0 to 1.2 x the largest of tau, the finite margins and 1 ms.
    """
    margins = numbers.delay_margin * MS_PER_S
    delay = numbers.state.delay * MS_PER_S
    colours = ["tab:green" if ok else "tab:red" for ok in numbers.stable_at_delay]
    top = 1.2 * max(delay, float(np.max(margins[np.isfinite(margins)], initial=0.0)), 1.0)
    columns = _bar_columns(numbers.segment_names, margins, colours)
    return ViewData(columns, (0.0, top), f"delay margins, joint by joint (red: unstable at τ = {delay:g} ms)", delay)


def _axes(ax):
    if ax is not None:
        return ax
    fig = new_figure(figsize=VIEW_SIZE)
    fig.subplots_adjust(**VIEW_MARGINS)
    return fig.add_subplot()


def _colours(n: int) -> list[str]:
    return [PAIR_COLOURS[i % len(PAIR_COLOURS)] for i in range(n)]


def model_drawing(numbers: PointNumbers, ax=None) -> Figure:
    """The model at the state's point with the chosen activation and its counter torques (paper Figure 2).

    Parameters
    ----------
    numbers : PointNumbers
    ax : matplotlib.axes.Axes, optional
        Default: a figure of :data:`DRAWING_SIZE` with fixed axes (a constrained layout would
        double the drawing time).

    Returns
    -------
    matplotlib.figure.Figure
        :func:`spinectl.paper.drawing.draw_model`, every fibre's width proportional to its PCSA
        (geometry only where the optimum is infeasible).
    """
    if ax is None:
        ax = new_figure(figsize=DRAWING_SIZE).add_axes(DRAWING_AXES)
    state = numbers.state
    return draw_model(
        numbers.model,
        state.eccentricity,
        state.lordosis,
        pcsa=numbers.pcsa,
        counter_torque=numbers.pcsa is not None,
        ax=ax,
    )


def eigenvalue_plot(numbers: PointNumbers, ax=None) -> Figure:
    """Both eigenvalues of each segment in the complex plane (paper eq. 1), a root-locus-style view.

    Parameters
    ----------
    numbers : PointNumbers
    ax : matplotlib.axes.Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
        Re lambda [1/s] across, Im lambda [1/s] up; the unstable half plane shaded (each segment alone).
    """
    data = eigenvalue_data(numbers)
    ax = _axes(ax)
    ax.axvspan(0, 1, transform=ax.get_yaxis_transform(), color="tab:red", alpha=0.08, lw=0)
    ax.axvline(0, color="0.3", lw=0.8)
    ax.axhline(0, color="0.7", lw=0.5)
    columns = data.columns
    for name in dict.fromkeys(columns["segment"]):
        rows = [i for i, segment in enumerate(columns["segment"]) if segment == name]
        re, im = (np.array(columns[key])[rows] for key in ("re", "im"))
        ax.plot(re, im, "x", color=columns["colour"][rows[0]], ms=7, mew=2, label=name)
    ax.set_xlim(*data.limits)
    ax.set_ylim(*data.limits)
    ax.set_xlabel("Re λ [1/s]")
    ax.set_ylabel("Im λ [1/s]")
    ax.set_title(data.title, fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    return ax.figure


def _bars(ax, data: ViewData) -> None:
    columns = data.columns
    ax.bar(columns["segment"], columns["value"], color=columns["colour"])
    for x, mark in enumerate(columns["mark"]):
        if mark:
            ax.annotate(mark, (x, 0), ha="center", va="bottom", fontsize=9)
    ax.tick_params(axis="x", labelsize=8)
    ax.set_ylim(*data.limits)
    ax.set_title(data.title, fontsize=9)


def counter_torque_plot(numbers: PointNumbers, ax=None) -> Figure:
    """CT_k of each segment at the chosen activation, and the local muscles' +-30 N m band.

    Parameters
    ----------
    numbers : PointNumbers
    ax : matplotlib.axes.Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
        Bars [N m]; the band is :data:`spinectl.paper.landmarks.CT_LIMIT` (paper, Discussion).
    """
    ax = _axes(ax)
    ax.axhspan(-CT_LIMIT, CT_LIMIT, color="tab:green", alpha=0.12, lw=0, label=f"±{CT_LIMIT:g} N m")
    ax.axhline(0, color="0.3", lw=0.8)
    _bars(ax, counter_torque_data(numbers))
    ax.set_ylabel("CT [N m]")
    ax.legend(fontsize=7, loc="upper left")
    return ax.figure


def delay_margin_plot(numbers: PointNumbers, ax=None) -> Figure:
    """The exact delay margin of each segment's reflex loop, and the reflex delay.

    Parameters
    ----------
    numbers : PointNumbers
    ax : matplotlib.axes.Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
        Bars [ms]; a dashed line at the delay tau: a segment whose bar ends below it is unstable,
        joint by joint (each CoR alone, the others fixed).
    """
    ax = _axes(ax)
    data = delay_margin_data(numbers)
    _bars(ax, data)
    ax.axhline(data.line, color="0.2", ls="--", lw=1, label=f"delay τ = {data.line:g} ms")
    ax.set_ylabel("delay margin [ms]")
    ax.legend(fontsize=7, loc="upper left")
    return ax.figure


def landscape_plot(dataset: xr.Dataset, variable: str, numbers: PointNumbers, ax=None) -> Figure:
    """One landscape over E x Lambda [cm] with the current point marked.

    Parameters
    ----------
    dataset : xarray.Dataset
        From :func:`spinectl.explore.numbers.landscapes`.
    variable : str
        A key of :data:`LANDSCAPE_LABELS`.
    numbers : PointNumbers
        Its state gives the point.
    ax : matplotlib.axes.Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
        E across, Lambda up, as the paper's Figure 3.
    """
    ax = _axes(ax)
    e, lam = (dataset[name].values * CM_PER_M for name in ("E", "Lambda"))
    mesh = ax.pcolormesh(e, lam, dataset[variable].values.T, shading="nearest", cmap="viridis")
    ax.figure.colorbar(mesh, ax=ax, label=LANDSCAPE_LABELS[variable])
    state = numbers.state
    ax.plot(state.eccentricity * CM_PER_M, state.lordosis * CM_PER_M, "o", mfc="white", mec="black", ms=8)
    ax.set_xlabel("E [cm]")
    ax.set_ylabel("Λ [cm]")
    ax.set_aspect("equal")
    return ax.figure


def state_figure(numbers: PointNumbers, dataset: xr.Dataset | None) -> Figure:
    """Every view of the explorer on one figure: the explorer's PNG export.

    Parameters
    ----------
    numbers : PointNumbers
    dataset : xarray.Dataset or None
        The landscapes; None leaves their places empty (still being solved).

    Returns
    -------
    matplotlib.figure.Figure
        The model drawing, eigenvalues, counter torques, delay margins (joint by joint) and both landscapes;
        the title gives the chain's verdict (:func:`chain_caption`).
    """
    fig = new_figure(figsize=STATE_FIGURE_SIZE, layout="constrained")
    axes = fig.subplots(2, 3)
    state = numbers.state
    model_drawing(numbers, axes[0, 0])
    eigenvalue_plot(numbers, axes[0, 1])
    counter_torque_plot(numbers, axes[0, 2])
    delay_margin_plot(numbers, axes[1, 0])
    for ax, variable in zip(axes[1, 1:], LANDSCAPE_LABELS, strict=True):
        if dataset is None:
            ax.set_axis_off()
        else:
            landscape_plot(dataset, variable, numbers, ax)
    fig.suptitle(
        f"spinectl explore: mass {state.mass:g} kg, K {state.stiffness:g} N m/rad, delay {state.delay * 1000:g} ms, "
        f"activation {state.activation:g} × minimum PCSA, lag {state.activation_lag * 1000:g} ms\n"
        + chain_caption(numbers)
    )
    return fig


def chain_caption(numbers: PointNumbers) -> str:
    """The chain's verdict in one line, its criterion named: what the PNG export says beside the segments' views.

    Parameters
    ----------
    numbers : PointNumbers

    Returns
    -------
    str
        E.g. 'chain (all 5 CoRs free), the same reflex: stable at τ: no, delay margin 4.787e-05 s;
        without reflex 5 of 10 modes grow'.
    """
    row = numbers.chain_row()
    return (
        f"{row['criterion']}, the same reflex: stable at τ: {row['stable_at_delay']}, delay margin "
        f"{row['delay_margin_s']} s; without reflex {row['modes']}"
    )
