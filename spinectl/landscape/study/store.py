"""The Zarr store of a study: layout, creation, the resume check, chunk writes and reading back.

Layout (``docs/studies.md``): every output of the study is one array with the
study's parameter dimensions, then ``E``, ``Lambda`` and the output's own
(``segment``, ``muscle``); its Zarr chunks are exactly the study's chunks, so
that no two chunks of work ever share a file. ``chunk_done`` counts, per chunk,
how often its results were written: 0 not yet (floats read NaN there), 1 done,
never more. The attributes hold the study file, its digest and the base model.

Zarr format 2: its specification covers the fixed-width strings of the status
variables and coordinates; zarr-python 3.1 writes those in format 3 only with a
warning that format 3 has no specification for them yet. Every Zarr file is
written atomically (zarr's local store writes a temporary and renames it), so a
killed run leaves whole chunks or none. Every chunk is written as a file, also
one of fill values only (``write_empty_chunks``), so that a chunk counted done
has a file of each output; with its count the writer records ``chunk_crc32``, the
CRC-32 of those files' bytes. A resume and :func:`open_store` check every chunk
counted done (its files present, their CRC-32 as recorded) and the store's
layout (every array present with the shape it was made with, and the values of
the arrays written once at creation, the coordinates, as recorded in the
attribute ``layout``): :func:`damaged_chunks`.

A run holds the store's lock file (:func:`locked`), ``<store>.lock`` beside it,
from before the existence check to its end: a second run on the same store is
refused at once, naming the first.
"""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
import warnings
import zlib
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import xarray as xr
import zarr

from ..._version import __version__
from ...atomic import Owner, atomic_path, output_errors, temporary_beside
from ...errors import OutputError, ParameterError
from ...model import config, source
from ...model._toml import field_metadata
from .. import schema
from .metadata import check_consolidated, check_metadata_files
from .spec import SAMPLE, STORE_FORMAT, Chunk, Study

DONE = "chunk_done"
"""The per-chunk counter of writes."""

CHECKSUM = "chunk_crc32"
"""Per chunk, the CRC-32 of its files' bytes (every output, in name order), recorded before its count."""

LAYOUT = "layout"
"""The attribute (JSON text) of every array's shape, and the CRC-32 of the values of those written once at creation."""

CHUNK_FILES = "every_chunk_a_file"
"""The attribute that says every chunk written is a file (``write_empty_chunks``); stores made before
it may lack the files of chunks of fill values only, so their chunks are not checked (:func:`damaged_chunks`)."""

STRING_WIDTH = 32
"""Characters of the fixed-width status strings; the longest status has 22."""

ZARR_FORMAT = 2

OPEN_ERRORS = (zarr.errors.BaseZarrError, OSError, ValueError, KeyError, TypeError)
"""What opening something that is not a Zarr store raises (TypeError: metadata of the wrong types,
e.g. a fill value NaN for an integer dtype)."""


def encode(columns: dict, outputs, tile: tuple[int, int]) -> dict[str, np.ndarray]:
    """The chosen outputs of :func:`~spinectl.landscape.columns.point_columns` as stored.

    On the tile, strings fixed-width.

    Parameters
    ----------
    columns : dict of str to numpy.ndarray
        Leading dimension: the tile's points, E-major.
    outputs : sequence of str
        Names to keep.
    tile : tuple of int
        Points of the tile along E and Lambda.

    Returns
    -------
    dict of str to numpy.ndarray
        Each of ``outputs``, shape ``tile`` + its trailing shape (segment, muscle);
        strings as fixed-width unicode of :data:`STRING_WIDTH` characters.

    Raises
    ------
    ValueError
        A string longer than :data:`STRING_WIDTH` characters.
    """
    out = {}
    for name in outputs:
        values = columns[name].reshape(tuple(tile) + columns[name].shape[1:])
        if values.dtype == object:
            text = values.astype(str)
            if text.dtype.itemsize // 4 > STRING_WIDTH:  # numpy would truncate silently
                raise ValueError(f"{name}: a value longer than {STRING_WIDTH} characters")
            values = text.astype(f"<U{STRING_WIDTH}")
        out[name] = values
    return out


