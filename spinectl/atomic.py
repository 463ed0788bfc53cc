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
        The folder cannot be created or written, or ``target`` cannot be
        replaced (e.g. a folder where a file should go). Exceptions of the
        writer itself propagate unchanged.
    """
    target = Path(target)
    with output_errors(target):
        target.parent.mkdir(parents=True, exist_ok=True)
        tmp = _temporary(target, directory)
    try:
        yield tmp
        with output_errors(target):
            _set_mode(tmp, target, directory)
            _replace(tmp, target, directory)
    except BaseException:
        if tmp.is_dir():
            shutil.rmtree(tmp, ignore_errors=True)
        else:
            tmp.unlink(missing_ok=True)
        raise


@contextlib.contextmanager
def output_errors(target: str | Path) -> Iterator[None]:
    """Turn an :class:`OSError` of the block into an :class:`OutputError` naming ``target``.

    Parameters
    ----------
    target : str or Path
        The output, as named in the message.

    Yields
    ------
    None
    """
    try:
        yield
    except OutputError:
        raise  # already says what and why
    except OSError as exc:
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
        ``target`` is a folder, or its folder cannot be created or written.
    """
    target = Path(target)
    with output_errors(target):
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
        The empty staging folder, beside ``target``; write the outputs into it.

    Raises
    ------
    OutputError
        The folders cannot be created or the files not moved into ``target``.
    """
    target = Path(target)
    with output_errors(target):
        target.parent.mkdir(parents=True, exist_ok=True)
        stage = _temporary(target, directory=True)
    try:
        yield stage
        with output_errors(target):
            target.mkdir(exist_ok=True)
            for item in sorted(stage.iterdir()):
                _set_mode(item, target / item.name, item.is_dir())
                os.replace(item, target / item.name)
    finally:
        shutil.rmtree(stage, ignore_errors=True)
