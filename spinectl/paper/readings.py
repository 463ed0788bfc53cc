"""Reading a landscape: a value at a position, the grid point read, and the crest of a ridge fitted sub-grid.

The instruments of the landmarks (:mod:`spinectl.paper.landmarks`): the nearest grid point of
a position (:func:`at`, :func:`grid_point`, :func:`label`), and the line Lambda = s E through a
ridge's crest or a valley's floor, located between grid points by the vertex of a parabola
(:func:`crest_fit`, :func:`vertex`, :func:`line_slope`). Pure functions of an xarray landscape
with dimensions E and Lambda (:mod:`spinectl.landscape.schema`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr


def at(dataset: xr.Dataset, name: str, position) -> float:
    """The value of a variable at one position, from the nearest grid point.

    Parameters
    ----------
    dataset : xarray.Dataset
        A landscape with dimensions E and Lambda.
    name : str
        Variable name.
    position : tuple of float
        (E, Lambda) [m].

    Returns
    -------
    float
        The value, in the variable's unit (NaN at an infeasible point).
    """
    e, lam = position
    return float(dataset[name].sel(E=e, Lambda=lam, method="nearest"))


def grid_point(dataset: xr.Dataset, position) -> tuple[float, float | None]:
    """The grid point that :func:`at` reads for ``position``: the nearest E and Lambda [m].

    Parameters
    ----------
    dataset : xarray.Dataset
        A landscape with dimensions E and Lambda.
    position : tuple of (float, float or None)
        (E, Lambda) [m]; Lambda None for a whole column.

    Returns
    -------
    tuple of (float, float or None)
        The coordinates of the nearest grid point [m] (Lambda None if not asked).
    """
    e, lam = position
    near_e = float(dataset["E"].sel(E=e, method="nearest"))
    return near_e, None if lam is None else float(dataset["Lambda"].sel(Lambda=lam, method="nearest"))


def label(position) -> str:
    """A position as the report writes it, e.g. ``"E = 3, Λ = 4 cm"``.

    Parameters
    ----------
    position : tuple of (float, float or None)
        (E, Lambda) [m]; Lambda None for a whole column.

    Returns
    -------
    str
        E and Lambda in cm, to 0.01 mm.
    """
    e, lam = position
    return f"E = {e * 100:.4g} cm" if lam is None else f"E = {e * 100:.4g}, Λ = {lam * 100:.4g} cm"


@dataclass(frozen=True)
class CrestFit:
    """The line Lambda = s E fitted to a ridge's crest (or a valley's floor).

    Attributes
    ----------
    slope : float
        s = Lambda / E [1]; NaN if fewer than one column counts.
    uncertainty : float
        Standard error of ``slope`` from the scatter of the crest about the line [1]; NaN with
        fewer than two columns.
    columns : int
        Columns E that the fit used.
    """

    slope: float
    uncertainty: float
    columns: int


def vertex(axis, values, index) -> np.ndarray:
    """Sub-grid position of an extremum: the vertex of the parabola through the grid point and its two neighbours.

    Exact for a quadratic extremum; a flat top (three equal values) stays at the grid point.

    Parameters
    ----------
    axis : array_like, shape (n,)
        The grid coordinate [any unit].
    values : array_like, shape (..., n)
        The values along the axis, one row per extremum.
    index : array_like of int, shape (...)
        The grid index of each row's extremum, strictly inside (1 to n - 2).

    Returns
    -------
    numpy.ndarray, shape (...)
        The vertex's coordinate, in the unit of ``axis``.
    """
    axis, values, index = np.asarray(axis, float), np.asarray(values, float), np.asarray(index)
    x0, x1, x2 = axis[index - 1], axis[index], axis[index + 1]
    rows = np.take_along_axis(values, np.stack([index - 1, index, index + 1], axis=-1), axis=-1)
    f0, f1, f2 = np.moveaxis(rows, -1, 0)
    top = (x1 - x0) ** 2 * (f1 - f2) - (x1 - x2) ** 2 * (f1 - f0)
    bottom = (x1 - x0) * (f1 - f2) - (x1 - x2) * (f1 - f0)
    safe = np.where(bottom == 0, 1.0, bottom)
    return np.where(bottom == 0, x1, x1 - 0.5 * top / safe)


def crest_fit(dataset: xr.Dataset, name: str, pick: str) -> CrestFit:
    """The line Lambda = s E through the crest of ``name`` (``pick`` 'max') or its floor ('min'), sub-grid.

    In every column E > 0 the extremum over Lambda is located between grid points
    (:func:`vertex`), so the slope does not move in steps of the grid. The crest
    is followed from A: the first run of consecutive columns whose extremum lies
    strictly inside the Lambda range (an extremum on the edge says the line left
    the grid; a later, separate run is another feature, not this line), skipping
    columns with an infeasible (NaN) point next to the extremum. Least squares through the origin; the
    uncertainty is the slope's standard error from the scatter of the crest.

    Parameters
    ----------
    dataset : xarray.Dataset
        A landscape with dimensions E and Lambda.
    name : str
        Variable name.
    pick : {'max', 'min'}
        Ridge or valley.

    Returns
    -------
    CrestFit
        Slope [1], its standard error [1] and the number of columns used.
    """
    field = dataset[name].transpose("E", "Lambda").values
    sign = 1.0 if pick == "max" else -1.0
    signed = np.where(np.isnan(field), -np.inf, sign * field)
    index = np.argmax(signed, axis=1)
    e, lam = dataset["E"].values, dataset["Lambda"].values
    n = field.shape[1]
    inside = (e > 0) & (index > 0) & (index < n - 1)
    inside &= np.isfinite(np.take_along_axis(signed, np.clip(index[:, None] + [-1, 0, 1], 0, n - 1), axis=1)).all(1)
    run = _first_run(inside)
    if not run.any():
        return CrestFit(np.nan, np.nan, 0)
    crest = vertex(lam, sign * field[run], index[run])
    slope = float(np.sum(e[run] * crest) / np.sum(e[run] ** 2))
    count = int(run.sum())
    if count < 2:
        return CrestFit(slope, np.nan, count)
    scatter = np.sum((crest - slope * e[run]) ** 2) / (count - 1)
    return CrestFit(slope, float(np.sqrt(scatter / np.sum(e[run] ** 2))), count)


def _first_run(mask: np.ndarray) -> np.ndarray:
    """The first run of consecutive True values of ``mask`` (all False if none)."""
    out = np.zeros_like(mask)
    start = int(np.argmax(mask))
    if not mask[start]:
        return out
    stop = start + int(np.argmin(mask[start:])) if not mask[start:].all() else mask.size
    out[start:stop] = True
    return out


def line_slope(dataset: xr.Dataset, name: str, pick: str) -> float:
    """Slope [1] of the line Lambda = s E through the crest (:func:`crest_fit`); NaN if no column counts.

    Parameters
    ----------
    dataset : xarray.Dataset
        A landscape with dimensions E and Lambda.
    name : str
        Variable name.
    pick : {'max', 'min'}
        Ridge or valley.

    Returns
    -------
    float
        s = Lambda / E [1].
    """
    return crest_fit(dataset, name, pick).slope