def _fill(dtype: np.dtype):
    return {"f": np.nan, "U": "", "b": False}.get(dtype.kind, 0)


def template(study: Study, probe: dict[str, np.ndarray]) -> xr.Dataset:
    """The whole store as a lazy Dataset: fill values, coordinates, attributes; nothing computed.

    Parameters
    ----------
    study : Study
        Its dimensions, coordinates and tiling.
    probe : dict of str to numpy.ndarray
        One point's outputs as :func:`encode` gives them (tile 1 x 1): their dtypes and trailing shapes.

    Returns
    -------
    xarray.Dataset
        Every output over the study's dimensions and the grid, as dask arrays of fill
        values chunked by the study's tiles, the chunk counts (``chunk_done``), the
        coordinates with units and the study's attributes.
    """
    lead = study.shape + study.grid_shape
    chunks = (1,) * len(study.shape) + study.tile
    data_vars = {}
    for name, values in probe.items():
        dims = study.dims + schema.dims_of(name, values.ndim)
        shape, fill = lead + values.shape[2:], _fill(values.dtype)
        units, long_name = schema.VARIABLES[name]
        data_vars[name] = _lazy(dims, shape, fill, values.dtype, chunks + values.shape[2:])
        data_vars[name].attrs.update(units=units, long_name=long_name)
    data_vars[DONE] = _lazy(("chunk",), (study.n_chunks,), 0, "int16", (1,))
    data_vars[DONE].attrs["long_name"] = "times the chunk was written: 0 not yet, 1 done"
    data_vars[CHECKSUM] = _lazy(("chunk",), (study.n_chunks,), 0, "int64", (1,))
    data_vars[CHECKSUM].attrs["long_name"] = "CRC-32 of the chunk's files, once done"
    return xr.Dataset(data_vars, _coordinates(study), _attributes(study))


def _lazy(dims, shape, fill, dtype, chunks) -> xr.Variable:
    """A variable of fill values, one dask chunk, whose Zarr chunks are ``chunks`` (its encoding).

    One dask chunk, not one per Zarr chunk: the store is made with ``compute=False`` (metadata
    only), and a dask graph of one task per study chunk and output took about 7 kB and 0.5 ms
    each (324,000 chunks of two outputs: 2.3 GB and 153 s before the first chunk).
    """
    import dask.array as da  # only where a store is made: the other commands need no dask

    variable = xr.Variable(dims, da.full(shape, fill, dtype=dtype, chunks=-1))
    variable.encoding["chunks"] = tuple(chunks)
    return variable


def _coordinates(study: Study) -> dict:
    model = study.model
    coords = {a.name: (a.name, list(a.values), _parameter_attributes(model, a.parameter)) for a in study.axes}
    if study.samples:
        coords[SAMPLE] = (SAMPLE, np.arange(study.samples.count), {"long_name": "Monte-Carlo draw"})
        for name, values in study.samples.values().items():
            coords[name] = (SAMPLE, values, _parameter_attributes(model, name))
    return coords | schema.grid_coordinates(model, list(study.eccentricity), list(study.lordosis))


def _parameter_attributes(model, dotted: str) -> dict[str, str]:
    """``units``, ``long_name`` and ``parameter`` of a parameter's coordinate, from its field metadata."""
    meta = field_metadata(model, dotted)
    unit = source.stiffness_unit(model.passive.convention) if dotted == "passive.stiffness" else meta.get("unit", "")
    return {"units": unit, "long_name": meta.get("doc", dotted), "parameter": dotted}


