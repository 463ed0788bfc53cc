"""The anatomy figures, drawn from :mod:`spinectl.anatomy.drawing` and the lordosis curve (docs/anatomy.md).

Each function draws on a :func:`spinectl.canvas.new_figure` and returns it; saving is the
separate step (:func:`save_anatomy_figures`, through :func:`spinectl.canvas.save_figures`,
all files or none).
"""

from __future__ import annotations

import textwrap

import numpy as np

from ..canvas import new_figure, save_figures
from .drawing import ModeShapes, SagittalProjection
from .naming import joint_labels
from .optimum import CURVE_AXIS, CURVE_AXIS_MEANING, CURVE_INACCURATE

CLASS_COLOURS = {"global": "tab:blue", "local": "tab:red", "between": "tab:green", "non-lumbar": "tab:gray"}
"""Muscle class -> colour (:data:`spinectl.model.linear_chain.CONTROL_CLASSES`)."""

PLOT_FILES = ("sagittal.png", "modes.png", "lordosis.png")
"""The files of :func:`save_anatomy_figures`; ``modes.png`` needs a sagittal analysis, ``lordosis.png`` a curve."""

CRITERIA = (
    ("none", "classic (no stability criterion)", "tab:grey"),
    ("joints", "joint by joint (-K_jj >= mu)", "tab:orange"),
    ("chain", "the chain, free (-K >= mu I)", "tab:purple"),
)


def _spine_axes(ax, cors, thorax, **style):
    ax.plot(*np.vstack([cors, thorax]).T, **style)


def sagittal_figure(projection: SagittalProjection, title: str = ""):
    """The model in its sagittal plane: muscles coloured by class, the spine line and the chain's CoRs.

    Parameters
    ----------
    projection : SagittalProjection
        From :func:`~spinectl.anatomy.drawing.sagittal_projection`.
    title : str
        The figure's title (e.g. the model's name).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig = new_figure(figsize=(5.6, 7.2), layout="constrained")
    ax = fig.add_subplot()
    counts = {c: projection.classes.count(c) for c in CLASS_COLOURS}
    for cls in ("non-lumbar", "local", "between", "global"):  # global on top: the fewest
        for segments, c in zip(projection.segments, projection.classes, strict=True):
            if c != cls:
                continue
            for seg in segments:
                ax.plot(seg[:, 0], seg[:, 1], color=CLASS_COLOURS[c], lw=0.7, alpha=0.55)
        ax.plot([], [], color=CLASS_COLOURS[cls], lw=2, label=f"{cls} muscles ({counts[cls]})")
    _spine_axes(ax, projection.cors, projection.thorax, color="black", lw=2.5, zorder=5)
    ax.plot(*projection.cors.T, "o", ms=7, mfc="white", mec="black", mew=1.5, zorder=6, label="CoRs (chain joints)")
    for name, (x, y) in zip(joint_labels(projection.joints, "sagittal"), projection.cors, strict=True):
        ax.annotate(
            name,
            (x, y),
            xytext=(8, 0),
            textcoords="offset points",
            va="center",
            fontsize=8,
            zorder=7,
            bbox={"fc": "white", "ec": "none", "alpha": 0.75, "pad": 0.5},
        )
    ax.plot(*projection.thorax, "s", color="black", ms=6, zorder=6, label="thorax centre of mass")
    ax.set_aspect("equal")
    ax.set_xlabel("anterior [m]")
    ax.set_ylabel("up [m]")
    ax.set_title(title or "sagittal projection", fontsize=11)
    fig.legend(loc="outside lower center", ncols=2, fontsize=8)
    ax.grid(alpha=0.3)
    return fig


def modes_figure(shapes: ModeShapes, title: str = ""):
    """Each mode of -K drawn as the spine bent along it, beside the spine at rest; unstable modes in red.

    Parameters
    ----------
    shapes : ModeShapes
        From :func:`~spinectl.anatomy.drawing.mode_shapes`.
    title : str
        The figure's title (e.g. the model, plane and activation).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.ticker import MaxNLocator

    n = len(shapes.eigenvalues)
    fig = new_figure(figsize=(2.4 * n, 5.0), layout="constrained")
    axes = np.atleast_1d(fig.subplots(1, n, sharey=True))
    for k, ax in enumerate(axes):
        value = shapes.eigenvalues[k]
        colour = "tab:red" if value <= 0 else "tab:blue"
        ax.plot(*shapes.rest.T, "-o", color="0.7", lw=2, ms=4, label="at rest")
        ax.plot(*shapes.bent[k].T, "-o", color=colour, lw=2, ms=4, label="along the mode")
        shares = ", ".join(f"{v:+.2f}" for v in shapes.modes[:, k])
        verdict = "unstable" if value <= 0 else "stable"
        ax.set_title(f"mode {k + 1}: {value:.4g} N m/rad, {verdict}\n({shares})", fontsize=8)
        ax.set_aspect("equal", adjustable="datalim")
        ax.xaxis.set_major_locator(MaxNLocator(3))
        ax.grid(alpha=0.3)
        ax.set_xlabel("anterior [m]")
    axes[0].set_ylabel("up [m]")
    axes[0].legend(loc="lower left", fontsize=7)
    fig.suptitle(
        (title + "\n" if title else "")
        + f"modes of -K (the free chain, every joint free), each drawn with summed |angle| {shapes.angle_deg:g} deg "
        "(exaggerated); joint shares L5S1 up",
        fontsize=9,
    )
    return fig


