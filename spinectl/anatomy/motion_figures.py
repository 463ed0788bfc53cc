"""The figure of a motion's stability index (:func:`spinectl.anatomy.motion.motion_plot`; docs/motion.md).

Drawn on a :func:`spinectl.canvas.new_figure` from the Dataset of :func:`spinectl.anatomy.motion.motion_response`
alone, so that a file written earlier draws the same figure; saving is :func:`spinectl.canvas.save_figures`.
"""

from __future__ import annotations

import textwrap

import numpy as np

from ..canvas import new_figure
from .motion_removal import KEPT


def motion_figure(ds):
    """The index of the free and the constrained chain, their unstable modes, and the posture, against time.

    Parameters
    ----------
    ds : xarray.Dataset
        From :func:`spinectl.anatomy.motion.motion_response` (or the NetCDF file it was written to).

    Returns
    -------
    matplotlib.figure.Figure
        Three panels sharing the time axis: the index [N m/rad] (zero marked), the number of unstable modes,
        the chain's coordinates [deg]; a fourth between the last two where the Dataset has contributions: each
        class's d lambda_min / d a_i on the free chain.
    """
    shares = "free_class_contribution" in ds
    figure = new_figure(figsize=(8.0, 10.5 if shares else 8.0))
    axes = figure.subplots(4 if shares else 3, 1, sharex=True)
    index, modes, posture = axes[0], axes[1], axes[-1]
    if shares:
        _classes_panel(axes[2], ds)
    t = ds["time"].values
    for name, style in (("free", "-o"), ("constrained", "--s")):
        criterion = ds.attrs[f"{name}_criterion"]
        index.plot(t, ds[f"{name}_index"].values, style, ms=3, label=criterion)
        modes.plot(t, ds[f"{name}_unstable_modes"].values, style, ms=3, drawstyle="steps-mid", label=criterion)
    index.axhline(0.0, color="0.5", lw=0.8)
    index.set_ylabel("least eigenvalue of -K\n[N m/rad]")
    index.set_title(
        f"{ds.attrs['model_name']}, {ds.attrs['plane']} plane: Cholewicki-McGill index (> 0 stable)\n"
        "free chain and chain constrained by the rhythm",
        fontsize=10,
    )
    index.legend(fontsize=7, loc="best")
    modes.set_ylabel("unstable modes\n(eigenvalues of -K <= 0)")
    modes.set_title("number of unstable modes, by the same two criteria", fontsize=10)
    for j, joint in enumerate(ds["joint"].values):
        posture.plot(t, np.degrees(ds["posture"].values[:, j]), label=str(joint))
    posture.set_ylabel("coordinate [deg]")
    posture.set_xlabel("time [s]")
    posture.set_title(f"posture: the chain's coordinates ({ds.attrs['coordinates_file']})", fontsize=10)
    posture.legend(fontsize=7, ncol=3, loc="best")
    return figure


def _classes_panel(ax, ds) -> None:
    """Each class's d lambda_min / d a_i on the free chain against time (NaN where lambda_min is repeated)."""
    t = ds["time"].values
    for k, name in enumerate(ds["muscle_class"].values):
        ax.plot(t, ds["free_class_contribution"].values[:, k], "-o", ms=3, label=str(name))
    ax.axhline(0.0, color="0.5", lw=0.8)
    ax.set_ylabel("d lambda_min / d a\nper class [N m/rad]")
    ax.set_title("each class's contribution to the free chain's index (summed over its muscles)", fontsize=10)
    ax.legend(fontsize=7, ncol=4, loc="best")


def removal_figure(ds):
    """The relative change of the index when each class and named group is removed, against time, on both chains.

    Parameters
    ----------
    ds : xarray.Dataset
        From :func:`spinectl.anatomy.motion.motion_response` with ``removal`` (or its NetCDF file).

    Returns
    -------
    matplotlib.figure.Figure
        Two panels sharing the time axis, the free chain above the constrained one: one line per class and
        group (single muscles, with ``removal="muscles"``, are in the file, not drawn) of ``*_removed_change``
        [%], zero marked; an x at the panel's foot where the re-solved optimum is infeasible (its NaN).
    """
    from matplotlib.transforms import blended_transform_factory

    figure = new_figure(figsize=(8.0, 7.0), layout="constrained")
    axes = figure.subplots(2, 1, sharex=True)
    t = ds["time"].values
    groups = [k for k, name in enumerate(ds["group"].values) if str(name).startswith(("class:", "group:"))]
    method = ds["free_removed_change"].attrs["method"]
    for ax, name in zip(axes, ("free", "constrained"), strict=True):
        change = ds[f"{name}_removed_change"].values
        foot = blended_transform_factory(ax.transData, ax.transAxes)
        for n, k in enumerate(groups):
            line = ax.plot(t, change[:, k], "-o", ms=3, color=f"C{n}", label=str(ds["group"].values[k]))[0]
            failed = np.char.startswith(ds["removal_status"].values[:, k].astype(str), "re-solved: infeasible")
            # at the foot, one height per group so that two groups failing at one frame both show
            ax.plot(t[failed], np.full(int(failed.sum()), 0.03 + 0.03 * n), "x", color=line.get_color(), transform=foot)
        ax.axhline(0.0, color="0.5", lw=0.8)
        ax.set_ylabel("change of the index\nwhen removed [%]")
        ax.set_title(ds.attrs[f"{name}_criterion"], fontsize=9)
        ax.legend(fontsize=7, ncol=3, loc="best")
    axes[-1].set_xlabel("time [s]")
    failed = "; x: the re-solved optimum infeasible" if method != KEPT else ""
    what = textwrap.fill(f"{method}{failed}", 90)
    figure.suptitle(f"{ds.attrs['model_name']}: the removal method (Cholewicki & VanVliet 2002)\n{what}", fontsize=10)
    return figure
