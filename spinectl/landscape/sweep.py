"""Sweeps over the (E, Lambda) grid: the paper's landscapes as an xarray Dataset.

The points are solved by :mod:`spinectl.landscape.columns`. The Dataset carries the answers, the
per-segment coefficients that define every problem (so that later analyses, e.g. delay margins, need
not recompute them) and the resolved configuration; docs/optimisation.md lists the schema with units.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr
from tqdm import tqdm

from .._validate import range_spec
from ..atomic import check_writable
from ..errors import ModelError, ParameterError
from ..model import config, source
from ..model.checks import check_axis_range
from ..model.params import Model
from ..units import CM_PER_M
from . import budget, columns, netcdf
from .columns import DEFAULT_CHUNK, passive_columns
from .schema import landscape_dataset

METHODS = ("fast", "per-point")
"""'fast': exact batched active sets (:func:`spinectl.optimise.active_set.solve_block`, falling back to stacked
Clarabel blocks); 'per-point': the cvxpy reference."""

MAX_GRID_POINTS = 1_000_000
"""Most points of one sweep, every axis counted (E x Lambda x the K values): the answer alone takes
about 1.2 kB a point (1.2 GB here, 3 GB at its peak), and at about 40 us a point the fast path needs
some minutes. A larger request is more likely a typo (a step count in place of a point count) than a
plan. Below it, a sweep must also fit in the available memory and its file on the free disk
(:func:`spinectl.landscape.budget.check`)."""


def parse_grid(spec: str, name: str, bounds: tuple[float, float] | None = None) -> np.ndarray:
    """A grid axis from ``"start:stop:num"`` (inclusive, metres) or a single value.

    Parameters
    ----------
    spec : str
        E.g. ``"0:0.08:81"`` or ``"0.03"``.
    name : str
        The option, for the error message.
    bounds : (float, float), optional
        The allowed range [m] (``geometry.eccentricity_range``, ``lordosis_range``): an axis beyond it
        is refused naming ``spec`` as typed, and the spec in metres where cm were likely typed.

    Returns
    -------
    numpy.ndarray, shape (num,)
        The axis [m], ``numpy.linspace(start, stop, num)``, or the single value.

    Raises
    ------
    ParameterError
        Naming ``name`` (e.g. ``"--E"``) and the allowed form (NUM = 1 only with START = STOP), or the
        range and the spec as typed.
    """
    axis = range_spec(name, spec, MAX_GRID_POINTS, "in metres, e.g. 0:0.08:81")
    _check_bounds(axis, spec, name, bounds)
    return axis


def _check_bounds(axis: np.ndarray, spec: str, name: str, bounds) -> None:
    """Refuse an axis beyond ``bounds``, naming the spec as typed (not its first bad point) and a cm slip."""
    if bounds is None:
        return
    parts = spec.split(":")
    in_metres = ":".join([f"{float(p) / CM_PER_M:g}" for p in parts[:2]] + parts[2:])
    check_axis_range(name, axis, bounds, spec, in_metres)


def sweep(
    model: Model,
    eccentricity,
    lordosis,
    *,
    method: str = "fast",
    chunk_size: int = DEFAULT_CHUNK,
    progress: bool | None = None,
    coupled: bool = False,
    out=None,
    notify=None,
) -> xr.Dataset:
    """Minimum PCSA and counter torques on the grid E x Lambda (Figures 3 and 4).

    Parameters
    ----------
    model : Model
        Its ``passive.stiffness`` is the K of this landscape.
    eccentricity, lordosis : array_like, 1-D
        Grid axes E and Lambda [m].
    method : {'fast', 'per-point'}
    chunk_size : int
        Grid points per chunk.
    progress : bool or None
        Show a progress bar on stderr; None: only on a terminal.
    coupled : bool
        Also the coupled chain's SDP variables (:data:`spinectl.landscape.schema.ON_REQUEST`, docs/chain.md).
    out, notify
        As for :func:`passive_sweeps`: where the answer goes (its free disk checked), who hears a long sweep's estimate.

    Returns
    -------
    xarray.Dataset
        Dimensions ``E``, ``Lambda``, ``segment``, ``muscle``; schema in docs/optimisation.md.
    """
    options = {"method": method, "chunk_size": chunk_size, "progress": progress, "coupled": coupled}
    options |= {"out": out, "notify": notify}
    return passive_sweeps([model], eccentricity, lordosis, **options)[0]


def passive_sweeps(
    models,
    eccentricity,
    lordosis,
    *,
    method: str = "fast",
    chunk_size: int = DEFAULT_CHUNK,
    progress: bool | None = None,
    coupled: bool = False,
    out=None,
    notify=None,
) -> list[xr.Dataset]:
    """:func:`sweep` of several models that differ in their passive stiffness alone (K, its convention), in one pass.

    The coefficients that do not depend on K are computed once per chunk for all of them
    (:func:`spinectl.landscape.columns.passive_columns`); each Dataset equals that of its
    own :func:`sweep`.

    Parameters
    ----------
    models : sequence of Model
        Equal but for ``passive``; at least one.
    eccentricity, lordosis : array_like, 1-D
        Grid axes E and Lambda [m].
    method, chunk_size, progress, coupled
        As for :func:`sweep`; one progress bar for all models.
    out : str or Path, optional
        Where the answer will be written: the estimate of its file must fit on that file system.
    notify : callable, optional
        Told the estimate (:meth:`spinectl.landscape.budget.Estimate.line`) of work long enough to deserve it.

    Returns
    -------
    list of xarray.Dataset
        One landscape per model, in the order of ``models``.

    Raises
    ------
    ParameterError
        A bad option or grid (as :func:`sweep`), models that differ in more than ``passive``, or
        more points than the available memory holds (:func:`spinectl.landscape.budget.check`).
    OutputError
        The file estimated would not fit on the free disk at ``out``.
    """
    if method not in METHODS:
        raise ParameterError("method", f"must be one of {', '.join(map(repr, METHODS))} (got {method!r})")
    if int(chunk_size) < 1:
        raise ParameterError("chunk_size", f"must be >= 1 (got {chunk_size})")
    e_axis = np.atleast_1d(np.asarray(eccentricity, float))
    l_axis = np.atleast_1d(np.asarray(lordosis, float))
    if e_axis.ndim != 1 or l_axis.ndim != 1 or e_axis.size * l_axis.size > MAX_GRID_POINTS:
        raise ParameterError("grid", f"must be two 1-D axes with at most {MAX_GRID_POINTS:,} points in all")
    for name, axis in (("E", e_axis), ("Lambda", l_axis)):
        distinct(name, axis)
    e_grid, l_grid = (a.ravel() for a in np.meshgrid(e_axis, l_axis, indexing="ij"))
    columns._check_passive_only(models)  # before the estimate, which solves the first model at one point
    try:
        cost = estimate(models[0], e_grid[:1], l_grid[:1], e_grid.size * len(models), chunk_size, coupled)
    except ModelError:  # the sweep itself says so, naming the grid rather than its first point
        cost = None
    if cost is not None:
        budget.check(cost, out)
        if cost.long and notify is not None:
            notify(cost.line())
    disable = None if progress is None else not progress  # None: tqdm shows it on a terminal only
    with tqdm(total=e_grid.size * len(models), disable=disable, unit="pt", desc="sweep") as bar:
        options = {"method": method, "chunk_size": chunk_size, "update": bar.update, "coupled": coupled}
        answers = passive_columns(models, e_grid, l_grid, **options)
    shape = (e_axis.size, l_axis.size)
    datasets = []
    for model, (arrays, per_point) in zip(models, answers, strict=True):
        arrays = {name: values.reshape(shape + values.shape[1:]) for name, values in arrays.items()}
        datasets.append(landscape_dataset(model, e_axis, l_axis, arrays, method, per_point))
    return datasets


def estimate(model: Model, eccentricity, lordosis, points: int, chunk_size: int, coupled: bool) -> budget.Estimate:
    """What a sweep of ``points`` points costs, from the answer at one point (its variables' bytes).

    Parameters
    ----------
    model : Model
        The model (its segments and muscles fix the bytes of a point).
    eccentricity, lordosis : numpy.ndarray, shape (1,)
        One point of the grid [m], solved to measure the answer's bytes.
    points : int
        Points of the whole sweep, every K counted.
    chunk_size : int
        Points per stacked problem (its working memory).
    coupled : bool
        The coupled chain's SDPs too.

    Returns
    -------
    spinectl.landscape.budget.Estimate
        Memory (answer times :data:`~spinectl.landscape.budget.SWEEP_MEMORY_PER_BYTE`, plus one chunk's
        working memory), the NetCDF file and the CPU time (the benchmark's cost per point).
    """
    arrays, _ = passive_columns([model], eccentricity, lordosis, coupled=coupled)[0]
    per_point = sum(values.nbytes for values in arrays.values())
    seconds = budget.SWEEP_SECONDS_PER_POINT + coupled * budget.COUPLED_SECONDS_PER_POINT
    return budget.Estimate(
        "sweep",
        points,
        memory=points * per_point * budget.SWEEP_MEMORY_PER_BYTE
        + min(points, chunk_size) * budget.WORKING_BYTES_PER_POINT,
        disk=points * per_point * budget.NETCDF_BYTES_PER_BYTE,
        seconds=points * seconds,
    )


def distinct(name: str, axis: np.ndarray) -> None:
    """Raise :class:`ParameterError` if ``axis`` repeats a value: a coordinate must pick one point.

    A repeated E, Lambda or K (``--K 15,15``, ``--E 0:0:3``) would be written, and then
    no reader could select one landscape by it.

    Parameters
    ----------
    name : str
        The axis, for the message.
    axis : numpy.ndarray, 1-D
        Its values, in its unit.
    """
    values, counts = np.unique(axis, return_counts=True)
    if np.any(counts > 1):
        repeated = ", ".join(f"{x:g}" for x in values[counts > 1])
        raise ParameterError(name, f"must not repeat a value (repeated: {repeated})")


def stiffness_sweep(model: Model, stiffnesses, eccentricity, lordosis, **options) -> xr.Dataset:
    """:func:`sweep` for several passive stiffnesses K [N m/rad], stacked along a ``K`` dimension.

    The landscapes are solved in one pass (:func:`passive_sweeps`). ``config_toml`` is then
    the model of the first K; the ``K`` coordinate gives each one's ``passive.stiffness``
    (convention: ``passive_convention``).

    Parameters
    ----------
    model : Model
    stiffnesses : sequence of float
        K values [N m/rad].
    eccentricity, lordosis : array_like, 1-D
        Grid axes [m].
    **options
        Passed to :func:`sweep`.

    Returns
    -------
    xarray.Dataset
        The landscapes of :func:`sweep` stacked along ``K`` [N m/rad], in the order of
        ``stiffnesses``.

    Raises
    ------
    ParameterError
        A K repeated (:func:`distinct`), or as :func:`sweep`.
    """
    distinct("K", np.asarray(stiffnesses, float))
    models = [config.set_parameter(model, "passive.stiffness", float(k)) for k in stiffnesses]
    return stack_stiffnesses(passive_sweeps(models, eccentricity, lordosis, **options), model)


def stack_stiffnesses(parts, model: Model) -> xr.Dataset:
    """Landscapes of one model at several K stacked along a ``K`` dimension, as :func:`stiffness_sweep` gives them.

    Parameters
    ----------
    parts : sequence of xarray.Dataset
        :func:`sweep`'s landscapes (scalar ``K``), distinct in K alone.
    model : Model
        The model they share but for K: its source names every K (:func:`spinectl.model.source.attributes`).

    Returns
    -------
    xarray.Dataset
        Stacked along ``K`` [N m/rad] in the order of ``parts``; the attributes of the first,
        with the source's naming every K, and ``points_solved_per_point`` summed.
    """
    combined = xr.concat(parts, dim="K", data_vars="all", coords="minimal", compat="override", combine_attrs="override")
    combined.attrs |= source.attributes(model, stiffnesses=combined["K"].values)
    combined.attrs["points_solved_per_point"] = sum(p.attrs["points_solved_per_point"] for p in parts)
    return combined


def write_sweep(model: Model, eccentricity, lordosis, path, *, stiffnesses=None, notify=None, **options) -> xr.Dataset:
    """:func:`sweep` for one K, :func:`stiffness_sweep` for several, saved as NetCDF: ``spinectl sweep``.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : array_like, 1-D
        Grid axes E and Lambda [m].
    path : str or Path
        NetCDF file, written atomically (:func:`spinectl.landscape.netcdf.save`); checked
        before the solves, so that a typo costs a second, not the sweep.
    stiffnesses : sequence of float, optional
        Passive stiffnesses K [N m/rad]; one gives a landscape with a scalar ``K``, several a
        ``K`` dimension. Default (None or empty): the model's K.
    notify : callable, optional
        Told the estimate of a long sweep in one line before it starts (:func:`passive_sweeps`).
    **options
        Passed to :func:`sweep` (``method``, ``chunk_size``, ``progress``).

    Returns
    -------
    xarray.Dataset
        What was written.

    Raises
    ------
    OutputError
        ``path`` cannot be written (or named to the NetCDF library, :func:`.netcdf.check_name`), or the
        file estimated would not fit on its file system.
    ParameterError
        A bad option or K, ``path`` not ending in ``.nc`` (named ``--out``, as the CLI's option), more
        than :data:`MAX_GRID_POINTS` points (E x Lambda x K), or more than the memory holds.
    """
    if Path(path).suffix.lower() != ".nc":  # NetCDF under another name (x.csv) misleads every reader
        raise ParameterError("--out", f"must end in .nc: the sweep is written as NetCDF (got {str(path)!r})")
    stiffnesses = list(stiffnesses or [model.passive.stiffness])
    points = np.size(eccentricity) * np.size(lordosis) * len(stiffnesses)
    if points > MAX_GRID_POINTS:  # every K is a landscape of its own: 10 values of K cost 10 grids
        raise ParameterError(
            "grid",
            f"E x Lambda x K must have at most {MAX_GRID_POINTS:,} points in all (got {np.size(eccentricity):,} x "
            f"{np.size(lordosis):,} x {len(stiffnesses):,} = {points:,})",
        )
    netcdf.check_name(path)
    check_writable(path)
    options |= {"out": path, "notify": notify}
    if len(stiffnesses) == 1:
        if stiffnesses[0] != model.passive.stiffness:  # else the model's own K, not an override
            model = config.set_parameter(model, "passive.stiffness", stiffnesses[0])
        dataset = sweep(model, eccentricity, lordosis, **options)
    else:
        dataset = stiffness_sweep(model, stiffnesses, eccentricity, lordosis, **options)
    netcdf.save(dataset, path)
    return dataset


def describe(dataset: xr.Dataset) -> str:
    """How many points a sweep solved, and the ranges of both landscapes, in one line.

    Parameters
    ----------
    dataset : xarray.Dataset
        Output of :func:`sweep` or :func:`stiffness_sweep`.

    Returns
    -------
    str
        E.g. ``"preset wagner2012, K = 0 N m/rad, convention paper: 25 points (25 solved, 0 infeasible or
        failed); min PCSA 10.2-40.3 cm2, ||CT|| 0.0-31.5 N m"`` (the model's line from the ``model`` attribute);
        the ranges only if some point was solved, and a warning naming the points whose
        status is ``optimal_inaccurate`` (the solver did not meet its tolerances: their
        numbers may be far off) if there are any.
    """
    status = dataset["status"].values
    pcsa, torque = dataset["min_pcsa_cm2"].values, dataset["counter_torque_norm_Nm"].values
    ok = np.isfinite(pcsa)
    ranges = ""
    if ok.any():
        ranges = (
            f"; min PCSA {np.nanmin(pcsa):.1f}-{np.nanmax(pcsa):.1f} cm2, "
            f"||CT|| {np.nanmin(torque):.1f}-{np.nanmax(torque):.1f} N m"
        )
    inaccurate = int(np.sum(status == "optimal_inaccurate"))
    if inaccurate:
        ranges += f"; WARNING: {inaccurate} inaccurate (status optimal_inaccurate: values may be far off)"
    model = f"{dataset.attrs['model']}: " if "model" in dataset.attrs else ""
    points = "1 point" if status.size == 1 else f"{status.size} points"
    return f"{model}{points} ({int(ok.sum())} solved, {int((~ok).sum())} infeasible or failed){ranges}"
