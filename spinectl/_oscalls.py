"""The operating system's own calls behind :mod:`spinectl.atomic`, each with its fallback.

What a path leads to (symbolic link loops, links to nothing), ``fsync`` of a file or a
folder tree, Linux's ``renameat2`` (two folders exchanged in one step, a rename that never
replaces), a file's attributes (``chattr +i``, ``+a``: ``FS_IOC_GETFLAGS``), the mount points
inside a folder (psutil) and a process's start time (``/proc``). Where the OS or file
system lacks one, each says so (False, None, 0, []) and :mod:`spinectl.atomic` takes the
slower or weaker way that it documents.
"""

from __future__ import annotations

import errno
import functools
import os
import stat
import struct
from pathlib import Path

from ._validate import show
from .errors import OutputError


def check_way(path: Path) -> None:
    """Raise :class:`OutputError` if no file can be written at ``path``: the way to it is blocked.

    It is, where ``path`` is a symbolic link loop, or a part above it is a loop, a symbolic
    link to nothing, or no folder (a file, or a link to a file). A missing part is no block
    (the writer makes the folders), nor is ``path`` as a link to nothing (written through).

    Parameters
    ----------
    path : Path
        The output, as the user named it.

    Raises
    ------
    OutputError
        Naming the part and why, e.g. ``cannot write 'loop/x.nc': 'loop' is a symbolic link loop ...``.
    """
    parts = path.parts
    for depth in range(1, len(parts) + 1):
        step, above = Path(*parts[:depth]), depth < len(parts)
        try:
            info = os.stat(step)
        except FileNotFoundError:
            if above and os.path.islink(step):
                raise _no_way(
                    path, step, f"is a symbolic link to {os.readlink(step)!r}, which does not exist"
                ) from None
            return  # missing: made by the write (a link to nothing as the output itself: written through)
        except OSError as exc:
            if exc.errno == errno.ELOOP:
                raise _no_way(path, step, "is a symbolic link loop (following it leads back to it)") from None
            return  # e.g. no permission: the write says so
        if above and not stat.S_ISDIR(info.st_mode):
            kind = f"a symbolic link to a file ({os.readlink(step)!r})" if os.path.islink(step) else "a file"
            raise _no_way(path, step, f"is {kind}, not a folder")


def _no_way(path: Path, step: Path, why: str) -> OutputError:
    return OutputError(f"cannot write {str(path)!r}: {show(str(step))} {why}")


_QUIET_OPEN = os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NOCTTY", 0)
"""An entry opened only to be asked about: read-only, never waiting (a pipe), following no link, taking no
terminal."""


def start_time(pid: int) -> int | None:
    """The start time of a process (Linux's ``/proc/<pid>/stat``, field 22).

    Parameters
    ----------
    pid : int
        Process id.

    Returns
    -------
    int or None
        Clock ticks after boot; None where there is no such process or no ``/proc``.
    """
    try:
        text = Path(f"/proc/{pid}/stat").read_bytes()
    except OSError:
        return None
    try:  # the name (field 2) is in parentheses and may hold spaces: count from the last ')'
        return int(text.rsplit(b")", 1)[1].split()[19])
    except (IndexError, ValueError):
        return None


def synced(path: str | Path, tree: bool = True) -> None:
    """Write ``path`` to disk (``fsync``): a file, or a folder and (``tree``) every entry below it.

    A rename survives a power cut whole only if the bytes it names were on disk first: the
    new file (or folder, and all in it) is synced before its rename, the folder holding the
    new name after it. A file system that takes no ``fsync`` of a folder is passed over.

    Parameters
    ----------
    path : str or Path
        A file or a folder.
    tree : bool
        For a folder: every file and folder below it too, each folder after what it holds.

    Raises
    ------
    OSError
        The file system failed to write (e.g. ``EIO``, ``ENOSPC``).
    """
    if tree and os.path.isdir(path) and not os.path.islink(path):
        for folder, _, files in os.walk(path, topdown=False):  # each folder after what it holds
            for name in files:
                _fsync(os.path.join(folder, name))
            _fsync(folder)
    else:
        _fsync(path)


def _fsync(path: str | Path) -> None:
    try:
        fd = os.open(path, _QUIET_OPEN)
    except OSError as exc:  # a symbolic link or socket (no bytes of its own), a file this user cannot read
        if exc.errno in (errno.ELOOP, errno.EACCES, errno.EPERM, errno.ENXIO):
            return
        raise
    try:
        os.fsync(fd)
    except OSError as exc:  # a file system or kind of file that takes no fsync (a folder on some, a pipe)
        if exc.errno not in (errno.EINVAL, errno.ENOTSUP, errno.EBADF):
            raise
    finally:
        os.close(fd)