def _attributes(study: Study) -> dict:
    return {
        "title": "spinectl parameter study",
        "description": study.description,
        "source": f"spinectl {__version__}",
        "references": schema.PAPER_REFERENCE,
        "method": "fast",
        "store_format": STORE_FORMAT,
        "study_digest": study.digest(),
        "study_toml": study.text,
        "config_toml": config.dump_toml(study.model),
        "chunk_tile": list(study.tile),
        CHUNK_FILES: True,
    } | source.attributes(study.model)


def existing(
    study: Study, path: str | Path, resume: bool, notify: Callable[[str], None] = lambda line: None
) -> np.ndarray | None:
    """The write count of every chunk of an existing store; None if there is none yet.

    An existing store is never replaced: it is filled in place, chunk by chunk
    (that is what makes it resumable), so replacing it would discard every
    finished chunk. Without ``resume`` it is refused; the user removes it deliberately.

    Parameters
    ----------
    study : Study
        The study to run.
    path : str or Path
        The store (a folder).
    resume : bool
        Continue an existing store.
    notify : callable
        Told (a line of text) of chunks counted done whose data is missing: they count 0, to be computed again.

    Returns
    -------
    numpy.ndarray of int, shape (n_chunks,) or None
        How many times each chunk was written (0: not yet, or counted done but its data is
        damaged, :func:`damaged_chunks`); None if ``path`` does not exist.

    Raises
    ------
    OutputError
        The store exists and ``resume`` is false, or it cannot be written (read-only, immutable, not the user's).
    ParameterError
        ``resume`` and the path holds no study store, or one of another study (field ``store``).
    """
    path = Path(path)
    if not (path.exists() or path.is_symlink()):
        return None
    if not resume:
        refuse_existing(path)
    counts = _done_counts(study, path)
    missing = damaged_chunks(path, counts)
    _check_writable(path)  # before any work: a read-only store would fail at its first chunk
    _check_unblocked(path, missing)
    if missing.size:
        notify(f"study: {_missing_text(path, missing)}; computing {'it' if missing.size == 1 else 'them'} again")
        counts[missing] = 0
    return counts


def refuse_existing(path: str | Path) -> None:
    """Raise the :class:`OutputError` of a store that exists when no resume was asked (every kind of study's).

    Parameters
    ----------
    path : str or Path
        The store.
    """
    raise OutputError(
        f"{str(path)!r} exists: add --resume to continue the study it holds, or remove it to start "
        "afresh (a study store is filled in place and never replaced, which would discard its chunks)"
    )


def _check_unblocked(path: Path, chunks) -> None:
    """Raise :class:`OutputError` if something other than a file (a folder) stands where a chunk of ``chunks`` goes.

    zarr cannot replace it, so every resume would find the chunk missing, compute it and fail
    to write it: the advice to resume would loop. The user removes it, then resumes.
    """
    if len(chunks) == 0:
        return
    files = _ChunkFiles(path, _checked_group(path))
    for index in chunks:
        blocked = files.blocked(index)
        if blocked is not None:
            raise OutputError(_blocked_text(blocked))


def _blocked_text(blocked: Path) -> str:
    return (
        f"cannot write {str(blocked)!r}: a folder (or other non-file) stands where a chunk file of the store "
        "belongs; remove it, then run again with --resume"
    )


def _check_writable(path: Path) -> None:
    """Raise :class:`OutputError` if a file cannot be made in the store or one of its arrays' folders.

    zarr writes each chunk (and the consolidated metadata at the end) to a temporary file
    in its folder, then renames it: the same is tried here, in every folder, and undone.
    """
    for folder in (path, *sorted(p for p in path.iterdir() if p.is_dir())):
        with output_errors(folder):
            fd, name = tempfile.mkstemp(prefix=".spinectl-probe.", dir=folder)
            os.close(fd)
            os.replace(name, f"{name}.renamed")
            os.unlink(f"{name}.renamed")


