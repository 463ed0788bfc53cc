"""Matplotlib figures without pyplot: drawn on the Agg canvas, saved atomically.

The figure functions of :mod:`spinectl.reflex.plots` and :mod:`spinectl.paper.figures`
draw on a :func:`new_figure` and return it; :func:`save_file` is the separate save step,
:func:`save_figures` that of a set of figures into one folder, swapped in as a whole.
Nothing here selects a backend or touches pyplot's global figure list, so a figure is
garbage-collected like any object, works without a display, and shows itself in a
notebook (``display(fig)``).
"""

from __future__ import annotations

from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from .atomic import atomic_path, staged_directory


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


def laid_out(figure: Figure):
    """Lay ``figure`` out as its next draw will, without drawing it; returns a renderer to measure with.

    The layout engine (if any) places the axes, then each axes takes its aspect, so axes' boxes, data
    transforms and text extents hold as they will be drawn: labels can be placed by their measured
    extents (:mod:`spinectl.paper.figures`, :mod:`spinectl.paper.drawing`). Cheaper than
    ``draw_without_rendering``, and no print: that one prints to memory through the canvas's
    ``print_png``, so a failing writer would fail here, before any file is written.

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        A figure on a canvas with a renderer (the Agg canvas of :func:`new_figure`, pyplot's).

    Returns
    -------
    matplotlib.backend_bases.RendererBase
        The canvas's renderer, for ``get_window_extent``.
    """
    engine = figure.get_layout_engine()
    if engine is not None:
        engine.execute(figure)
    for ax in figure.axes:
        if ax.get_axes_locator() is None:  # an inset (a colour bar) is placed by its locator when drawn
            ax.apply_aspect()
    return figure.canvas.get_renderer()


def save_file(figure: Figure, path: str | Path, dpi: float) -> Path:
    """Write ``figure`` atomically in the format its suffix names (``.png``, ``.pdf``, ``.svg``, ...).

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        The figure to write.
    path : str or Path
        The file; its folder is created if missing.
    dpi : float
        Resolution of raster output [dots per inch].

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    OutputError
        The file cannot be written; a previous file of that name is left as it was.
    """
    file_format = Path(path).suffix.lower().lstrip(".") or "png"
    with atomic_path(path) as tmp:
        if file_format == "png" and isinstance(figure.canvas, FigureCanvasAgg):
            _print_png(figure, tmp, dpi)
        else:
            figure.savefig(tmp, format=file_format, dpi=dpi)
    return Path(path)


def _print_png(figure: Figure, path, dpi: float) -> None:
    """``figure.savefig(path, dpi=dpi)`` as PNG, the figure drawn once: the same file, byte for byte.

    ``savefig`` draws a figure that has a layout engine twice: once without rendering, to
    lay it out, and once to render it with the layout engine off
    (``FigureCanvasBase.print_figure``). The Agg canvas's own ``print_png`` lays the figure
    out and renders it in one draw (benchmarks/bench_reproduce.py measures the saving).
    """
    original = figure.dpi
    figure.set_dpi(dpi)
    try:
        figure.canvas.print_png(path)
    finally:
        figure.set_dpi(original)


def save_figures(figures: dict[str, Figure], folder: str | Path, dpi: float, replaces=()) -> list[Path]:
    """Write a set of figures into ``folder``, each in the format of its name's suffix: all of them or none.

    They are written into a staging folder that then replaces ``folder`` as a whole
    (:func:`spinectl.atomic.staged_directory`; the other files of ``folder`` are kept), so
    an interruption or a full disk half-way leaves no mix of new and old figures.

    Parameters
    ----------
    figures : dict of str to matplotlib.figure.Figure
        File name -> figure.
    folder : str or Path
        The output folder; created if missing.
    dpi : float
        Resolution of raster output [dots per inch].
    replaces : iterable of str
        Names of earlier figures of the set that go even where ``figures`` has none of that name.

    Returns
    -------
    list of Path
        The files written, in the order of ``figures``.

    Raises
    ------
    OutputError
        ``folder`` cannot take the files (checked before the first is written); nothing is written.
    """
    with staged_directory(folder, figures, replaces) as stage:
        for name, figure in figures.items():
            save_file(figure, stage / name, dpi)
    return [Path(folder) / name for name in figures]
