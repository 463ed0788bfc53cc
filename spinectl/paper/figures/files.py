"""The save step and the files' names: PNG, PDF or SVG by the suffix, the resolutions accepted, K in a name.

:func:`save_figure` writes one figure atomically (:func:`spinectl.canvas.save_file`); the name
functions give each figure of a landscape its file name, distinct for distinct stiffnesses.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ...canvas import save_file
from ...errors import ParameterError

DPI = 150
MIN_DPI, MAX_DPI = 10, 1200
"""Resolutions [dots per inch] that :func:`save_figure` accepts: legible, and an image of tens of megapixels at most."""
FORMATS = ("png", "pdf", "svg")
"""File formats of :func:`save_figure`, named by the file's suffix."""


def check_dpi(dpi: float) -> None:
    """Raise :class:`~spinectl.errors.ParameterError` unless ``dpi`` is a resolution matplotlib can render.

    Parameters
    ----------
    dpi : float
        Dots per inch: finite, 10 to :data:`MAX_DPI`.
    """
    if not (np.isfinite(dpi) and MIN_DPI <= dpi <= MAX_DPI):
        raise ParameterError("--dpi", f"must be {MIN_DPI} to {MAX_DPI} dots per inch (got {dpi:g})")


def save_figure(fig: Figure, path: str | Path, dpi: float = DPI) -> Path:
    """The save step: write ``fig`` atomically (:func:`spinectl.atomic.atomic_path`), its format named by the suffix.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        A figure of :mod:`spinectl.paper.figures` or of :mod:`spinectl.paper.drawing`.
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
    """File name of :func:`~spinectl.paper.figures.ratios.ratio_figure`.

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
    """File name of :func:`~spinectl.paper.figures.ratios.coupled_ratio_figure`.

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