def lordosis_figure(curve: dict, title: str = ""):
    """The three optima along the rhythm: least cost (top) and the chain's margin (bottom), in degrees.

    Parameters
    ----------
    curve : dict
        From :func:`~spinectl.anatomy.optimum.lordosis_curve`.
    title : str
        The figure's title.

    Returns
    -------
    matplotlib.figure.Figure
        Infeasible postures are gaps (NaN); each curve's least cost is marked.
    """
    degrees = np.asarray(curve["lordosis_deg"], float)
    fig = new_figure(figsize=(7.0, 6.4), layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True)
    inaccurate, hollow = 0, 0
    for key, label, colour in CRITERIA:
        row = curve[key]
        ok = np.array([s in ("optimal", "optimal_inaccurate") for s in row["status"]])
        cost = np.where(ok, np.asarray(row["cost"], float), np.nan)
        margin = np.where(ok, np.asarray(row["margin_Nm_per_rad"], float), np.nan)
        feasible = bool(np.any(np.isfinite(cost)))  # a criterion with no point drawn says why in its legend entry
        top.plot(
            degrees,
            cost,
            "-o",
            ms=3,
            color=colour,
            label=label if feasible else f"{label}: infeasible at every posture",
        )
        rough = np.array([s == "optimal_inaccurate" for s in row["status"]])
        inaccurate += int(rough.sum())
        if np.any(np.isfinite(cost)):
            best = int(np.nanargmin(cost))  # hollow where that optimum is inaccurate
            face = "none" if rough[best] else colour
            hollow += bool(rough[best])
            top.plot(degrees[best], cost[best], "*", ms=14, color=colour, mfc=face, mec="black", zorder=5)
        for ax, values in ((top, cost), (bottom, margin)):  # each inaccurate optimum crossed, as the table marks it
            ax.plot(degrees[rough], values[rough], "x", ms=8, mew=1.5, color="black", zorder=6)
        bottom.plot(degrees, margin, "-o", ms=3, color=colour, label=label)
    for ax in (top, bottom):
        ax.axvline(0.0, color="black", lw=0.8, ls="--")
        ax.grid(alpha=0.3)
    top.text(0.0, 1.0, " the model's posture", transform=top.get_xaxis_transform(), va="top", fontsize=8)
    bottom.axhline(0.0, color="tab:red", lw=0.8)
    top.set_ylabel(r"least cost $\sum_i w_i a_i^2$ [1]")
    bottom.set_ylabel("least eigenvalue of -K [N m/rad]\n(free chain; < 0 unstable)")
    meaning = f"{CURVE_AXIS}: {CURVE_AXIS_MEANING}; the thorax tilts with it: not a lordosis at a fixed upright trunk"
    bottom.set_xlabel(textwrap.fill(meaning, 95), fontsize=8)  # wrapped: one line ran past both edges
    top.legend(fontsize=8, title="criterion (star: least cost)", title_fontsize=8)
    top.set_title(title or f"the three optima along the rhythm ({CURVE_AXIS})", fontsize=10)
    if inaccurate:
        warning = CURVE_INACCURATE.format(count=inaccurate, mark=inaccurate_marks(hollow))
        fig.suptitle(textwrap.fill(warning, 120), fontsize=7, color="tab:red")
    return fig


