"""A cache of compiled MuJoCo models (MuJoCo's binary ``.mjb``), so that a model compiles once (docs/anatomy.md).

Composing MyoTorso and compiling it takes most of :func:`spinectl.anatomy.load`; MuJoCo's own
binary of the compiled model (:func:`mujoco.mj_saveModel`, read back by
``mujoco.MjModel.from_binary_path``) loads in a fraction of that and holds the whole
``MjModel``: names, keyframes, equalities, muscle parameters, everything spinectl reads.
The editable spec is not cached: only MuJoCo as the referee (``--check``) needs it, and it
is composed on demand.

The key is a SHA-256 of what the compiled model depends on:

- MuJoCo's version, myo-sim's version and this file's :data:`FORMAT`;
- a built-in model: its name and myo-sim's package files, the sources (``.py``, ``.xml``,
  ``.json``, ``.toml``) by content and the other files (meshes, textures) by size and
  modification time, as Python's own bytecode cache checks a source;
- an MJCF file: its bytes, the model as MuJoCo parsed it (:meth:`mujoco.MjSpec.to_xml`, its includes
  merged) and the bytes of every mesh, texture, height field and skin file it names.

The folder is ``$SPINECTL_CACHE_DIR``, else ``$XDG_CACHE_HOME/spinectl``, else
``~/.cache/spinectl``: per key a ``.mjb`` and a JSON header with its SHA-256, each written
atomically (a temporary name, then a rename). A file that is truncated, corrupt, of another
key or unreadable is ignored and rebuilt. A folder that cannot be written means no cache (one
debug log line), never an error.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
from pathlib import Path

from ..atomic import atomic_path

FORMAT = 2
"""The cache file's layout; a new number invalidates every older file (2: the model as published, its welds
and free root taken into the tree, :mod:`spinectl.anatomy.devices`)."""

SOURCE_SUFFIXES = frozenset({".py", ".xml", ".json", ".toml"})
"""A package's files hashed by content; the others (large binary assets) by size and modification time."""

log = logging.getLogger(__name__)


def cache_dir() -> Path:
    """The cache folder: ``$SPINECTL_CACHE_DIR``, else ``$XDG_CACHE_HOME/spinectl``, else ``~/.cache/spinectl``.

    Returns
    -------
    pathlib.Path
    """
    if os.environ.get("SPINECTL_CACHE_DIR"):
        return Path(os.environ["SPINECTL_CACHE_DIR"])
    if os.environ.get("XDG_CACHE_HOME"):
        return Path(os.environ["XDG_CACHE_HOME"]) / "spinectl"
    return Path.home() / ".cache" / "spinectl"


def digest(*parts) -> str:
    """SHA-256 of ``parts`` (each bytes or str, length-prefixed so that no two lists collide).

    Parameters
    ----------
    *parts : bytes or str

    Returns
    -------
    str
        Hex SHA-256.
    """
    out = hashlib.sha256()
    for part in parts:
        data = part.encode() if isinstance(part, str) else bytes(part)
        out.update(len(data).to_bytes(8, "little"))
        out.update(data)
    return out.hexdigest()


def _key(*parts) -> str:
    """SHA-256 of the versions and ``parts`` (:func:`digest`)."""
    import mujoco

    return digest(f"format {FORMAT}", f"mujoco {mujoco.__version__}", *parts)


def builtin_key(name: str, package) -> str:
    """The key of a built-in model composed by an installed package (myo-sim).

    Parameters
    ----------
    name : str
        The model's name (``"myotorso"``).
    package : module
        The package that composes it (:mod:`myo_sim`).

    Returns
    -------
    str
        Hex SHA-256.
    """
    root = Path(package.__file__).parent
    parts = [f"builtin {name}", f"{package.__name__} {getattr(package, '__version__', '?')}"]
    for path in sorted(root.rglob("*")):
        if "__pycache__" in path.parts or not path.is_file():
            continue
        parts.append(path.relative_to(root).as_posix())
        if path.suffix in SOURCE_SUFFIXES:
            parts.append(path.read_bytes())
        else:
            stat = path.stat()
            parts.append(f"{stat.st_size} {stat.st_mtime_ns}")
    return _key(*parts)


