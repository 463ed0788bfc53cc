"""A parameter study's E x Lambda slices drawn (``spinectl plot STORE.zarr``).

A study store (:mod:`spinectl.landscape.study`) holds one landscape per value of each parameter axis
and per Monte-Carlo draw. Each slice is drawn as the landscape figures are
(:func:`~spinectl.paper.figures.landscape.landscape_figure`): its minimum PCSA and its ‖CT‖ with the ±30 N m
limit, the title naming the slice's parameter values with their units. A store with more slices than
:data:`MAX_SLICES` is refused with the way to select from it.
"""

from __future__ import annotations

import itertools
import warnings
from pathlib import Path

import xarray as xr

from ..canvas import save_figures
from ..errors import ParameterError
from . import comparison, figures

MAX_SLICES = 24
"""Most slices one ``spinectl plot`` of a store draws (two figures each)."""


def slice_figures(dataset: xr.Dataset, format: str = "png", computed: xr.DataArray | None = None) -> dict:
    """The minimum PCSA and ‖CT‖ (with the ±30 N m limit) of every E x Lambda slice of a study, by file name.

    Parameters
    ----------
    dataset : xarray.Dataset
        A study store as :func:`spinectl.landscape.study.load` reads it.
    format : str
        One of :data:`~spinectl.paper.figures.files.FORMATS`.
    computed : xarray.DataArray of bool, optional
        Which points are computed (:func:`spinectl.landscape.study.store.computed`); the others are
        drawn white as not computed, counted apart from infeasible points. Default: every point.

    Returns
    -------
    dict of str to matplotlib.figure.Figure
        ``{stem}_{dim}={value}_....{format}`` for each stem of
        :data:`spinectl.paper.comparison.COMPARED` and each slice (``{stem}.{format}`` for a study
        without axes); nothing is written.

    Raises
    ------
    ParameterError
        More than :data:`MAX_SLICES` slices (field ``results``), naming the dimensions.
    """
    dims = [d for d in dataset["min_pcsa_cm2"].dims if d not in ("E", "Lambda")]
    count = 1
    for d in dims:
        count *= dataset.sizes[d]
    if count > MAX_SLICES:
        shape = " x ".join(f"{d} ({dataset.sizes[d]})" for d in dims)
        raise ParameterError(
            "results",
            f"the study has {count} E x Lambda slices ({shape}); spinectl plot draws at most {MAX_SLICES}: "
            "select some with spinectl.landscape.study.load(...).isel(...) and "
            "spinectl.paper.figures.landscape_figure (docs/studies.md)",
        )
    drawn = {}
    for index in itertools.product(*(range(dataset.sizes[d]) for d in dims)):
        part = dataset.isel(dict(zip(dims, index, strict=True)))
        values = [(d, part[d].values.item()) for d in dims]
        where = ", ".join(f"{d} = {v:g}{_unit(part[d])}" for d, v in values) or "the study's model"
        name = "".join(f"_{d}={v:g}" for d, v in values)
        done = None if computed is None else computed.isel(dict(zip(dims, index, strict=True)))
        for variable, what, unit, stem in comparison.COMPARED:
            title = f"{what} of the study, {where}"
            fig = figures.landscape_figure(part[variable], title, f"{what} [{unit}]", _blank(part[variable], done))
            if variable == "counter_torque_norm_Nm":  # as Figure 4
                figures.torque_limit(fig.axes[0], part[variable])
            drawn[f"{stem}{name}.{format}"] = fig
    return drawn


def _blank(field: xr.DataArray, done: xr.DataArray | None) -> str | None:
    """The title's line on a slice's white points where some are not computed (None: all computed)."""
    if done is None or bool(done.all()):
        return None
    missing = int((~done).sum())
    infeasible = int((done & field.isnull()).sum())
    parts = [f"not computed yet, the study is unfinished ({missing})"]
    if infeasible:
        parts.append(f"no self-stable activation within the bounds ({infeasible})")
    return f"white ({missing + infeasible} of {field.size} points): {'; '.join(parts)}"


def unfinished(computed: xr.DataArray, path) -> str:
    """The warning for a store with points not computed, or ``""``.

    Parameters
    ----------
    computed : xarray.DataArray of bool
        :func:`spinectl.landscape.study.store.computed` of the store.
    path : str or Path
        The store, as the user named it.

    Returns
    -------
    str
        E.g. ``'s.zarr' is unfinished: 9 of 18 points not computed, drawn white as such; run the study
        again with --resume``.
    """
    missing = int((~computed).sum())
    if not missing:
        return ""
    return (
        f"{str(path)!r} is unfinished: {missing} of {computed.size} points not computed, drawn white as such; "
        "run the study again with --resume"
    )


def _unit(coordinate: xr.DataArray) -> str:
    """The unit of a study axis as a title writes it after a value (" kg"), from the store's ``units``."""
    unit = coordinate.attrs.get("units", "").replace("^2", "²")  # K under eq. 2 as printed: 1/s^2
    return f" {unit}" if unit and unit != "1" else ""


def draw_study(path, out_dir, format: str = "png", dpi: float = figures.DPI) -> list[Path]:
    """Read a study store and save :func:`slice_figures` into ``out_dir`` (all or none).

    Parameters
    ----------
    path : str or Path
        The store (a folder written by ``spinectl study``).
    out_dir : str or Path
        Folder for the figures.
    format : str
        One of :data:`~spinectl.paper.figures.files.FORMATS`.
    dpi : float
        Resolution of PNG files.

    Returns
    -------
    list of Path
        The files written.

    Warns
    -----
    UserWarning
        The store is unfinished (:func:`unfinished`): its points not yet computed are drawn white as such.

    Raises
    ------
    ParameterError
        Not a study store (field ``store``), or too many slices (field ``results``).
    OutputError
        ``out_dir`` cannot take the files; nothing is written.
    """
    from ..landscape.study import store  # zarr and dask only for a store

    dataset = store.load(path)
    computed = store.computed(dataset)
    written = save_figures(slice_figures(dataset, format, computed), out_dir, dpi)
    if note := unfinished(computed, path):
        warnings.warn(note, UserWarning, stacklevel=2)  # the CLI prints it as one line
    return written
