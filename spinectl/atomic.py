"""Atomic output: write to a temporary name beside the target, then rename.

An interrupted run leaves either the previous file or the new one, never a
half-written file.
"""

from __future__ import annotations

import contextlib
import errno
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path

from ._validate import show
from .errors import OutputError


@contextlib.contextmanager
def atomic_path(target: str | Path, *, directory: bool = False) -> Iterator[Path]:
    """Yield a temporary path in the target's folder; rename it onto ``target`` on success.

    On an exception the temporary is removed and ``target`` is left untouched.
    The new output gets the previous one's permissions, or the usual ones of a
    new file (the umask), not the private mode of a temporary.

    Parameters
    ----------
    target : str or Path
        Final file (or folder, with ``directory=True``, e.g. a Zarr store).
    directory : bool
        Create the temporary as a folder.

    Yields
    ------
    Path
        The temporary to write, beside ``target``: an empty file, or an empty folder
        with ``directory=True``.

    Raises
    ------
    OutputError
        The folder cannot be created or written, the writer meets a full disk
        (an ``OSError`` of :data:`DEVICE_ERRORS`), or ``target`` cannot be
        replaced (e.g. a folder where a file should go). Other exceptions of the
        writer itself propagate unchanged.
    """
    target = _named(target)
    with _output_errors(target):
        target.parent.mkdir(parents=True, exist_ok=True)
        tmp = _temporary(target, directory)
    try:
        with _output_errors(target, errnos=DEVICE_ERRORS):  # the writer meets a full disk
            yield tmp
        with _output_errors(target):
            _set_mode(tmp, target, directory)
            _replace(tmp, target, directory)
    except BaseException:
        if tmp.is_dir():
            shutil.rmtree(tmp, ignore_errors=True)
        else:
            tmp.unlink(missing_ok=True)
        raise


def _named(target: str | Path) -> Path:
    """``target`` as a Path, or :class:`OutputError` if its name has a line break or control character.

    Such a name is valid on POSIX, but it breaks the one-line listings and messages
    that name the outputs, and the command line that a preset's header records.
    """
    text = str(target)
    if not text.isprintable():
        raise OutputError(f"cannot write {show(text)}: the name must be printable (no line breaks or control codes)")
    return Path(target)


DEVICE_ERRORS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EROFS, errno.EIO})
"""Error numbers of an output's file system refusing the bytes (full, over quota, file too
large, read-only, failing): a writer's ``OSError`` with one of these is an :class:`OutputError`;
its other exceptions (e.g. a missing input) propagate unchanged."""


@contextlib.contextmanager
def _output_errors(target: Path, errnos=None):
    try:
        yield
    except OutputError:
        raise  # already one line, naming its own target
    except OSError as exc:
        if errnos is not None and exc.errno not in errnos:
            raise
        reason = exc.strerror or exc.__class__.__name__
        raise OutputError(f"cannot write {str(target)!r}: {reason}") from None


def _temporary(target: Path, directory: bool) -> Path:
    prefix = f".{target.name}."
    if directory:
        return Path(tempfile.mkdtemp(prefix=prefix, suffix=".tmp", dir=target.parent))
    fd, name = tempfile.mkstemp(prefix=prefix, suffix=".tmp" + target.suffix, dir=target.parent)
    os.close(fd)
    return Path(name)


def _set_mode(tmp: Path, target: Path, directory: bool) -> None:
    """Give ``tmp`` the mode of the output it replaces, or the umask's default (mkstemp makes 0600)."""
    if target.exists():
        mode = target.stat().st_mode
    else:
        umask = os.umask(0)  # the only way to read it; restored at once (sweeps use processes, not threads)
        os.umask(umask)
        mode = (0o777 if directory else 0o666) & ~umask
    os.chmod(tmp, mode & 0o7777)


def _replace(tmp: Path, target: Path, directory: bool) -> None:
    if not (directory and target.exists()):
        os.replace(tmp, target)
        return
    # A folder cannot be renamed over a non-empty one: move the old aside first,
    # and put it back if the new one cannot take its place.
    old = target.with_name(f".{target.name}.old")
    shutil.rmtree(old, ignore_errors=True)
    os.replace(target, old)
    try:
        os.replace(tmp, target)
    except BaseException:
        os.replace(old, target)
        raise
    shutil.rmtree(old, ignore_errors=True)