def create(study: Study, path: str | Path, probe: dict) -> np.ndarray:
    """Create the store atomically (:func:`spinectl.atomic.atomic_path`): complete or absent; return zero counts.

    Parameters
    ----------
    study : Study
        The study to run.
    path : str or Path
        The store (a folder) to create.
    probe : dict
        See :func:`template`.

    Returns
    -------
    numpy.ndarray of int, shape (n_chunks,)
        Zeros: no chunk written yet.

    Raises
    ------
    OutputError
        The store cannot be created.
    """
    with atomic_path(path, directory=True) as tmp:
        template(study, probe).to_zarr(
            tmp, mode="w", compute=False, zarr_format=ZARR_FORMAT, consolidated=False, write_empty_chunks=True
        )
        group = zarr.open_group(tmp, mode="r+", zarr_format=ZARR_FORMAT)
        group.attrs[LAYOUT] = json.dumps({name: _layout_entry(array) for name, array in sorted(group.arrays())})
    return np.zeros(study.n_chunks, dtype=int)


def _done_counts(study: Study, path: Path) -> np.ndarray:
    check_metadata_files(path)
    try:  # the root's own attributes: a damaged .zmetadata is reported as such below, not as a foreign folder
        root = zarr.open_group(path, mode="r", zarr_format=ZARR_FORMAT, use_consolidated=False)
        digest = root.attrs.get("study_digest")
    except OPEN_ERRORS:
        digest = None
    if not isinstance(digest, str):
        raise ParameterError("store", f"{str(path)!r} is not a spinectl study store")
    if digest != study.digest():
        raise ParameterError(
            "store",
            f"{str(path)!r} holds another study (digest {digest[:12]}, this file {study.digest()[:12]}): resume "
            "with the study file that made it, or write to another store",
        )
    group = _checked_group(path)  # a study store, but its layout may be damaged: say what is lost
    check_consolidated(path)
    try:
        return group[DONE][:].astype(int)
    except OPEN_ERRORS as exc:  # a store made before the layout was recorded
        raise ParameterError("store", f"{str(path)!r} is damaged: array {DONE!r}: {exc}") from None


class Writer:
    """Writes finished chunks into their own regions, then counts them done.

    Parameters
    ----------
    study : Study
        The study of the store.
    path : str or Path
        The store, as made by :func:`create`.
    done : numpy.ndarray of int
        The write counts read by :func:`existing` or :func:`create`; updated in place.
    """

    def __init__(self, study: Study, path: str | Path, done: np.ndarray):
        self.study, self.path, self.done = study, Path(path), done
        # every chunk a file, also one of fill values only (zarr's default skips those): see CHUNK_FILES;
        # an array's runtime configuration is fixed when it is opened
        with zarr.config.set({"array.write_empty_chunks": True}):
            group = zarr.open_group(self.path, mode="r+", zarr_format=ZARR_FORMAT)
            self._arrays = dict(group.arrays())
        self._flags, self._crc, self._files = self._arrays[DONE], self._arrays[CHECKSUM], _ChunkFiles(self.path, group)

    def write(self, chunk: Chunk, outputs: dict[str, np.ndarray]) -> None:
        """Write one chunk's outputs (from :func:`encode`), then raise its count.

        The data first, then the CRC-32 of its files, the count last: a run killed
        in between leaves the chunk counted 0, and a resume writes it again, whole.
        Each output goes straight into its zarr array's region, which is exactly one
        zarr chunk: the same files as ``Dataset.to_zarr(region=...)``, bit for bit, at a
        fraction of its cost (which opens the store's every array again for each chunk).

        Parameters
        ----------
        chunk : Chunk
            Where the outputs go.
        outputs : dict of str to numpy.ndarray
            On the chunk's tile.

        Raises
        ------
        OutputError
            The store cannot be written (a full disk, a quota, permissions): the chunk
            stays counted 0, the store resumable.
        """
        region = (*chunk.combination, chunk.eccentricity, chunk.lordosis)
        try:
            for name, values in outputs.items():
                self._arrays[name][region] = values
            self._crc[chunk.index] = self._files.checksum(chunk.index)
            self._flags[chunk.index] = self.done[chunk.index] + 1
        except OSError as exc:  # a full disk, a quota, a store made read-only meanwhile: the chunk counts 0
            blocked = self._files.blocked(chunk.index)
            if blocked is not None:  # "resume" would fail here again: say what to remove
                raise OutputError(_blocked_text(blocked)) from None
            raise OutputError(
                f"cannot write {str(self.path)!r}: {exc.strerror or exc.__class__.__name__}; the store holds every "
                "chunk finished: run again with --resume once it can be written"
            ) from None
        self.done[chunk.index] += 1