def file_key(spec, text: bytes = b"") -> str | None:
    """The key of a model parsed from an MJCF file: its MJCF as MuJoCo writes it and its asset files' bytes.

    Parameters
    ----------
    spec : mujoco.MjSpec
        The spec parsed from the file (:meth:`mujoco.MjSpec.from_file`).
    text : bytes
        The file's own bytes: MuJoCo's writing of the spec drops what it reads as a default, a
        ``stiffness="nan"`` included, so that file's key would be that of the file without it.

    Returns
    -------
    str or None
        Hex SHA-256, or None (no cache) where MuJoCo cannot write the model (it compiles it to
        write it: a missing mesh, a zero mass) or an asset file cannot be read: the compiler then
        says why, as without the cache.
    """
    try:
        parts = [spec.to_xml(), text]
    except ValueError as exc:
        log.debug("no compiled-model cache: MuJoCo cannot write the model: %s", exc)
        return None
    base = Path(spec.modelfiledir or ".")
    kinds = (
        (spec.meshes, spec.meshdir),
        (spec.skins, spec.meshdir),
        (spec.hfields, spec.meshdir),
        (spec.textures, spec.texturedir),
    )
    for items, folder in kinds:
        for item in items:
            if not item.file:
                continue
            try:
                parts += [item.file, (base / (folder or "") / item.file).read_bytes()]
            except OSError:
                log.debug("no compiled-model cache: cannot read the asset %s", item.file)
                return None
    return _key(*parts)


def _paths(key: str) -> tuple:
    """The compiled model (MuJoCo's ``.mjb``, as MuJoCo reads it fastest: from its own file) and its header."""
    folder = cache_dir()
    return folder / f"{key}.mjb", folder / f"{key}.json"


def read(key: str):
    """The cached model of ``key`` and its metadata, or None where there is none or it cannot be read.

    The header names the key and the SHA-256 of the ``.mjb`` file; a file that does not match
    it (truncated, corrupt, half of an interrupted pair) is ignored and later rewritten.

    Parameters
    ----------
    key : str
        From :func:`builtin_key` or :func:`file_key`.

    Returns
    -------
    tuple or None
        (mujoco.MjModel, dict of the metadata given to :func:`write`).
    """
    import mujoco

    binary, header_path = _paths(key)
    try:
        header = json.loads(header_path.read_bytes())
        checksum = hashlib.sha256(binary.read_bytes()).hexdigest()
        if not isinstance(header, dict) or header.get("key") != key or header.get("mjb_sha256") != checksum:
            raise ValueError("its key or its checksum does not match")
        # read again by MuJoCo: a file replaced meanwhile is a whole one (atomic rename) of the same key
        model = mujoco.MjModel.from_binary_path(str(binary))
    except (FileNotFoundError, NotADirectoryError):  # none cached (yet), or no folder to hold one
        return None
    except (OSError, ValueError, TypeError, UnicodeDecodeError) as exc:
        log.debug("ignoring the compiled-model cache %s (rebuilt): %s", binary, exc)
        return None
    meta = header.get("meta")
    return model, meta if isinstance(meta, dict) else {}


def write(key: str, model, meta: dict) -> None:
    """Store a compiled model under ``key``; a folder that cannot be written means no cache, silently.

    The ``.mjb`` first, then its header, each atomically: a reader sees a matching pair or
    ignores what it finds.

    Parameters
    ----------
    key : str
        From :func:`builtin_key` or :func:`file_key`.
    model : mujoco.MjModel
        The compiled model.
    meta : dict
        JSON-able metadata returned with it by :func:`read` (e.g. the SHA-256 of its MJCF).
    """
    import mujoco
    import numpy as np

    from ..errors import SpinectlError

    binary, header_path = _paths(key)
    try:
        payload = np.empty(mujoco.mj_sizeModel(model), np.uint8)
        mujoco.mj_saveModel(model, None, payload)
        header = {"key": key, "mjb_sha256": hashlib.sha256(payload).hexdigest(), "meta": meta}
        with atomic_path(binary) as tmp:
            tmp.write_bytes(payload.tobytes())
        with atomic_path(header_path) as tmp:
            tmp.write_text(json.dumps(header), encoding="utf-8")
    except (OSError, SpinectlError, ValueError) as exc:  # a cache that cannot be written is no cache, never an error
        log.debug("no compiled-model cache at %s: %s", binary, exc)
