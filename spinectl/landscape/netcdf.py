"""Landscapes on disk: NetCDF written atomically, read back checked, and the model they used.
"""

from __future__ import annotations

import os
import tomllib
from pathlib import Path

import numpy as np
import xarray as xr

from .._validate import printable, show
from ..atomic import atomic_path
from ..errors import OutputError, ParameterError, SpinectlError
from ..model import config
from ..model.params import Model

REQUIRED = ("min_pcsa_cm2", "counter_torque_norm_Nm", "status", "K")
"""What :func:`load` insists on finding: the variables the figures and landmarks read."""


def model_of(dataset: xr.Dataset) -> Model:
    """The resolved model a Dataset was computed with (from its ``config_toml`` attribute).

    Parameters
    ----------
    dataset : xarray.Dataset
        From :func:`~spinectl.landscape.sweep.sweep` or :func:`load`.

    Returns
    -------
    Model
        The parameters of the sweep, validated.

    Raises
    ------
    ParameterError
        No ``config_toml``, or one that is not TOML or not a valid model (an edited or
        foreign file; field ``config_toml``, the model's own field named in the message).
    """
    text = dataset.attrs.get("config_toml")
    if not isinstance(text, str):
        raise ParameterError("config_toml", f"must be the model as TOML text (got {show(text)})")
    try:
        return config.from_dict(Model, tomllib.loads(text))
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError("config_toml", f"is not valid TOML ({printable(str(exc))})") from None
    except ParameterError as exc:  # ConfigError too
        raise ParameterError("config_toml", f"is not a valid model ({printable(str(exc))})") from None


def save(dataset: xr.Dataset, path: str | Path) -> Path:
    """Write a Dataset to NetCDF atomically (:func:`spinectl.atomic.atomic_path`).

    Parameters
    ----------
    dataset : xarray.Dataset
    path : str or Path

    Returns
    -------
    Path
        ``path`` as a :class:`~pathlib.Path`, now holding the NetCDF file.

    Raises
    ------
    OutputError
        ``path`` cannot be written (a folder in the way, a full disk); the previous file is left intact.
    """
    with atomic_path(path) as tmp:
        try:
            dataset.to_netcdf(tmp, engine="netcdf4")
        except (OSError, RuntimeError) as exc:  # netCDF-C reports a full disk as e.g. "NetCDF: HDF error"
            if isinstance(exc, SpinectlError):
                raise
            raise OutputError(f"cannot write {str(path)!r}: {printable(str(exc))}{_full(path)}") from None
    return Path(path)


FULL_BELOW = 1 << 20
"""Free bytes below which a failed write names the full disk [B]: netCDF-C reports it in HDF5's words."""


def _full(path: str | Path) -> str:
    """``'; No space left on device'`` if the file system of ``path`` has (almost) no space left, else ''."""
    try:
        stats = os.statvfs(Path(path).resolve().parent)
    except OSError:
        return ""
    return "; No space left on device" if stats.f_bavail * stats.f_frsize < FULL_BELOW else ""


def load(path: str | Path) -> xr.Dataset:
    """Read a Dataset written by :func:`save` fully into memory (the file is closed again).

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    xarray.Dataset
        The landscape, loaded into memory, with at least :data:`REQUIRED`, ``E``,
        ``Lambda`` and the ``config_toml`` attribute.

    Raises
    ------
    ParameterError
        The file is missing, not NetCDF or not a sweep (field ``results``): a required
        variable, the dimensions E and Lambda (and K when K is a dimension),
        finite coordinates with no value repeated, or a ``config_toml`` that is a valid model.
    """
    path = Path(path)
    if not path.is_file():
        raise ParameterError("results", f"file not found: {path}")
    try:
        dataset = xr.load_dataset(path, engine="netcdf4")
    except (OSError, ValueError) as exc:
        raise ParameterError("results", f"{path} is not a spinectl NetCDF file ({exc.__class__.__name__})") from None
    missing = [name for name in (*REQUIRED, "E", "Lambda") if name not in dataset.variables]
    if missing or "config_toml" not in dataset.attrs:
        what = ", ".join(missing) or "attribute config_toml"
        raise ParameterError("results", f"{path} is not a spinectl sweep (missing {what})")
    problem = _layout_problem(dataset)
    if problem is None:
        try:
            model_of(dataset)
        except ParameterError as exc:
            problem = str(exc)
    if problem:
        raise ParameterError("results", f"{show(str(path))} is not a spinectl sweep as written ({printable(problem)})")
    return dataset


def _layout_problem(dataset: xr.Dataset) -> str | None:
    """What is wrong with the dimensions and coordinates that a sweep writes, or None.

    A sweep's landscapes have dimensions E and Lambda, and K when several
    stiffnesses were swept; E, Lambda and K are finite numbers, none repeated
    (what :func:`~spinectl.landscape.sweep.write_sweep` makes).
    """
    grid = ("K", "E", "Lambda") if "K" in dataset.dims else ("E", "Lambda")
    for name in REQUIRED[:-1]:
        if sorted(dataset[name].dims) != sorted(grid):  # in any order: readers select by name
            return f"{name} has dimensions {dataset[name].dims}, expected {grid}"
    for name in ("K", "E", "Lambda"):
        values = dataset[name].values
        if dataset[name].ndim != (1 if name in grid else 0) or values.dtype.kind not in "iuf":
            return f"coordinate {name} must be numbers along its own dimension"
        if not np.all(np.isfinite(values)):
            return f"coordinate {name} must be finite (got {show(values.tolist())})"
        if np.unique(values).size != values.size:
            return f"coordinate {name} must not repeat a value (got {show(values.tolist())})"
    return _value_problem(dataset)


SOLVED = ("optimal", "optimal_inaccurate")
"""Statuses of a point with an optimum: its values are numbers (others are NaN)."""

NON_NEGATIVE = ("min_pcsa_cm2", "pcsa_cm2", "counter_torque_norm_Nm")
"""Variables that are >= 0 by definition: a PCSA [cm²] and a norm [N m]."""

ROUNDING = 1e-6
"""How far below 0 a solver's rounding may leave a value of :data:`NON_NEGATIVE` (1e-6 cm², 1e-6 N m)."""


def _value_problem(dataset: xr.Dataset) -> str | None:
    """What is wrong with the values a sweep writes, or None: a PCSA or a norm that is infinite or negative,
    or NaN at a point whose status says it was solved (an edited or foreign file; figures would draw it)."""
    solved = np.isin(dataset["status"].values.astype(str), SOLVED)
    for name in NON_NEGATIVE:
        if name not in dataset.variables or dataset[name].dtype.kind not in "iuf":
            if name in REQUIRED:
                return f"{name} must be numbers"
            continue
        if not set(dataset["status"].dims) <= set(dataset[name].dims):
            return f"{name} has dimensions {dataset[name].dims}, expected {dataset['status'].dims} and its own"
        values = dataset[name].transpose(*dataset["status"].dims, ...).values
        at = solved.reshape(solved.shape + (1,) * (values.ndim - solved.ndim))
        bad = np.isinf(values) | (values < -ROUNDING) | (np.isnan(values) & at)
        if bad.any():
            first = values[bad].flat[0]
            rule = "finite where the status is optimal" if np.isnan(first) else "finite and >= 0"
            return f"{name} must be {rule} (got {first:g} at {int(bad.sum())} value(s))"
    return None