def consolidate(path: str | Path) -> None:
    """Consolidate the metadata of a finished store.

    Chunks are written with ``consolidated=False`` (region writes); once every
    chunk is done nothing changes the metadata again, so consolidating lets a
    plain ``xarray.open_zarr(path)`` open the store quickly and without a warning.

    Parameters
    ----------
    path : str or Path
        The store.
    """
    zarr.consolidate_metadata(str(path))


def open_store(path: str | Path) -> xr.Dataset:
    """A study store as a lazy Dataset (dask arrays; nothing read until asked).

    Parameters
    ----------
    path : str or Path
        The store.

    Returns
    -------
    xarray.Dataset
        The store's variables as dask arrays, with its coordinates and attributes.

    Raises
    ------
    ParameterError
        Not a spinectl study store, its layout is damaged (an array's metadata or a coordinate
        lost or changed), or a chunk counted done has lost its data or has other bytes than
        those written (field ``store``).
    """
    check_metadata_files(path)
    try:
        with warnings.catch_warnings():  # zarr warns of a folder whose metadata is lost: checked below
            warnings.simplefilter("ignore", zarr.errors.ZarrUserWarning)
            dataset = xr.open_zarr(path, consolidated=False, zarr_format=ZARR_FORMAT)
    except OPEN_ERRORS:
        dataset = None
    if dataset is None or "study_digest" not in dataset.attrs or DONE not in dataset:
        try:
            _checked_group(path)  # a study store whose layout is damaged: say what is lost
        except ParameterError:
            raise
        except OPEN_ERRORS:
            pass  # not a store at all
        raise ParameterError("store", f"{str(path)!r} is not a spinectl study store")
    missing = damaged_chunks(path, dataset[DONE].values)
    if missing.size:
        files = _ChunkFiles(path, _checked_group(path))
        blocked = next((b for b in map(files.blocked, missing) if b is not None), None)
        advice = "run the study again with --resume"
        if blocked is not None:  # a resume alone cannot replace a folder there
            advice = f"remove {str(blocked)!r}, which is not a file, then {advice}"
        raise ParameterError("store", f"{_missing_text(path, missing)}: {advice}")
    check_consolidated(path)
    return dataset


def load(path: str | Path) -> xr.Dataset:
    """A study store fully in memory, statuses as Python strings as in :func:`spinectl.landscape.sweep.sweep`.

    Points of chunks not yet done read NaN (numbers), ``''`` (statuses), False, see ``chunk_done``.

    Parameters
    ----------
    path : str or Path
        The store.

    Returns
    -------
    xarray.Dataset
        As :func:`open_store`, loaded into memory, string variables as object arrays.

    Raises
    ------
    ParameterError
        Not a spinectl study store (field ``store``).
    """
    dataset = open_store(path).load()
    for name, variable in dataset.data_vars.items():
        if variable.dtype.kind == "U":
            dataset[name] = variable.astype(object)
    return dataset


