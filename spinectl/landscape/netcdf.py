"""Landscapes on disk: NetCDF written atomically, read back checked, and the model they used.

Every file carries checksums, as a study store's chunks do: each variable has the
attribute ``spinectl_crc32``, the CRC-32 of its bytes as stored (with its type,
dimensions, shape and other attributes), and the file has one of its global
attributes (``config_toml`` among them), written by :func:`save` and checked by
:func:`load` before anything is used, so that a flipped bit is a one-line error
naming the variable, not a different number in a figure. A file that netCDF-C
cannot read (a damaged HDF5 structure) is a one-line error too; one without
checksums (written by spinectl before they were recorded, or by another program)
loads with a :class:`ChecksumWarning` saying that it could not be checked.
"""

from __future__ import annotations

import os
import sys
import tomllib
import warnings
import zlib
from pathlib import Path

import numpy as np
import xarray as xr

from .._validate import printable, show
from ..atomic import atomic_path, full_disk_note
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


def check_name(path, error=OutputError) -> None:
    """Refuse at once a name that the NetCDF library cannot open.

    netCDF4 encodes names strictly in the file system's encoding, and under the C locale without
    Python's UTF-8 mode that is ASCII, so ``Λ.nc`` or ``Λdir/k0.nc`` (which Python itself keeps as
    surrogate escapes and writes as their UTF-8 bytes) failed in a traceback, after the work.

    Parameters
    ----------
    path : str or Path
        The file to write or read.
    error : type
        :class:`~spinectl.errors.OutputError` for an output, or a callable taking the message for an input.

    Raises
    ------
    OutputError
        (or ``error``) The name cannot be encoded in the file system's encoding.
    """
    encoding = sys.getfilesystemencoding()
    try:
        str(path).encode(encoding)
    except UnicodeEncodeError:
        raise error(
            f"cannot open {show(str(path))}: the NetCDF library takes only names in the file system's encoding "
            f"({encoding} here), which cannot hold this one: run under a UTF-8 locale (LC_ALL=C.UTF-8) or with "
            "PYTHONUTF8=1, or choose an ASCII name"
        ) from None


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
    check_name(path)
    with atomic_path(path) as tmp:
        try:
            _unstamped(dataset).to_netcdf(tmp, engine="netcdf4")
            _stamp(tmp)
        except (OSError, RuntimeError) as exc:  # netCDF-C reports a full disk as e.g. "NetCDF: HDF error"
            if isinstance(exc, SpinectlError):
                raise
            raise OutputError(f"cannot write {str(path)!r}: {printable(str(exc))}{full_disk_note(path)}") from None
    return Path(path)


CHECKSUM = "spinectl_crc32"
"""The attribute of every variable (and of the file, for its global attributes): a CRC-32 as 8 hex digits."""


class ChecksumWarning(UserWarning):
    """A NetCDF file without checksums was read: a damaged value in it cannot be detected."""


def _unstamped(dataset: xr.Dataset) -> xr.Dataset:
    """``dataset`` without checksum attributes (e.g. one loaded, then edited): :func:`save` writes them anew."""
    if CHECKSUM not in dataset.attrs and not any(CHECKSUM in v.attrs for v in dataset.variables.values()):
        return dataset
    dataset = dataset.copy()
    dataset.attrs.pop(CHECKSUM, None)
    for variable in dataset.variables.values():
        variable.attrs.pop(CHECKSUM, None)
    return dataset


def _stamp(path: Path) -> None:
    """Record the checksum of every variable and of the global attributes in the NetCDF file ``path``."""
    import netCDF4

    with netCDF4.Dataset(path, "r+") as file:
        for variable in file.variables.values():
            variable.setncattr(CHECKSUM, _variable_crc(variable))
        file.setncattr(CHECKSUM, _attributes_crc(file))


def _variable_crc(variable) -> str:
    """CRC-32 of a netCDF4 variable: its name, type, dimensions, shape, other attributes and values as stored."""
    variable.set_auto_maskandscale(False)  # the bytes stored, not a decoded copy
    variable.set_auto_chartostring(False)
    head = f"{variable.name}|{variable.dtype}|{variable.dimensions}|{variable.shape}|{_attributes_text(variable)}"
    return f"{zlib.crc32(_stored_bytes(variable[...]), zlib.crc32(head.encode())):08x}"


def _attributes_crc(holder) -> str:
    return f"{zlib.crc32(_attributes_text(holder).encode('utf-8', 'surrogatepass')):08x}"


