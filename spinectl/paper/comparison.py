"""Two landscapes on the same grid compared: difference and ratio maps (``spinectl plot a.nc --vs b.nc``).

For each K the two files share, the minimum PCSA (Figure 3 / S1) and ‖CT‖ (Figure 4) of the first
file minus, and over, those of the second, drawn as the landscape figures are
(:mod:`spinectl.paper.figures`). Landscapes on different grids are not interpolated: the comparison
names the axis that differs and stops.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib.figure import Figure

from ..canvas import save_figures
from ..errors import ParameterError
from ..landscape import netcdf
from . import figures

COMPARED = (
    ("min_pcsa_cm2", "minimum PCSA", "cm²", "min_pcsa"),
    ("counter_torque_norm_Nm", "‖CT‖", "N m", "counter_torque"),
)
"""The variables compared: name in the dataset, what it is, unit, stem of the file name."""

ROUNDING = float(np.sqrt(np.finfo(float).eps))
"""Relative rounding level of a map's values [1]: sqrt(machine epsilon), 1.5e-8. ‖CT‖ is found by
minimising its square, whose optimum is known to about eps times its scale squared, so ‖CT‖ itself only
to about sqrt(eps) times its scale (the largest value of the map); below that a value is rounding noise
(0 at the optimum, e.g. 3e-15 N m at position A) and a ratio over it is undefined
(docs/robustness.md, "Analysis commands")."""

_TOLERANCE = 1e-9
"""Coordinates [m, or K's unit] closer than this are the same grid point (rounding in a file)."""


def stiffnesses(dataset: xr.Dataset) -> list[float]:
    """The values of K (N m/rad or 1/s², by its convention) of a landscape, whether K is a dimension or a scalar.

    Parameters
    ----------
    dataset : xarray.Dataset

    Returns
    -------
    list of float
    """
    return [float(k) for k in np.atleast_1d(dataset["K"].values)]


def check_same_grid(first: xr.Dataset, second: xr.Dataset) -> None:
    """Raise unless two landscapes share their E and Lambda axes and their values of K.

    Parameters
    ----------
    first, second : xarray.Dataset

    Raises
    ------
    ParameterError
        Field ``--vs``: the axis that differs, with both files' ranges.
    """
    for name, unit in (("E", "m"), ("Lambda", "m"), ("K", figures.k_unit(first.attrs.get("passive_convention", "?")))):
        x, y = np.atleast_1d(first[name].values), np.atleast_1d(second[name].values)
        if x.shape != y.shape or not np.allclose(x, y, rtol=0, atol=_TOLERANCE):
            raise ParameterError(
                "--vs",
                f"the grids differ in {name}: {_axis(x)} {unit} in the first file, {_axis(y)} {unit} in the second; "
                "sweep both on the same grid",
            )


def _axis(values: np.ndarray) -> str:
    return f"{values.size} value(s) {values.min():g} to {values.max():g}"


def _at(dataset: xr.Dataset, stiffness: float) -> xr.Dataset:
    return dataset.sel(K=stiffness) if "K" in dataset.dims else dataset


def comparison_set(first: xr.Dataset, second: xr.Dataset, labels=("first", "second"), format: str = "png") -> dict:
    """Difference and ratio maps of the minimum PCSA and ‖CT‖ of two landscapes, by file name.

    Parameters
    ----------
    first, second : xarray.Dataset
        Landscapes on the same grid (:func:`check_same_grid`), e.g. two presets' sweeps.
    labels : tuple of str
        How the titles name the two (e.g. their file names).
    format : str
        File format of the names, one of :data:`~spinectl.paper.figures.files.FORMATS`.

    Returns
    -------
    dict of str to matplotlib.figure.Figure
        ``{stem}_difference_K{K}.{format}`` (first minus second, in the variable's unit) and
        ``{stem}_ratio_K{K}.{format}`` (first over second [1], white where either is infeasible or
        the second is at rounding level, :func:`rounding_level`, the title says which) for each stem
        of :data:`COMPARED` and each K; nothing is written.

    Raises
    ------
    ParameterError
        The grids differ (field ``--vs``).
    """
    check_same_grid(first, second)
    drawn: dict[str, Figure] = {}
    units = [figures.k_unit(d.attrs.get("passive_convention", "?")) for d in (first, second)]
    for k in stiffnesses(first):
        a, b = _at(first, k), _at(second, k)
        where = f"K = {k:g} {units[0]}"
        if units[1] != units[0]:  # the same number, two quantities: name both
            where = f"K = {k:g} {units[0]} ({labels[0]}), {units[1]} ({labels[1]})"
        for name, what, unit, stem in COMPARED:
            suffix = f"_K{figures.k_in_name(k)}.{format}"
            difference = a[name] - b[name]
            title = f"{what}: {labels[0]} minus {labels[1]}, {where}"
            drawn[f"{stem}_difference{suffix}"] = figures.landscape_figure(difference, title, f"difference [{unit}]")
            ratio, blank = _ratio(a[name], b[name], what, unit, labels[1])
            title = f"{what}: {labels[0]} over {labels[1]}, {where}"
            drawn[f"{stem}_ratio{suffix}"] = figures.landscape_figure(ratio, title, "ratio [1]", blank)
    return drawn


def rounding_level(field: xr.DataArray) -> float:
    """The largest magnitude of a map that is rounding noise: :data:`ROUNDING` times its largest finite magnitude.

    Parameters
    ----------
    field : xarray.DataArray
        A map, e.g. ‖CT‖ [N m] over E and Lambda; NaN (infeasible) points are left out.

    Returns
    -------
    float
        In the unit of ``field``; 0 for a map without a finite value.
    """
    values = np.abs(field.values[np.isfinite(field.values)])
    return ROUNDING * float(values.max()) if values.size else 0.0


def _ratio(a: xr.DataArray, b: xr.DataArray, what: str, unit: str, label: str) -> tuple[xr.DataArray, str]:
    """``a / b`` where both are feasible and ``b`` is above its :func:`rounding_level`; the title's line on the rest."""
    level = rounding_level(b)
    feasible = np.isfinite(a) & np.isfinite(b)
    noise = feasible & (np.abs(b) <= level)
    ratio = (a / b).where(feasible & ~noise)
    infeasible, undefined = int((~feasible).sum()), int(noise.sum())
    parts = [f"no self-stable activation in one file or both ({infeasible})"] if infeasible else []
    if undefined:
        parts.append(
            f"{what} of {label} at rounding level, ≤ {level:.1g} {unit} (√ε × its largest): undefined ({undefined})"
        )
    return ratio, f"white ({infeasible + undefined} of {a.size} points): {'; '.join(parts)}"


def draw_comparison(first, second, out_dir, format: str = "png", dpi: float = figures.DPI) -> list:
    """Load two sweep files, draw :func:`comparison_set` and save it into ``out_dir`` (all or none).

    Parameters
    ----------
    first, second : str or Path
        NetCDF files of ``spinectl sweep`` or ``reproduce`` (:func:`spinectl.landscape.netcdf.load`).
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

    Raises
    ------
    ParameterError
        A file that is no sweep (field ``results``), or grids that differ (field ``--vs``).
    OutputError
        ``out_dir`` cannot take the files; nothing is written.
    """
    labels = (Path(first).name, Path(second).name)
    drawn = comparison_set(netcdf.load(first), netcdf.load(second), labels, format)
    return save_figures(drawn, out_dir, dpi)