def check_writable(target: str | Path) -> Path:
    """Raise :class:`OutputError` now if ``target`` could not be written later.

    Long jobs call it before they start, so that a typo in ``--out`` costs a
    second, not the run. It makes the missing parent folders (as
    :func:`atomic_path` would) and a temporary file beside ``target``, then
    removes the file; ``target`` itself is not touched.

    Parameters
    ----------
    target : str or Path
        The file a job will write with :func:`atomic_path`.

    Returns
    -------
    Path
        ``target`` as a :class:`~pathlib.Path`.

    Raises
    ------
    OutputError
        ``target`` is a folder or has a name that is not printable, or its folder cannot be
        created or written.
    """
    target = _named(target)
    with _output_errors(target):
        if target.is_dir():
            raise IsADirectoryError(errno.EISDIR, "Is a directory")
        target.parent.mkdir(parents=True, exist_ok=True)
        _temporary(target, directory=False).unlink()
    return target


def atomic_write_text(target: str | Path, text: str) -> Path:
    """Write ``text`` to ``target`` atomically (UTF-8); return the target path.

    Parameters
    ----------
    target : str or Path
        Final file.
    text : str
        Its whole content.

    Returns
    -------
    Path
        ``target`` as a :class:`~pathlib.Path`, now holding ``text``.
    """
    with atomic_path(target) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return Path(target)


def _stage(target: Path) -> Path:
    """A new, empty staging folder for ``target`` on its file system: inside it, or beside it if it does not exist."""
    if target.is_dir():
        return Path(tempfile.mkdtemp(prefix=f".{target.name}.", suffix=".tmp", dir=target))
    target.parent.mkdir(parents=True, exist_ok=True)
    return _temporary(target, directory=True)


def check_staged_directory(target: str | Path) -> Path:
    """Raise :class:`OutputError` now if :func:`staged_directory` could not fill ``target`` later.

    Long jobs call it before they start: it makes the staging folder, moves a file
    from it into ``target`` by a rename (as the end of the job will) and removes both;
    a mount point that refuses the rename, a file where the folder should be or a
    read-only folder fail here, not after the run. ``target`` keeps its contents; its
    missing parent folders are created.

    Parameters
    ----------
    target : str or Path
        The output folder.

    Returns
    -------
    Path
        ``target`` as a :class:`~pathlib.Path`.

    Raises
    ------
    OutputError
        ``target`` is a file, or its folder cannot be written or take a rename from the staging folder.
    """
    target = _named(target)
    with _output_errors(target):
        if target.exists() and not target.is_dir():
            raise NotADirectoryError(errno.ENOTDIR, "Not a directory")
        stage = _stage(target)
        try:
            probe = stage / "probe"
            probe.touch()
            landed = (target if target.is_dir() else stage.parent) / f".{stage.name}.probe"
            os.replace(probe, landed)
            landed.unlink()
        finally:
            shutil.rmtree(stage, ignore_errors=True)
    return target


@contextlib.contextmanager
def staged_directory(target: str | Path) -> Iterator[Path]:
    """Yield an empty staging folder; on success move each of its files into ``target``.

    Every file lands by an atomic rename, all at the end: an interrupted run
    leaves ``target`` as it was, and files already in ``target`` that the run
    does not write are kept. On an exception the staging folder is removed.

    Parameters
    ----------
    target : str or Path
        The output folder (created if missing).

    Yields
    ------
    Path
        The empty staging folder, on ``target``'s file system (inside ``target`` if it
        exists, beside it if not: a mount point cannot take renames from its parent);
        write the outputs into it.

    Raises
    ------
    OutputError
        The folders cannot be created or the files not moved into ``target``.
    """
    target = Path(target)
    with _output_errors(target):
        stage = _stage(target)
    try:
        yield stage
        with _output_errors(target):
            target.mkdir(exist_ok=True)
            for item in sorted(stage.iterdir()):
                _set_mode(item, target / item.name, item.is_dir())
                os.replace(item, target / item.name)
    finally:
        shutil.rmtree(stage, ignore_errors=True)
