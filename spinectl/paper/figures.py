"""The paper's figures from a sweep Dataset: Figures 3, 4 and S1.

Filled contours over E (abscissa) and Lambda (ordinate), both in cm, with
positions A-D labelled at the corners (:data:`spinectl.paper.landmarks.POSITIONS`).
Figure 4 adds the +-30 N m limit of the local muscles as a contour and the
paper's optimum. Each figure function draws on a new figure with the Agg
canvas (:func:`spinectl.canvas.new_figure`: no global backend state, no display
needed) and returns it, writing nothing; :func:`save_figure` writes one
atomically, :func:`figure_set` draws the set and :func:`draw_figures` saves it (as a whole).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib.figure import Figure

from ..canvas import new_figure, save_png, save_pngs
from ..landscape import netcdf
from ..units import M2_PER_CM2
from . import grid, landmarks

CM_PER_M = 100.0
FIGURE_SIZE = (6.4, 5.2)
"""Inches."""
DPI = 150
LEVELS = 16
"""Number of filled contour levels."""

_CORNER_OFFSET = {"A": (6, 6), "B": (-16, 6), "C": (-16, -16), "D": (6, -16)}
"""Label offsets [points] that keep the corner labels inside the axes."""


def _axes(title: str):
    fig = new_figure(figsize=FIGURE_SIZE, layout="constrained")
    ax = fig.add_subplot()
    ax.set_xlabel("eccentricity E [cm]")
    ax.set_ylabel("lordosis Λ [cm]")
    ax.set_title(title, fontsize=10)
    ax.set_aspect("equal")
    return fig, ax


def _mark_positions(ax) -> None:
    for name, (e, lam) in grid.POSITIONS.items():
        x, y = e * CM_PER_M, lam * CM_PER_M
        ax.plot(x, y, "o", color="k", markersize=4, clip_on=False)
        ax.annotate(
            name,
            (x, y),
            xytext=_CORNER_OFFSET[name],
            textcoords="offset points",
            fontweight="bold",
            bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "k", "lw": 0.5},
        )


def _landscape(field: xr.DataArray, title: str, label: str):
    """A filled contour of ``field`` (dims E, Lambda) with A-D marked; returns (figure, axes).

    Infeasible points (NaN) stay white, and the title says how many there are.
    """
    values = np.ma.masked_invalid(field.transpose("Lambda", "E").values)
    infeasible = int(values.mask.sum()) if np.ma.is_masked(values) else 0
    if infeasible:
        title += f"\nwhite: no self-stable activation within the bounds ({infeasible} of {values.size} points)"
    fig, ax = _axes(title)
    e = field["E"].values * CM_PER_M
    lam = field["Lambda"].values * CM_PER_M
    if infeasible < values.size:
        filled = ax.contourf(e, lam, values, levels=LEVELS, cmap="viridis")
        fig.colorbar(filled, ax=ax).set_label(label)
    ax.set_xlim(e.min(), e.max())
    ax.set_ylim(lam.min(), lam.max())
    _mark_positions(ax)
    return fig, ax


def _k_label(dataset: xr.Dataset) -> str:
    return f"K = {float(dataset['K']):g} N m/rad ({dataset.attrs.get('passive_convention', '?')})"


def min_pcsa_figure(dataset: xr.Dataset) -> Figure:
    """Figure 3 (K = 0) or S1 (K > 0): minimum PCSA for self-stability of every segment.

    Parameters
    ----------
    dataset : xarray.Dataset
        One landscape (scalar K).

    Returns
    -------
    matplotlib.figure.Figure
        Filled contours over E and Lambda [cm]; nothing is written.
    """
    name = "Fig. 3" if float(dataset["K"]) == 0 else "Fig. S1"
    title = f"{name}: minimum PCSA for self-stability, {_k_label(dataset)}"
    fig, _ = _landscape(dataset["min_pcsa_cm2"], title, "minimum PCSA [cm²]")
    return fig


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
    e, lam = field["E"].values * CM_PER_M, field["Lambda"].values * CM_PER_M
    values = np.ma.masked_invalid(field.transpose("Lambda", "E").values)
    if values.count() and values.min() < landmarks.CT_LIMIT < values.max():
        limit = ax.contour(e, lam, values, levels=[landmarks.CT_LIMIT], colors="white", linestyles="--")
        ax.clabel(limit, fmt=lambda _: f"±{landmarks.CT_LIMIT:g} N m", fontsize=8)
    ax.plot(*(np.array(landmarks.OPTIMUM) * CM_PER_M), "*", color="red", markersize=10, label="paper's optimum")
    ax.legend(loc="upper center", fontsize=8, framealpha=0.8)
    return fig


def save_figure(fig: Figure, path: str | Path) -> Path:
    """The save step: :func:`spinectl.canvas.save_png` at this module's :data:`DPI`.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        A figure of this module.
    path : str or Path
        The PNG file, written atomically.

    Returns
    -------
    Path
        ``path``.
    """
    return save_png(fig, path, DPI)


def figure_names(stiffness: float) -> tuple[str, str]:
    """File names of the minimum-PCSA and counter-torque figures.

    Parameters
    ----------
    stiffness : float
        Passive stiffness K [N m/rad]; 0 gives Figures 3 and 4, else S1 and 4 with K in the name.

    Returns
    -------
    tuple of str
        The PNG names of the minimum-PCSA and the counter-torque figure: K short (``K15``)
        where that reads back as K, else every digit of K (``K15.000001``), so that
        distinct stiffnesses never share a file.
    """
    if stiffness == 0:
        return "fig3_min_pcsa.png", "fig4_counter_torque.png"
    short = f"{stiffness:g}"
    k = short if float(short) == stiffness else repr(float(stiffness))
    return f"figS1_min_pcsa_K{k}.png", f"fig4_counter_torque_K{k}.png"


def figure_set(dataset: xr.Dataset, specific_tension: float | None = None) -> dict[str, Figure]:
    """Figures 3 and 4 for every K of ``dataset`` (Figure S1 for K > 0), by file name; nothing written.

    Parameters
    ----------
    dataset : xarray.Dataset
        From :func:`~spinectl.landscape.sweep.sweep` (scalar K) or
        :func:`~spinectl.landscape.sweep.stiffness_sweep` (a K dimension).
    specific_tension : float, optional
        f_iso per PCSA [N/m^2], for the local-PCSA scale of Figure 4; default: that of
        the model the dataset was computed with (:func:`spinectl.landscape.netcdf.model_of`).

    Returns
    -------
    dict of str to matplotlib.figure.Figure
        :func:`figure_names` of each K -> its figure, K in the dataset's order.

    Raises
    ------
    ConfigError, ParameterError
        ``specific_tension`` not given and the dataset's ``config_toml`` is not a valid model.
    """
    if specific_tension is None:
        specific_tension = netcdf.model_of(dataset).fibre.specific_tension
    parts = [dataset.sel(K=k) for k in dataset["K"].values] if "K" in dataset.dims else [dataset]
    drawn = {}
    for part in parts:
        pcsa_name, ct_name = figure_names(float(part["K"]))
        drawn[pcsa_name] = min_pcsa_figure(part)
        drawn[ct_name] = counter_torque_figure(part, specific_tension)
    return drawn


def draw_figures(dataset: xr.Dataset, out_dir: str | Path, specific_tension: float | None = None) -> list[Path]:
    """Draw :func:`figure_set` and save it into ``out_dir``: every figure or none (:func:`spinectl.canvas.save_pngs`).

    Parameters
    ----------
    dataset : xarray.Dataset
        As for :func:`figure_set`.
    out_dir : str or Path
        Folder for the PNG files (created if missing), named by :func:`figure_names`; its
        other files are kept.
    specific_tension : float, optional
        As for :func:`figure_set`.

    Returns
    -------
    list of Path
        The PNG files written.

    Raises
    ------
    ConfigError, ParameterError
        ``specific_tension`` not given and the dataset's ``config_toml`` is not a valid model.
    OutputError
        ``out_dir`` cannot take the files; nothing is written.
    """
    return save_pngs(figure_set(dataset, specific_tension), out_dir, DPI)
