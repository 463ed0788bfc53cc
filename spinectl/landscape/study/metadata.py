"""A study store's metadata files checked before zarr reads them (docs/robustness.md, "Studies").

zarr and xarray open a store through its metadata: the root's and each array's ``.zgroup``, ``.zattrs`` and
``.zarray``, and the consolidated ``.zmetadata`` of a finished store. A file there that is no small regular
file would hang the reader (a FIFO) or fill the memory (a link to /dev/zero); a consolidated copy that
disagrees with the files would be read instead of them. Both are said in one line, with the remedy.
"""

from __future__ import annotations

import json
from pathlib import Path

from ..._validate import file_fault
from ...errors import ParameterError

MAX_METADATA_BYTES = 16 * 2**20
"""The largest metadata file of a store read [B]: a study's are kilobytes (its layout lists every array)."""


def check_metadata_files(path) -> None:
    """Every metadata file of the store (the root's and each array's) a small regular file: zarr would read a
    FIFO for ever and a link to /dev/zero until memory runs out (``_validate.file_fault``).

    Parameters
    ----------
    path : str or pathlib.Path
        The store.

    Raises
    ------
    ParameterError
        Naming the file and what it is (field ``store``).
    """
    root = Path(path)
    folders = [root, *(d for d in root.iterdir() if d.is_dir())] if root.is_dir() else []
    for file in (f / name for f in folders for name in (".zmetadata", ".zgroup", ".zattrs", ".zarray")):
        if fault := file_fault(file, MAX_METADATA_BYTES):
            raise ParameterError("store", f"{str(path)!r} is damaged: its metadata file {str(file)!r} {fault}")


def check_consolidated(path) -> None:
    """A finished store's ``.zmetadata``, if any, must be what its files say: a copy for ``xarray.open_zarr``,
    which the resume of a finished store writes again (the remedy the error gives).

    Parameters
    ----------
    path : str or pathlib.Path
        The store.

    Raises
    ------
    ParameterError
        Naming the file, what is wrong and the remedy (field ``store``).
    """
    file = Path(path) / ".zmetadata"
    if not (file.exists() or file.is_symlink()):
        return
    try:
        fault = _consolidated_fault(Path(path), json.loads(file.read_text(encoding="utf-8"), parse_constant=str))
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        fault = f"cannot be read as JSON ({exc.strerror if isinstance(exc, OSError) else exc})"
    if fault:
        raise ParameterError(
            "store",
            f"{str(path)!r} is damaged: its consolidated metadata {str(file)!r} {fault}: remove that file and run "
            "the study again with --resume, which writes it anew from the arrays' own metadata",
        )


def _consolidated_fault(path: Path, document) -> str:
    """What is wrong with a consolidated metadata document, or ``""``: its form, then each entry against its file."""
    entries = document.get("metadata") if isinstance(document, dict) else None
    if not isinstance(entries, dict) or document.get("zarr_consolidated_format") != 1:
        return "is not Zarr's consolidated metadata (a table of 'metadata' with 'zarr_consolidated_format' = 1)"
    folders = ["", *(f"{d.name}/" for d in path.iterdir() if d.is_dir())]  # the root and its arrays: no subgroups
    files = {f"{f}{name}" for f in folders for name in (".zgroup", ".zattrs", ".zarray") if (path / f / name).is_file()}
    if set(entries) != files:
        return f"does not list the store's metadata files (lists {len(entries)}, the store has {len(files)})"
    for name, entry in sorted(entries.items()):
        try:
            same = json.loads((path / name).read_text(encoding="utf-8"), parse_constant=str) == entry
        except (OSError, UnicodeDecodeError, ValueError):
            same = False
        if not same:
            return f"does not hold what {name!r} of the store holds"
    return ""
