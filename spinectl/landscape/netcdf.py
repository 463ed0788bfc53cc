"""Landscapes on disk: NetCDF written atomically, read back checked, and the model they used.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import xarray as xr

from .._validate import printable
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
    """
    return config.from_dict(Model, tomllib.loads(dataset.attrs["config_toml"]))


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
            raise OutputError(f"cannot write {str(path)!r}: {printable(str(exc))}") from None
    return Path(path)


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
        The file is missing, not NetCDF or not a sweep (field ``results``).
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
    return dataset
