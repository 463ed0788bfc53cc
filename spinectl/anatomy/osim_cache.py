"""A cache of OpenSim linearisations, so that an ``.osim`` model is linearised once per posture (docs/anatomy.md).

An OpenSim model cannot be stored compiled as MuJoCo's can (:mod:`spinectl.anatomy.cache`):
what is kept is the :class:`~spinectl.anatomy.linearise.Linearisation` at a posture, everything
the chains, verdicts and optima read. Its key is a SHA-256 (:func:`spinectl.anatomy.cache.digest`) of

- this file's :data:`FORMAT`, OpenSim's version, spinectl's version and the bytes of spinectl's
  own Python files (a changed muscle law or geometry is a new key, released or not);
- the ``.osim`` file's bytes (their SHA-256, :attr:`OsimEngine.sha256`);
- the coordinates linearised over (the mapping's plane and the couplers' coordinates, in
  order), how many are the chain's, and the posture (each coordinate's value, exactly).

A mapping that names the same coordinates shares the entry: the linearisation does not read the
mapping's bodies. The folder is the compiled models' (:func:`spinectl.anatomy.cache.cache_dir`):
per key one ``<key>.osim-lin.npz`` (numpy's zip of the arrays, with the key in it), written
atomically. A file that is truncated, corrupt (its zip checksums), of another key or
unreadable is ignored and rewritten; a folder that cannot be written means no cache (one
debug log line), never an error. Within a process the engine also keeps each linearisation it
made (:attr:`OsimEngine.linearisations`), cache or not.
"""

from __future__ import annotations

import functools
import logging
import zipfile
from dataclasses import fields
from pathlib import Path

import numpy as np

from .._version import __version__
from ..atomic import atomic_path
from .cache import cache_dir, digest
from .linearise import Linearisation

FORMAT = 1
"""The cache file's layout; a new number invalidates every older file."""

log = logging.getLogger(__name__)


@functools.cache
def _code() -> str:
    """SHA-256 of spinectl's Python files (their paths and bytes), read once per process."""
    root = Path(__file__).resolve().parents[1]
    parts = []
    for path in sorted(root.rglob("*.py")):
        parts += [path.relative_to(root).as_posix(), path.read_bytes()]
    return digest(*parts)


def key(sha256: str, names, n: int, values: dict, activations=None) -> str:
    """The key of a linearisation of an ``.osim`` file at a posture.

    Parameters
    ----------
    sha256 : str
        The SHA-256 of the file's bytes.
    names : sequence of str
        The coordinates linearised over, the chain's first.
    n : int
        How many of ``names`` are the chain's.
    values : dict
        Coordinate name -> value [rad] of the posture (the others at the file's defaults).
    activations : numpy.ndarray, shape (m,), optional
        The operating activations [1], where the linearisation depends on them (compliant tendons).

    Returns
    -------
    str
        Hex SHA-256.
    """
    from .export_osim import require_opensim

    osim = require_opensim()
    posture = [f"{name} {float(values[name]).hex()}" for name in sorted(values)]
    return digest(
        f"osim linearisation {FORMAT}",
        f"opensim {osim.__version__}",
        f"spinectl {__version__}",
        _code(),
        sha256,
        "\n".join(names),
        str(int(n)),
        "\n".join(posture),
        "" if activations is None else " ".join(float(a).hex() for a in activations),
    )


def _path(key_: str) -> Path:
    return cache_dir() / f"{key_}.osim-lin.npz"


def read(key_: str) -> Linearisation | None:
    """The cached linearisation of ``key_``, or None where there is none or it cannot be read.

    Parameters
    ----------
    key_ : str
        From :func:`key`.

    Returns
    -------
    Linearisation or None
    """
    path = _path(key_)
    try:
        with np.load(path, allow_pickle=False) as stored:
            if str(stored["key"]) != key_:
                raise ValueError("its key does not match")
            arrays = {f.name: stored[f.name] for f in fields(Linearisation)}
    except (FileNotFoundError, NotADirectoryError):  # none cached (yet), or no folder to hold one
        return None
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as exc:
        log.debug("ignoring the cached linearisation %s (rebuilt): %s", path, exc)
        return None
    arrays["dofs"] = tuple(int(d) for d in arrays["dofs"])
    arrays["n"] = int(arrays["n"])
    arrays["notes"] = tuple(str(note) for note in arrays["notes"])
    return Linearisation(**arrays)


def write(key_: str, lin: Linearisation) -> None:
    """Store a linearisation under ``key_``; a folder that cannot be written means no cache, silently.

    Parameters
    ----------
    key_ : str
        From :func:`key`.
    lin : Linearisation
    """
    from ..errors import SpinectlError

    path = _path(key_)
    arrays = {f.name: np.asarray(getattr(lin, f.name)) for f in fields(Linearisation)}
    try:
        with atomic_path(path) as tmp, open(tmp, "wb") as out:
            np.savez(out, key=np.array(key_), **arrays)
    except (OSError, SpinectlError, ValueError) as exc:  # a cache that cannot be written is no cache, never an error
        log.debug("no linearisation cache at %s: %s", path, exc)