RENAME_EXCHANGE = 2
"""Linux's ``renameat2`` flag that swaps two paths in one step (<linux/fs.h>)."""


RENAME_NOREPLACE = 1
"""Linux's ``renameat2`` flag that fails (EEXIST) rather than replace the destination (<linux/fs.h>)."""


@functools.cache
def _renameat2():
    """The C library's ``renameat2``, or None; looked up once (``find_library`` may start ``ldconfig``)."""
    import ctypes
    import ctypes.util

    try:
        return ctypes.CDLL(ctypes.util.find_library("c"), use_errno=True).renameat2
    except (OSError, AttributeError, TypeError):  # no C library by that name, or no renameat2 in it
        return None


def exchange(a: Path, b: Path, flags: int = RENAME_EXCHANGE) -> bool:
    """Swap the paths ``a`` and ``b`` atomically (Linux >= 3.15, ``renameat2`` through ctypes).

    Parameters
    ----------
    a, b : Path
        Two paths on one file system.
    flags : int
        :data:`RENAME_EXCHANGE`, or :data:`RENAME_NOREPLACE`: rename ``a`` to ``b`` unless ``b`` exists.

    Returns
    -------
    bool
        Done; False where the OS or file system cannot (the caller renames in two steps).

    Raises
    ------
    OSError
        The rename failed (``FileExistsError`` for an existing ``b`` with ``RENAME_NOREPLACE``).
    """
    import ctypes

    renameat2 = _renameat2()
    if renameat2 is None:
        return False
    at_cwd = -100  # AT_FDCWD: paths relative to the working directory
    if renameat2(at_cwd, os.fsencode(a), at_cwd, os.fsencode(b), flags) == 0:
        return True
    error = ctypes.get_errno()
    if error in (errno.ENOSYS, errno.EINVAL, errno.ENOTSUP):
        return False  # not supported here: the caller renames in two steps
    raise OSError(error, os.strerror(error), str(b))


FS_IOC_GETFLAGS = 0x80086601 if struct.calcsize("l") == 8 else 0x80046601
"""Linux's ioctl that reads a file's attributes (``lsattr``; <linux/fs.h>, ``_IOR('f', 1, long)``)."""


PINNED_FLAGS = {0x10: "immutable (chattr +i)", 0x20: "append-only (chattr +a)"}
"""Linux's FS_IMMUTABLE_FL and FS_APPEND_FL: such an entry cannot be removed, nor one inside such a folder."""


def pinned(path: Path, info: os.stat_result) -> str | None:
    """Whether an entry is immutable or append-only (Linux's ``chattr``, BSD's and macOS's ``chflags``).

    Parameters
    ----------
    path : Path
        The entry.
    info : os.stat_result
        Its ``lstat``.

    Returns
    -------
    str or None
        ``'immutable (chattr +i)'``, ``'append-only (chattr +a)'`` (or the ``chflags`` words), else None.
    """
    flags = getattr(info, "st_flags", 0)  # BSD and macOS: chflags
    if flags & (stat.UF_IMMUTABLE | stat.SF_IMMUTABLE):
        return "immutable (chflags uchg)"
    if flags & (stat.UF_APPEND | stat.SF_APPEND):
        return "append-only (chflags uappnd)"
    if not (stat.S_ISREG(info.st_mode) or stat.S_ISDIR(info.st_mode)):
        return None  # devices and pipes are not opened (an open may act); symbolic links carry no flags
    flags = _linux_flags(path)
    return next((what for flag, what in PINNED_FLAGS.items() if flags & flag), None)


def _linux_flags(path: Path) -> int:
    """The attributes of ``path`` (``lsattr``), or 0 where they cannot be read (not Linux, no permission)."""
    try:
        import fcntl
    except ImportError:  # not POSIX
        return 0
    try:
        fd = os.open(path, _QUIET_OPEN)
    except OSError:
        return 0
    try:
        return struct.unpack("i", fcntl.ioctl(fd, FS_IOC_GETFLAGS, bytes(8))[:4])[0]  # the kernel writes an int
    except OSError:  # not Linux, or a file system without attributes
        return 0
    finally:
        os.close(fd)


def mount_points_below(root: str | Path) -> list[str]:
    """The mount points strictly inside ``root``, as psutil reads the system's table of mounts.

    Parameters
    ----------
    root : str or Path
        A folder.

    Returns
    -------
    list of str
        Their real paths, sorted (bind mounts on the same device included: Linux's
        ``/proc/self/mounts``); [] where the table cannot be read.
    """
    import psutil  # only here: the commands that write no folder do not pay for its import

    try:
        points = [part.mountpoint for part in psutil.disk_partitions(all=True)]
    except OSError:
        return []
    inside = os.path.realpath(root) + os.sep
    return sorted(point for point in points if point.startswith(inside))
