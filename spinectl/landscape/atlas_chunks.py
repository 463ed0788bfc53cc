"""The atlas's saved chunks: each records its atlas, its position and a checksum, checked when read back.

An atlas run saves every chunk of outputs in ``DIR/chunks`` as it finishes (``<atlas>-<index>.npz``,
written atomically), so that an interrupted run resumes where it stopped. A file there may since have
been cut short, copied from another position or another atlas's folder, or edited: so each chunk
holds, beside its outputs, the :func:`spinectl.landscape.atlas.fingerprint` of its atlas, its index
and the CRC-32 of its outputs (names, dtypes, shapes and bytes), and :func:`read` checks all three
(and its number of draws) before the chunk counts as done. A chunk that fails is solved again, as the
study's store does with a damaged chunk (:mod:`spinectl.landscape.study.store`).
"""

from __future__ import annotations

import contextlib
import re
import zipfile
import zlib
from pathlib import Path

import numpy as np

from ..atomic import atomic_path
from ..errors import OutputError

ATLAS, INDEX, CRC = "_atlas", "_index", "_crc32"
"""The entries of a chunk file beside its outputs: its atlas's fingerprint, its index, its outputs' CRC-32."""

NAME = re.compile(r"(?P<atlas>[0-9a-f]{16})-(?P<index>\d{6,})\.npz")
"""A chunk file's name: its atlas's fingerprint and its index."""


def name(key: str, index: int) -> str:
    """The file name of chunk ``index`` of the atlas ``key``.

    Parameters
    ----------
    key : str
        The atlas's fingerprint (16 hex digits).
    index : int
        The chunk.

    Returns
    -------
    str
    """
    return f"{key}-{index:06d}.npz"


def checksum(outputs: dict[str, np.ndarray]) -> int:
    """CRC-32 of a chunk's outputs: every array's name, dtype, shape and bytes, in name order.

    Parameters
    ----------
    outputs : dict of str to numpy.ndarray

    Returns
    -------
    int
        In [0, 2^32).
    """
    crc = 0
    for key in sorted(outputs):
        array = np.ascontiguousarray(outputs[key])
        crc = zlib.crc32(f"{key}:{array.dtype.str}:{array.shape};".encode(), crc)
        crc = zlib.crc32(array.tobytes(), crc)
    return crc


def save(path: Path, outputs: dict[str, np.ndarray], key: str, index: int) -> None:
    """Save a chunk atomically (a temporary name, then a rename), with its atlas, index and checksum.

    Parameters
    ----------
    path : Path
        ``DIR/chunks/<name>``.
    outputs : dict of str to numpy.ndarray
        The chunk's outputs.
    key : str
        The atlas's fingerprint.
    index : int
        The chunk.
    """
    marks = {ATLAS: np.str_(key), INDEX: np.int64(index), CRC: np.uint32(checksum(outputs))}
    with atomic_path(path) as tmp, open(tmp, "wb") as handle:
        np.savez(handle, **outputs, **marks)


def read(path: Path, key: str, index: int, size: int) -> tuple[dict | None, str | None]:
    """A chunk's outputs as an earlier run of this atlas saved them, checked.

    Parameters
    ----------
    path : Path
        Where chunk ``index`` of the atlas ``key`` is saved.
    key : str
        The atlas's fingerprint.
    index : int
        The chunk.
    size : int
        Its number of draws.

    Returns
    -------
    outputs : dict of str to numpy.ndarray or None
        None if there is no file, or it fails a check.
    problem : str or None
        What is wrong with the file (to be solved again), e.g. ``"holds chunk 2 (a copy from another
        position)"``; None if it is good or absent.

    Raises
    ------
    OutputError
        Something other than a file (a folder) stands at the chunk's name: it could not be saved
        again, so the run is refused before any chunk is solved.
    """
    if (path.exists() or path.is_symlink()) and not path.is_file():
        raise OutputError(
            f"cannot write {str(path)!r}: a folder (or other non-file) stands where a chunk of the atlas belongs; "
            "remove it, then run the atlas again"
        )
    if not path.is_file():
        return None, None
    try:
        with np.load(path, allow_pickle=False) as saved:
            found = {k: saved[k] for k in saved.files}
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile, zlib.error):
        return None, "cannot be read (cut short, or no chunk file)"
    problem = _problem(found, key, index, size)
    return (None, problem) if problem else ({k: v for k, v in found.items() if not k.startswith("_")}, None)


def _problem(found: dict, key: str, index: int, size: int) -> str | None:
    """What is wrong with a chunk's entries (:func:`read`), or None."""
    if not {ATLAS, INDEX, CRC} <= set(found):
        return "records no atlas, position or checksum (no chunk of this spinectl)"
    if str(found[ATLAS]) != key:
        return f"is a chunk of another atlas ({str(found[ATLAS])[:16]})"
    if int(found[INDEX]) != index:
        return f"holds chunk {int(found[INDEX])} (a copy from another position)"
    outputs = {k: v for k, v in found.items() if not k.startswith("_")}
    if checksum(outputs) != int(found[CRC]):
        return "holds other outputs than were saved (its checksum differs)"
    if "status" not in outputs or outputs["status"].shape != (size,):
        return f"does not hold the chunk's {size} draws"
    return None


def remove_others(folder: Path, key: str) -> list[Path]:
    """Remove the chunk files of other atlases from ``folder`` (other files stay); best effort.

    Parameters
    ----------
    folder : Path
        ``DIR/chunks``.
    key : str
        The fingerprint of the atlas whose chunks stay.

    Returns
    -------
    list of Path
        The files removed.
    """
    removed = []
    with contextlib.suppress(OSError):
        for path in sorted(folder.iterdir()):
            match = NAME.fullmatch(path.name)
            if match and match["atlas"] != key and path.is_file() and not path.is_symlink():
                with contextlib.suppress(OSError):
                    path.unlink()
                    removed.append(path)
    return removed