def computed(dataset: xr.Dataset) -> xr.DataArray:
    """Which points of a store are computed: those of the chunks counted done in ``chunk_done``.

    The chunks are the study's order (:meth:`spinectl.landscape.study.spec.Study.chunk`): the
    combinations of the parameter dimensions outer, then tiles of ``chunk_tile`` points along E and
    Lambda, so the counts, reshaped, repeated over each tile and cut to the grid, give every point's.

    Parameters
    ----------
    dataset : xarray.Dataset
        A store as :func:`open_store` or :func:`load` reads it.

    Returns
    -------
    xarray.DataArray of bool
        Over the parameter dimensions, then ``E`` and ``Lambda``: True where the point's chunk is done
        (its numbers are answers, NaN an infeasible point), False where it is not yet (NaN: not computed).

    Raises
    ------
    ParameterError
        The store's attribute ``chunk_tile`` is lost (field ``store``).
    """
    output = next(v for v in dataset.data_vars.values() if "Lambda" in v.dims)  # parameters, E, Lambda, own
    dims = list(output.dims[: output.dims.index("Lambda") + 1])
    shape = [dataset.sizes[d] for d in dims]
    if "chunk_tile" not in dataset.attrs:  # an edited store: its chunks' tiles are unknown
        raise ParameterError("store", "its attribute chunk_tile is lost: which points are computed is unknown")
    tile = [int(n) for n in dataset.attrs["chunk_tile"]]
    tiles = [-(-n // t) for n, t in zip(shape[-2:], tile, strict=True)]
    done = np.asarray(dataset[DONE].values).reshape(shape[:-2] + tiles) > 0
    points = done.repeat(tile[0], axis=-2).repeat(tile[1], axis=-1)[..., : shape[-2], : shape[-1]]
    return xr.DataArray(points, coords={d: dataset[d] for d in dims}, dims=dims, name="computed")


def damaged_chunks(path: str | Path, counts: np.ndarray) -> np.ndarray:
    """The chunks counted done that lost a file or whose files' bytes are not those written; the layout checked first.

    Every output array is chunked as the study (parameter dimensions one by one, then
    the tile of E and Lambda, the trailing dimensions whole), so chunk ``i`` of the study is
    the ``i``-th of the leading chunk grid in C order; and every chunk written is a file
    (``write_empty_chunks``). Reads each done chunk's files once, undecoded: cheap beside
    reading the data. A store made before the CRC-32 were recorded is checked for the
    files' presence only; one made before every chunk was a file is not checked.

    Parameters
    ----------
    path : str or Path
        The store.
    counts : numpy.ndarray of int, shape (n_chunks,)
        Its ``chunk_done``.

    Returns
    -------
    numpy.ndarray of int
        Indices of the chunks counted done with a chunk file missing or other bytes, ascending.

    Raises
    ------
    ParameterError
        The store's layout is damaged: an array lost (its metadata deleted), of another
        shape, or an array written once at creation (a coordinate) with other values (field ``store``).
    """
    group = _checked_group(path)
    done = np.flatnonzero(np.asarray(counts) > 0)
    if group.attrs.get(CHUNK_FILES) is not True:
        return np.zeros(0, dtype=int)  # an older store: a chunk of fill values only may lack its file
    files = _ChunkFiles(path, group)
    recorded = group[CHECKSUM][:] if CHECKSUM in group else None
    bad = [i for i in done if (crc := files.checksum(i)) is None or (recorded is not None and crc != recorded[i])]
    return np.asarray(bad, dtype=int)


def _checked_group(path):
    """The store's root group, its layout checked (:func:`_check_layout`)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", zarr.errors.ZarrUserWarning)
        # not the consolidated metadata of a finished store: it would list an array whose own metadata is lost
        group = zarr.open_group(path, mode="r", zarr_format=ZARR_FORMAT, use_consolidated=False)
        _check_layout(path, group)
    return group


class _ChunkFiles:
    """The files of each study chunk: one per output array (the arrays over E and Lambda)."""

    def __init__(self, path: str | Path, group):
        self.arrays = []
        for name, array in sorted(group.arrays(), key=lambda item: item[0]):
            dims = array.attrs.get("_ARRAY_DIMENSIONS", ())
            if not {"E", "Lambda"} <= set(dims):
                continue  # the chunk counts, the coordinates
            grid = tuple(-(-n // c) for n, c in zip(array.shape, array.chunks, strict=True))
            lead = list(dims).index("Lambda") + 1
            self.arrays.append((Path(path, name), array.metadata.dimension_separator, grid, lead))

    def paths(self, index: int) -> list[Path]:
        """The files of chunk ``index``, one per array, in array name order."""
        out = []
        for folder, separator, grid, lead in self.arrays:
            position = np.unravel_index(index, grid[:lead]) + (0,) * (len(grid) - lead)
            out.append(Path(folder, separator.join(str(int(i)) for i in position)))
        return out

    def checksum(self, index: int) -> int | None:
        """CRC-32 of chunk ``index``'s files, in array name order; None if one is missing."""
        crc = 0
        for path in self.paths(index):
            try:
                crc = zlib.crc32(path.read_bytes(), crc)
            except (FileNotFoundError, IsADirectoryError, NotADirectoryError):
                return None
        return crc

    def blocked(self, index: int) -> Path | None:
        """The first name of chunk ``index`` taken by something other than a file (a folder), or None."""
        for path in self.paths(index):
            if (path.exists() or path.is_symlink()) and not path.is_file():
                return path
        return None


def _layout_entry(array) -> dict:
    """An array's shape; for one written once at creation (not over E and Lambda, not a counter) its values' CRC-32."""
    dims = array.attrs.get("_ARRAY_DIMENSIONS")
    entry = {"shape": list(array.shape), "dims": dims, "dtype": np.dtype(array.dtype).str}
    if not {"E", "Lambda"} <= set(dims or ()) and array.basename not in (DONE, CHECKSUM):
        entry["crc32"] = zlib.crc32(np.ascontiguousarray(array[...]).tobytes())
    return entry


def _check_layout(path, group) -> None:
    """Every array of the attribute :data:`LAYOUT` present, of its shape, the fixed ones with their values."""
    try:
        layout = json.loads(group.attrs[LAYOUT])
    except KeyError:
        return  # a store made before the layout was recorded
    except (TypeError, ValueError):
        layout = None
    if not isinstance(layout, dict) or not all(isinstance(entry, dict) for entry in layout.values()):
        raise ParameterError("store", f"{str(path)!r} is damaged: its attribute {LAYOUT!r} is not as written")
    arrays = {}
    for name in layout:  # one by one: an array whose metadata cannot be read is named
        try:
            arrays[name] = group[name]
        except KeyError:
            pass  # lost: said below
        except OPEN_ERRORS as exc:
            reason = (str(exc).splitlines() or [type(exc).__name__])[0][:120]  # the CLI escapes what is not printable
            raise ParameterError(
                "store",
                f"{str(path)!r} is damaged: array {name!r}: its metadata cannot be read ({reason}); remove it "
                "and run the study afresh",
            ) from None
    for name, entry in layout.items():
        problem = None
        if name not in arrays:
            problem = "its metadata is lost"
        elif "dtype" in entry and np.dtype(arrays[name].dtype).str != entry["dtype"]:
            problem = f"its dtype is {np.dtype(arrays[name].dtype).str}, not {entry['dtype']} (its metadata edited)"
        elif list(arrays[name].shape) != entry.get("shape"):
            problem = f"its shape is {list(arrays[name].shape)}, not {entry.get('shape')}"
        elif arrays[name].attrs.get("_ARRAY_DIMENSIONS") != entry.get("dims"):
            problem = "its attributes (the dimensions' names) are lost or changed"
        elif "crc32" in entry and _layout_entry(arrays[name]).get("crc32") != entry["crc32"]:
            problem = "its values are not those written (a chunk file lost or changed)"
        if problem:
            raise ParameterError(
                "store", f"{str(path)!r} is damaged: array {name!r}: {problem}; remove it and run the study afresh"
            )


def _missing_text(path, missing: np.ndarray) -> str:
    shown = ", ".join(str(i) for i in missing[:5]) + (", ..." if missing.size > 5 else "")
    lost = "have lost their data or hold other bytes than written"
    return f"{str(path)!r}: {missing.size} chunk(s) counted done {lost} (chunk {shown})"


LOCK_SUFFIX = ".lock"
"""The lock file of a store ``s.zarr`` is ``s.zarr.lock``, beside it."""


@contextlib.contextmanager
def locked(path: str | Path) -> Iterator[Path]:
    """Hold the lock of the store ``path`` while the block runs: no second run can use it meanwhile.

    The lock is a file beside the store (beside its real path, after symbolic links),
    created whole or not at all (written to a temporary, then hard-linked: a link fails
    where the name exists), holding the process id, start time and host name of its
    holder (:class:`spinectl.atomic.Owner`); it is removed at the end, whatever happens.
    A lock left by a run that is gone (killed: its process id no longer runs on this
    host, or runs a process that started at another time, the id reused) is taken
    over; one of another host is never (its process cannot be checked): remove it by
    hand once that run has ended.

    Parameters
    ----------
    path : str or Path
        The store (it need not exist yet).

    Yields
    ------
    Path
        The lock file.

    Raises
    ------
    OutputError
        Another run holds the lock (its process id and host are named), or the lock cannot be written.
    """
    # one lock per store, however it is named: a trailing slash, '..' or a symbolic link leads to the same
    lock = Path(f"{os.path.realpath(path)}{LOCK_SUFFIX}")
    with output_errors(lock):
        lock.parent.mkdir(parents=True, exist_ok=True)
        _acquire(lock)
    try:
        yield lock
    finally:
        lock.unlink(missing_ok=True)


def _acquire(lock: Path, attempts: int = 3) -> None:
    me = Owner.me()
    for _ in range(attempts):  # a stale lock that another run took over meanwhile: look again
        if _create(lock, f"{me.pid} {me.start} {me.host}\n"):
            return
        holder = _holder(lock)
        if holder is None or not holder.gone():
            who = "unknown" if holder is None else f"process {holder.pid} on host {holder.host}"
            raise OutputError(
                f"{str(lock)[: -len(LOCK_SUFFIX)]!r} is in use by another study run ({who}, lock file "
                f"{str(lock)!r}): wait for it to end, or remove the lock file if that run has ended"
            )
        _take_over(lock, holder)
    raise OutputError(f"cannot lock {str(lock)!r}: other runs keep taking it")


def _create(lock: Path, text: str) -> bool:
    """Create ``lock`` holding ``text``, whole or not at all (False: it exists).

    The text is written to a temporary first and hard-linked as the lock (a link fails where
    the name exists), so that a run killed meanwhile leaves no empty lock that would count as held.
    """
    tmp = temporary_beside(lock)  # named after this run: a later run removes it if this one is killed
    try:
        tmp.write_text(text, encoding="utf-8")
        os.link(tmp, lock)
    except FileExistsError:
        return False
    finally:
        tmp.unlink(missing_ok=True)
    return True


def _holder(lock: Path) -> Owner | None:
    """The holder of a lock file (pid, start time, host; an older version's lock has no start time), or None
    if it is unreadable (then it counts as held)."""
    try:
        fields = lock.read_text(encoding="utf-8").split()
        if len(fields) == 2:
            return Owner(int(fields[0]), 0, fields[1])
        pid, start, host = fields
        return Owner(int(pid), int(start), host)
    except (OSError, ValueError, UnicodeDecodeError):
        return None


def _take_over(lock: Path, holder: Owner) -> None:
    """Remove a stale lock, unless another run replaced it meanwhile (then it is put back)."""
    aside = temporary_beside(lock)
    try:
        os.replace(lock, aside)
        if _holder(aside) != holder:  # a live lock of another run, taken over meanwhile
            with contextlib.suppress(FileExistsError):
                os.link(aside, lock)
    except FileNotFoundError:
        pass  # removed by its holder or by another run: try again
    finally:
        aside.unlink(missing_ok=True)
