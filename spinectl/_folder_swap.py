"""What a folder swap may move and remove: the old folder read whole before, settled entry by entry after.

:func:`spinectl.atomic.staged_directory` replaces an output folder as a whole. Before the swap it reads
the old folder (:func:`inventory`) and refuses what a rename could not carry safely (a mount point inside,
an immutable or append-only entry, a folder whose entries this user cannot remove); after it, it removes
the old folder entry by entry (:func:`settle`), never as a tree, so that a file another process wrote
meanwhile is moved back, not lost (docs/robustness.md, "files written into an output folder ...").
"""

from __future__ import annotations

import contextlib
import errno
import os
import stat
import tempfile
import warnings
from pathlib import Path

from ._oscalls import RENAME_NOREPLACE
from ._oscalls import exchange as _exchange
from ._oscalls import mount_points_below as _mount_points_below
from ._oscalls import pinned as _pinned
from ._validate import show
from .errors import OutputError


class OutputWarning(UserWarning):
    """Files that another process wrote into an output folder while it was replaced were kept aside."""


def inventory(root: Path, files: bool = True) -> dict[str, tuple]:
    """Every entry below ``root`` (path relative to it) -> its :func:`_identity`, read now.

    Parameters
    ----------
    root : Path
        The folder a swap will replace.
    files : bool
        False: the attributes of regular files are not read (one ``open`` each), for a caller that
        links every file (Linux refuses to link an immutable or append-only one).

    Returns
    -------
    dict of str to tuple

    Raises
    ------
    OutputError
        What a swap of ``root`` cannot move or remove: a mount point inside (another device, or in the
        system's table of mounts), an immutable or append-only entry, a folder whose entries this user
        cannot remove.
    """
    top = os.lstat(root)
    mounted = _mount_points_below(root)
    if mounted:
        raise _refused(root, mounted[0], "is a mount point")
    check_removable(root, top)
    seen: dict[str, tuple] = {}
    folders = [(str(root), "")]
    while folders:
        folder, rel = folders.pop()
        with os.scandir(folder) as entries:
            for entry in entries:
                info = entry.stat(follow_symlinks=False)
                name = f"{rel}/{entry.name}" if rel else entry.name
                if info.st_dev != top.st_dev:
                    raise _refused(root, entry.path, "is on another file system (a mount point)")
                if files or not stat.S_ISREG(info.st_mode):
                    check_removable(Path(entry.path), info, root)
                seen[name] = _identity(info)
                if stat.S_ISDIR(info.st_mode):
                    folders.append((entry.path, name))
    return seen


def _identity(info: os.stat_result) -> tuple:
    """(device, inode, type, size, modification time): an entry unchanged since it was read has the same."""
    return (info.st_dev, info.st_ino, stat.S_IFMT(info.st_mode), info.st_size, info.st_mtime_ns)


def check_removable(path: Path, info: os.stat_result, root: Path | None = None) -> None:
    """:class:`OutputError` if the entry ``path`` is pinned, or is a folder whose entries cannot be removed.

    Parameters
    ----------
    path : Path
    info : os.stat_result
        Its ``lstat``.
    root : Path, optional
        The folder the message names (default: ``path``'s parent).
    """
    pinned = _pinned(path, info)
    if pinned:
        raise _refused(root or path.parent, path, f"is {pinned}")
    if stat.S_ISDIR(info.st_mode) and not os.access(path, os.W_OK | os.X_OK):
        raise _refused(root or path.parent, path, "is a folder whose entries this user cannot remove")


def _refused(root: Path, entry, why: str) -> OutputError:
    return OutputError(
        f"cannot write {str(root)!r}: {show(os.path.relpath(entry, root))} in it {why}; the folder is "
        "replaced as a whole when the "
        "run ends, and that entry could not go with it safely: move it out, or write to another folder"
    )


def settle(old: Path, new: Path, seen: dict[str, tuple], written: frozenset) -> None:
    """Remove the old folder after a swap, entry by entry; move back what another process wrote meanwhile.

    An entry goes if it is a hard link to the entry of ``new`` of its name, or is as it
    was read (``seen``: kept in ``new``, or replaced by this run's file). Anything else
    appeared or changed during the swap: it moves into ``new`` where that name is free or
    holds only a kept copy; where the run wrote that name too (``written``, top-level
    names), the old folder is kept, renamed to a visible ``<name>.kept-…`` beside, with
    an :class:`OutputWarning`.

    Parameters
    ----------
    old, new : Path
        The old folder (swapped aside) and the new one (at the target).
    seen : dict of str to tuple
        :func:`inventory` of the old folder, read before the swap.
    written : frozenset of str
        The top-level names this run wrote.
    """
    device = os.lstat(old).st_dev
    for _ in range(3):  # an entry that came while the folder was emptied: look again
        _settle_folder(old, new, "", seen, written, device)
        try:
            old.rmdir()
            return
        except FileNotFoundError:
            return
        except OSError:
            continue
    _keep_aside(old, new)


def _settle_folder(folder: Path, new: Path, rel: str, seen: dict, written: frozenset, device: int) -> None:
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return
    for entry in entries:
        name = f"{rel}/{entry.name}" if rel else entry.name
        here, there = Path(entry.path), new / entry.name
        with contextlib.suppress(OSError):
            info = entry.stat(follow_symlinks=False)
            now, then = _identity(info), seen.get(name)
            if stat.S_ISDIR(info.st_mode) and info.st_dev == device and then is not None and then[:3] == now[:3]:
                _settle_folder(here, there, name, seen, written, device)
                here.rmdir()
            elif _linked(here, there) or (now == then and not stat.S_ISDIR(info.st_mode)):
                here.unlink()
            elif not os.path.lexists(there):
                _move_back(here, there)
            elif name.split("/")[0] not in written and not here.is_dir() and not there.is_dir():
                os.replace(here, there)  # a newer version of a file kept: it takes the kept copy's place


def _linked(a: Path, b: Path) -> bool:
    try:
        one, two = os.lstat(a), os.lstat(b)
    except OSError:
        return False
    return (one.st_dev, one.st_ino) == (two.st_dev, two.st_ino)


def _move_back(here: Path, there: Path) -> None:
    """Rename ``here`` to ``there`` unless ``there`` exists by then (``FileExistsError``)."""
    if _exchange(here, there, RENAME_NOREPLACE):
        return
    if here.is_dir() and not here.is_symlink():
        if os.path.lexists(there):
            raise FileExistsError(errno.EEXIST, "File exists", str(there))
        os.rename(here, there)
    else:
        os.link(here, there, follow_symlinks=False)  # fails if there exists
        here.unlink()


def _keep_aside(old: Path, new: Path) -> None:
    """Rename what is left of the old folder to a visible name beside ``new`` and say so."""
    kept = old
    with contextlib.suppress(OSError):
        aside = Path(tempfile.mkdtemp(prefix=f"{new.name}.kept-", dir=new.parent))
        os.replace(old, aside)  # onto the empty folder just made
        kept = aside
    left = sorted(str(path.relative_to(kept)) for path in kept.rglob("*") if not path.is_dir())
    warnings.warn(
        OutputWarning(
            f"{len(left)} file(s) written into {str(new)!r} by another process while it was replaced could not "
            f"be put back (this run wrote the same names): they are kept in {str(kept)!r}"
        ),
        stacklevel=2,
    )
