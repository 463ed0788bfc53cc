"""Matplotlib figures without pyplot: drawn on the Agg canvas, saved atomically as PNG.

The figure functions of :mod:`spinectl.reflex.plots` and :mod:`spinectl.paper.figures`
draw on a :func:`new_figure` and return it; :func:`save_png` is the separate save step.
Nothing here selects a backend or touches pyplot's global figure list, so a figure is
garbage-collected like any object, works without a display, and shows itself in a
notebook (``display(fig)``).
"""

from __future__ import annotations

from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from .atomic import atomic_path


def new_figure(**options) -> Figure:
    """A new figure with its own Agg canvas.

    Parameters
    ----------
    **options
        Passed to :class:`matplotlib.figure.Figure`, e.g. ``figsize`` [in] or ``layout``.

    Returns
    -------
    matplotlib.figure.Figure
        An empty figure, not registered with pyplot.
    """
    figure = Figure(**options)
    FigureCanvasAgg(figure)
    return figure


def save_png(figure: Figure, path: str | Path, dpi: float) -> Path:
    """Write ``figure`` as a PNG file atomically (:func:`spinectl.atomic.atomic_path`).

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        The figure to write.
    path : str or Path
        The PNG file; its folder is created if missing.
    dpi : float
        Resolution [dots per inch].

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    OutputError
        The file cannot be written; a previous file of that name is left as it was.
    """
    with atomic_path(path) as tmp:
        figure.savefig(tmp, format="png", dpi=dpi)
    return Path(path)
