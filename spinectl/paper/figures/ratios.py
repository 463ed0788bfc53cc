"""The ratio maps: Figure S1 over Figure 3 (the paper's "halving") and the coupled chain over the per segment.

Both are drawn as :func:`~spinectl.paper.figures.landscape.landscape_figure` draws a landscape, on round
levels over the ratio's range, with 0.5 and 1 marked where the ratio reaches them.
"""

from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.figure import Figure

from ...errors import ParameterError
from ...units import CM_PER_M
from .. import grid
from .landscape import _landscape
from .style import _k_label

HALVING = 0.5
"""The paper's ratio of minimum PCSA with and without K = 15 N m/rad (Additional file 1: "halves")."""


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
    """:func:`~.ratios.coupled_ratio` as a map: the coupled chain's global PCSA over the per-segment minimum.

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