def _attributes_text(holder) -> str:
    """The attributes of a netCDF4 file or variable but the checksum, as text in name order."""
    names = sorted(name for name in holder.ncattrs() if name != CHECKSUM)
    return "|".join(f"{name}={np.asarray(holder.getncattr(name)).tolist()!r}" for name in names)


def _stored_bytes(values) -> bytes:
    values = np.asarray(values)
    if values.dtype.kind == "O":  # variable-length strings: each with its length
        items = [str(item).encode("utf-8", "surrogatepass") for item in values.ravel()]
        return b"".join(len(item).to_bytes(8, "little") + item for item in items)
    if values.dtype.byteorder not in "|<":  # the same bytes on any machine
        values = values.astype(values.dtype.newbyteorder("<"))
    return np.ascontiguousarray(values).tobytes()


READ_ERRORS = (
    OSError,
    RuntimeError,
    ValueError,
    KeyError,
    IndexError,
    TypeError,
    AttributeError,
    UnicodeError,
    OverflowError,
)
"""What netCDF4-python and xarray raise on a file whose HDF5 structure is damaged (found by flipping its bits)."""


def _verify(path: Path) -> bool:
    """Check the checksums of the NetCDF file ``path``; False if it has none.

    Raises :class:`ParameterError` (field ``results``) naming the first variable (or the
    global attributes) whose bytes differ from those written, or the reason netCDF-C gives
    for not reading it.
    """
    import netCDF4

    try:
        with netCDF4.Dataset(path) as file:
            if CHECKSUM not in file.ncattrs():
                return False
            wrong = [] if file.getncattr(CHECKSUM) == _attributes_crc(file) else ["its global attributes differ"]
            for name, variable in file.variables.items():
                stamped = variable.getncattr(CHECKSUM) if CHECKSUM in variable.ncattrs() else None
                if not wrong and stamped != _variable_crc(variable):
                    wrong.append(f"variable {name!r} differs")
    except READ_ERRORS as exc:
        raise ParameterError("results", f"{str(path)!r} cannot be read: {_reason(exc)}") from None
    if wrong:
        raise ParameterError(
            "results",
            f"{str(path)!r} is damaged: {wrong[0]} from what was written (its CRC-32, attribute "
            f"{CHECKSUM}, does not match); write it again",
        )
    return True


def _reason(exc: Exception) -> str:
    text = printable(str(exc).splitlines()[0] if str(exc) else "")
    return f"{exc.__class__.__name__}: {text}" if text else exc.__class__.__name__


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
        The file is missing, not NetCDF, damaged (a variable or the global attributes
        differ from their checksums, or netCDF-C cannot read it) or not a sweep (field
        ``results``): a required variable, the dimensions E and Lambda (and K when K is a
        dimension), finite coordinates with no value repeated, or a ``config_toml`` that is a valid model.

    Warns
    -----
    ChecksumWarning
        The file carries no checksums (an older spinectl's, or another program's): it could not be checked.
    """
    path = Path(path)
    if not path.is_file():
        raise ParameterError("results", f"file not found: {show(str(path))}")
    check_name(path, lambda message: ParameterError("results", message))
    checked = _verify_or_foreign(path)
    try:
        dataset = _unstamped(xr.load_dataset(path, engine="netcdf4"))
    except READ_ERRORS as exc:
        raise ParameterError("results", f"{str(path)!r} cannot be read: {_reason(exc)}") from None
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
    if not checked:
        warnings.warn(
            ChecksumWarning(
                f"{str(path)!r} carries no checksums (written by spinectl before they were recorded, or by "
                "another program): a damaged value in it cannot be detected; write it again to add them"
            ),
            stacklevel=2,
        )
    return dataset


def _verify_or_foreign(path: Path) -> bool:
    """:func:`_verify`, but a file that is not NetCDF at all is named so."""
    try:
        fd = os.open(path, os.O_RDONLY)
        try:
            magic = os.read(fd, 8)
        finally:
            os.close(fd)
    except OSError as exc:  # no permission, a failing device
        raise ParameterError("results", f"{str(path)!r} cannot be read: {_reason(exc)}") from None
    if not (magic.startswith(b"\x89HDF") or magic.startswith(b"CDF")):
        raise ParameterError("results", f"{path} is not a spinectl NetCDF file (not NetCDF)")
    return _verify(path)


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
