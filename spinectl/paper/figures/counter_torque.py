"""Figure 4: the local counter torques ‖CT‖, with the ±30 N m limit of the local muscles as a contour."""

from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.figure import Figure

from ...units import CM_PER_M, M2_PER_CM2
from .. import landmarks
from .labels import _clear_of, _label_place
from .landscape import _landscape, grid_marks
from .style import _k_label


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
    (:func:`.labels._label_place`); C's label moves to a side of its point off the line. Nothing is drawn
    where ‖CT‖ does not cross the limit.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The axes of :func:`~spinectl.paper.figures.landscape.landscape_figure` of ``field``.
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
