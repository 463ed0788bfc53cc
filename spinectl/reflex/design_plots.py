"""Figures of the design question: the chain's verdicts against the passive stiffness, the design curve.

Compute and draw are separate: :func:`spinectl.reflex.design.passive.passive_curve` and
:func:`spinectl.reflex.design.curve.delay_curve` compute, the figure functions here draw on new
figures with the Agg canvas (:func:`spinectl.canvas.new_figure`) and write nothing, and
:func:`write_figures` saves them atomically (:func:`spinectl.canvas.save_figures`).
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ..canvas import new_figure, save_figures
from ..units import m2_to_cm2
from .design import PAPER_PASSIVE, REACTION_TIMES, DesignCurve, PassiveCurve
from .design.passive import GLOBAL_ALONE

DPI = 110
"""Resolution of the PNG files [dots per inch]."""


def passive_figure(curve: PassiveCurve) -> Figure:
    """The least global PCSA alone and the least local stiffness for the chain against the passive stiffness.

    Marked: the least passive stiffness at which global muscles alone suffice, Crisco et al.'s
    88 N buckling stiffness (computed, :func:`spinectl.reflex.design.passive.crisco_stiffness`) and the
    paper's 15 N m/rad.

    Parameters
    ----------
    curve : PassiveCurve

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig = new_figure(figsize=(7.0, 6.4), layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True)
    k = curve.passive_stiffness
    top.plot(k, m2_to_cm2(curve.global_pcsa), "o-", ms=3, color="C0")
    top.set_ylabel("least global PCSA alone [cm²]")
    top.set_title(
        "chain (all CoRs free): static stability without local muscles\n" + textwrap.fill(GLOBAL_ALONE, 100)
        + ", at each K",
        fontsize=9,
    )  # fmt: skip
    bottom.plot(k, curve.local_stiffness.sum(axis=1), "o-", ms=3, color="C1")
    bottom.set_ylabel("least local stiffness, sum [N m/rad]")
    bottom.set_title(
        f"least local stiffness at the paper's joint-by-joint minimum, {m2_to_cm2(curve.paper_pcsa):.1f} cm² "
        "held fixed\n(its own distribution, not the chain's best: not comparable with the top's totals)",
        fontsize=9,
    )
    bottom.set_xlabel("passive stiffness per joint K [N m/rad]")
    for ax in (top, bottom):
        for mark in _marks(curve):
            ax.axvline(mark["x"], label=mark["label"], **mark["line"])
        ax.grid(alpha=0.3)
    # the marks can lie 0.2 N m/rad apart (Crisco 37.6, threshold 37.5): each value is written at its own height,
    # on its own side of the line, so both stay readable where the lines overlap
    for j, mark in enumerate(_marks(curve)):
        side = mark["side"]
        top.annotate(
            f"K = {mark['x']:.1f}",
            xy=(mark["x"], 0.9 - 0.12 * j),
            xycoords=("data", "axes fraction"),
            xytext=(4 * side, 0),
            textcoords="offset points",
            ha="left" if side > 0 else "right",
            va="center",
            fontsize=8,
            color=mark["line"]["color"],
        )
    top.legend(fontsize=8, loc="center right")
    fig.suptitle(
        f"{curve.model.get('header', '')}\nE = {curve.eccentricity * 100:.1f} cm, Λ = {curve.lordosis * 100:.1f} cm",
        fontsize=9,
    )
    return fig


def _marks(curve: PassiveCurve) -> list[dict]:
    """The marked stiffnesses: ``x`` [N m/rad], the legend ``label``, ``line`` (axvline's style) and ``side``.

    Crisco's is a wide pale band and the threshold a thin dotted line on it, so that both show where they
    nearly coincide; ``side`` (+1 right, -1 left) places each value's text apart from the other's.
    """
    marks = [
        {
            "x": curve.crisco,
            "label": f"Crisco et al. 1992: 88 N buckles, K = {curve.crisco:.1f}",
            "line": {"color": "C3", "ls": "-", "lw": 4.0, "alpha": 0.35},
            "side": 1,
        },
        {
            "x": PAPER_PASSIVE,
            "label": f"the paper's K = {PAPER_PASSIVE:g}",
            "line": {"color": "0.4", "ls": "-.", "lw": 1.2},
            "side": 1,
        },
    ]
    if np.isfinite(curve.threshold):
        marks.append(
            {
                "x": curve.threshold,
                "label": f"global alone suffice from K = {curve.threshold:.1f}",
                "line": {"color": "C2", "ls": ":", "lw": 1.6},
                "side": -1 if curve.threshold <= curve.crisco else 1,
            }
        )
    return marks


def delay_figure(curve: DesignCurve) -> Figure:
    """The design curve: required co-contraction (joint by joint) and local stiffness (chain) against the delay.

    One line per lag T_a; the trunk muscles' reaction times of Radebold et al. (2000) marked
    (:data:`spinectl.reflex.design.result.REACTION_TIMES`).

    Parameters
    ----------
    curve : DesignCurve

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig = new_figure(figsize=(7.0, 6.5), layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True)
    ms = curve.delays * 1000.0
    for i, lag in enumerate(curve.lags):
        label = f"T_a = {lag * 1000:.4g} ms"
        top.plot(ms, curve.activation[i], "o-", ms=3, color=f"C{i}", label=label)
        bottom.plot(ms, curve.local_stiffness[i].sum(axis=1), "o-", ms=3, color=f"C{i}", label=label)
    top.set_ylabel("least activation [x minimum PCSA]")
    rule = "the reflex rule" if curve.reflex.startswith("the reflex rule") else "the given gains"
    top.set_title(
        f"joint by joint (each CoR alone, the others fixed): every segment's margin >= delay, {rule}", fontsize=10
    )
    bottom.set_ylabel("least local stiffness, sum [N m/rad]")
    bottom.set_title(
        f"chain (all CoRs free), global activation {curve.chain_activation:.3g} "
        f"({m2_to_cm2(curve.global_pcsa):.2f} cm²), {rule}: stable at the delay",
        fontsize=10,
    )
    bottom.set_xlabel("reflex delay [ms]")
    for ax in (top, bottom):
        for j, (t, text) in enumerate(REACTION_TIMES):
            ax.axvline(t * 1000.0, color="0.4", ls=(0, (4, 2 + 2 * j)), lw=1, label=f"{t * 1000:.0f} ms: {text}")
        ax.grid(alpha=0.3)
        ax.set_ylim(bottom=0)
    top.legend(fontsize=7, loc="upper left")
    fig.suptitle(
        f"{curve.model.get('header', '')}\nE = {curve.eccentricity * 100:.1f} cm, Λ = {curve.lordosis * 100:.1f} cm; "
        "each value the least, a stability boundary",
        fontsize=9,
    )
    return fig


def write_figures(figures: dict[str, Figure], folder: str | Path) -> list[Path]:
    """Save the figures into ``folder``, all or none (:func:`spinectl.canvas.save_figures`) at :data:`DPI`.

    Parameters
    ----------
    figures : dict of str to Figure
        File name -> figure.
    folder : str or Path

    Returns
    -------
    list of Path
    """
    return save_figures(figures, folder, DPI)
