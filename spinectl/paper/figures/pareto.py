"""The coupled chain's Pareto front: global PCSA total against local stiffness total (docs/chain.md)."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from ...canvas import new_figure
from ...model.chain import local_stiffness_per_pcsa
from ...model.params import Model
from ...optimise.coupled import ParetoFront
from ...units import CM_PER_M, M2_PER_CM2
from .style import FIGURE_SIZE


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