def inaccurate_marks(hollow: int) -> str:
    """The marks the lordosis figure draws on its inaccurate optima, as its warning names them.

    Parameters
    ----------
    hollow : int
        Least-cost stars drawn hollow (a curve's least cost that is itself inaccurate).

    Returns
    -------
    str
        ``"x"``, with the hollow star only where one is drawn (before: "x, a hollow star" beside an x alone).
    """
    return "x" if not hollow else "x; a curve's least cost, a hollow star"


def anatomy_figures(anatomy, analysis, curve: dict | None = None) -> dict:
    """The figures of one analysis: ``sagittal.png``, ``modes.png`` and, with a curve, ``lordosis.png``.

    Parameters
    ----------
    anatomy : Anatomy
        The model.
    analysis : AnatomyResult or None
        :func:`~spinectl.anatomy.analyses.analyse` (its free chain's modes, drawn for the sagittal
        plane); None (an infeasible optimum): no modes.
    curve : dict, optional
        :func:`~spinectl.anatomy.optimum.lordosis_curve`.

    Returns
    -------
    dict of str to matplotlib.figure.Figure
    """
    from .drawing import mode_shapes, sagittal_projection

    name = anatomy.name
    figures = {"sagittal.png": sagittal_figure(sagittal_projection(anatomy), f"{name}: sagittal projection")}
    if analysis is not None and analysis.plane == "sagittal":
        held = f"mean activation {analysis.activation_mean:.3g}" if analysis.activations.size else "no muscles"
        title = f"{name}, sagittal, {held}"
        figures["modes.png"] = modes_figure(mode_shapes(anatomy, analysis.free), title)
    if curve is not None:
        figures["lordosis.png"] = lordosis_figure(curve, f"{name}: the three optima along the rhythm ({CURVE_AXIS})")
    return figures


def figures_left_out(analysis) -> str:
    """What :func:`anatomy_figures` leaves out for ``analysis`` and why, for the user; '' if nothing.

    Parameters
    ----------
    analysis : AnatomyResult or None
        The analysis drawn.

    Returns
    -------
    str
        E.g. ``"modes.png not drawn: the mode shapes are drawn for the sagittal plane only (this analysis: all three
        planes (3-D)); --plane sagittal draws them"`` (before: the file was dropped without a word).
    """
    from .analyses import plane_text

    if analysis is None or analysis.plane == "sagittal":
        return ""
    return (
        f"modes.png not drawn: the mode shapes are drawn for the sagittal plane only (this analysis: "
        f"{plane_text(analysis.plane)}); --plane sagittal draws them"
    )


def save_anatomy_figures(anatomy, analysis, curve, folder, dpi: float = 150.0) -> list:
    """:func:`anatomy_figures` written into ``folder``, all of them or none.

    Parameters
    ----------
    anatomy : Anatomy
        The model.
    analysis : AnatomyResult or None
        The analysis drawn (:func:`anatomy_figures`).
    curve : dict or None
        The lordosis curve, if computed.
    folder : str or pathlib.Path
        The output folder.
    dpi : float
        Resolution [dots per inch].

    Returns
    -------
    list of pathlib.Path
        The files written.
    """
    return save_figures(anatomy_figures(anatomy, analysis, curve), folder, dpi)
