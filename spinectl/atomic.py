"""Atomic output: write to a temporary name beside the target, then rename.

An interrupted run leaves either the previous file or the new one, never a
half-written file. A folder replaces a folder in one step where the OS can
(Linux's ``renameat2`` with ``RENAME_EXCHANGE``), else in two (the old one moved
aside, the new one in), so that a set of files changes as a whole.
"""

from __future__ import annotations

import contextlib
import errno
import functools
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path

from ._validate import show
from .errors import OutputError, ParameterError


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
    target = _named(target)
    with output_errors(target):
        target.parent.mkdir(parents=True, exist_ok=True)
        tmp = _temporary(target, directory)
    try:
        with output_errors(target, errnos=DEVICE_ERRORS):  # the writer meets a full disk
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


def _named(target: str | Path) -> Path:
    """``target`` as a Path, or :class:`OutputError` if its name has a line break or control character.

    Such a name is valid on POSIX, but it breaks the one-line listings and messages
    that name the outputs, and the command line that a preset's header records.
    """
    text = str(target)
    if not _as_utf8(text).isprintable():
        raise OutputError(f"cannot write {show(text)}: the name must be printable (no line breaks or control codes)")
    return Path(target)


def _as_utf8(text: str) -> str:
    """A name as its bytes read as UTF-8: under a C locale Python keeps the bytes of ``Λ.png`` as
    surrogate escapes (``'\\udcce\\udc9b.png'``), which are not printable though the name is."""
    try:
        return os.fsencode(text).decode("utf-8")
    except UnicodeError:  # not UTF-8 (e.g. Latin-1 bytes): judged as Python holds it
        return text


DEVICE_ERRORS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EROFS, errno.EIO})
"""Error numbers of an output's file system refusing the bytes (full, over quota, file too
large, read-only, failing): a writer's ``OSError`` with one of these is an :class:`OutputError`;
its other exceptions (e.g. a missing input) propagate unchanged."""


@contextlib.contextmanager
def output_errors(target: str | Path, errnos=None) -> Iterator[None]:
    """Turn an :class:`OSError` of the block into an :class:`OutputError` naming ``target``.

    Parameters
    ----------
    target : str or Path
        The output, as named in the message.
    errnos : collection of int, optional
        Convert only these error numbers (e.g. :data:`DEVICE_ERRORS`); others propagate.

    Yields
    ------
    None
    """
    try:
        yield
    except OutputError:
        raise  # already says what and why
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
    if _exchange(tmp, target):  # one step: the new folder at target, the old one at tmp
        shutil.rmtree(tmp, ignore_errors=True)
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


RENAME_EXCHANGE = 2
"""Linux's ``renameat2`` flag that swaps two paths in one step (<linux/fs.h>)."""


@functools.cache
def _renameat2():
    """The C library's ``renameat2``, or None; looked up once (``find_library`` may start ``ldconfig``)."""
    import ctypes
    import ctypes.util

    try:
        return ctypes.CDLL(ctypes.util.find_library("c"), use_errno=True).renameat2
    except (OSError, AttributeError, TypeError):  # no C library by that name, or no renameat2 in it
        return None


def _exchange(a: Path, b: Path) -> bool:
    """Swap the paths ``a`` and ``b`` atomically (Linux >= 3.15); False where the OS or file system cannot."""
    import ctypes

    renameat2 = _renameat2()
    if renameat2 is None:
        return False
    at_cwd = -100  # AT_FDCWD: paths relative to the working directory
    if renameat2(at_cwd, os.fsencode(a), at_cwd, os.fsencode(b), RENAME_EXCHANGE) == 0:
        return True
    error = ctypes.get_errno()
    if error in (errno.ENOSYS, errno.EINVAL, errno.ENOTSUP):
        return False  # not supported here: the caller renames in two steps
    raise OSError(error, os.strerror(error), str(b))


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
    target = _named(target)
    with output_errors(target):
        if target.is_dir():
            raise IsADirectoryError(errno.EISDIR, "Is a directory")
        target.parent.mkdir(parents=True, exist_ok=True)
        _temporary(target, directory=False).unlink()
    return target


def check_distinct(outputs: dict, inputs: dict | None = None) -> None:
    """Raise :class:`ParameterError` if an output is one of the inputs or another of the outputs.

    Paths are compared resolved (after symlinks, ``..``), and as files where they exist
    (hard links), so that no spelling of a path lets a command replace its own input
    (``calibrate --config x.toml --out x.toml``) or write two outputs onto one file.

    Parameters
    ----------
    outputs : dict
        Option name (e.g. ``"--out"``) -> the path it writes, a list of paths (the files of
        an output folder), or None (not given).
    inputs : dict, optional
        Option name -> the path it reads, or None.

    Raises
    ------
    ParameterError
        Named after the later of the two options, e.g. ``--history: is the same file as --out ('x')``.
    """
    seen: list[tuple[str, Path]] = []
    for kind, given in (("input", inputs or {}), ("output", outputs)):
        for field, paths in given.items():
            for path in [paths] if isinstance(paths, str | Path) else paths or ():
                for other, earlier in seen:
                    if kind == "output" and _same_file(path, earlier):
                        raise ParameterError(
                            field,
                            f"is the same file as {other} ({str(earlier)!r}): an output must not replace "
                            "an input or another output",
                        )
                seen.append((field, Path(path)))


def _same_file(a: str | Path, b: str | Path) -> bool:
    if os.path.realpath(a) == os.path.realpath(b):
        return True
    try:
        return os.path.samefile(a, b)
    except (OSError, ValueError):  # one of them does not exist (yet), or cannot be a path
        return False


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


def check_folder(target: str | Path, names=()) -> Path:
    """Raise :class:`OutputError` now if the folder ``target`` could not take the files ``names`` later.

    Long jobs call it before they start (:func:`staged_directory` calls it too): it
    makes the missing parent folders and a temporary folder beside ``target``, then
    removes it; ``target`` itself is not touched.

    Parameters
    ----------
    target : str or Path
        The output folder, written with :func:`staged_directory`.
    names : iterable of str
        The files the job will write into it.

    Returns
    -------
    Path
        ``target`` as a :class:`~pathlib.Path`.

    Raises
    ------
    OutputError
        ``target`` is a file, the working directory or a folder above it (it could not be
        replaced as a whole), one of ``names`` is a folder in it, or its folder cannot be
        created or written.
    """
    target = _named(target)
    with output_errors(target):
        if (target.exists() or target.is_symlink()) and not target.is_dir():
            raise NotADirectoryError(errno.ENOTDIR, "Not a directory")
        if _is_mount(target):
            _probe_inside(target)
            return target
        if Path.cwd().resolve().is_relative_to(target.resolve()):
            raise OutputError(
                f"cannot write {str(target)!r}: it is the working directory or holds it; the output folder is swapped "
                "for a new one when the run ends (its other files are kept), which would pull it from under the "
                "shell: run from another folder or name another for the output"
            )
        target.parent.mkdir(parents=True, exist_ok=True)
        _temporary(target, directory=True).rmdir()
    for name in names:
        with output_errors(target / name):
            if (target / name).is_dir():
                raise IsADirectoryError(errno.EISDIR, "Is a directory")
    return target


@contextlib.contextmanager
def staged_directory(target: str | Path, names=(), replaces=()) -> Iterator[Path]:
    """Yield an empty staging folder; on success it replaces the folder ``target`` as a whole.

    The files already in ``target`` that the run does not write are kept (but those
    named in ``replaces``, earlier outputs of the same kind, go): they are
    hard-linked into the staging folder (copied where the file system cannot link), and
    the staging folder then takes the place of ``target``: in one step where Linux's
    ``renameat2`` exchanges them, else by renames (the old folder moved aside, the new one
    in, the old one removed; put back if the new one cannot go in). So ``target`` holds
    the old set of files or the new one, never a mix: an interruption, a full disk or a
    blocked name before the renames leaves it as it was. The other files are linked anew on
    every write: cheap for a folder of figures, not for one that also holds a large store.
    A mount point (a container's bind mount) cannot be replaced: there the staging
    folder is inside ``target`` and its files land one by one at the end, each by an
    atomic rename; then the files of ``replaces`` that the run did not write are removed.

    Parameters
    ----------
    target : str or Path
        The output folder (created if missing).
    names : iterable of str
        The files the run will write, checked first (:func:`check_folder`).
    replaces : iterable of str
        Files that the new output replaces as a set: not kept where the run does not
        write them (e.g. a Bode plot of an earlier run, beside a new response plot).

    Yields
    ------
    Path
        The empty staging folder, beside ``target`` (inside a mount point); write the outputs into it.

    Raises
    ------
    OutputError
        ``target`` cannot take the output (:func:`check_folder`), or a file written is a
        folder in ``target`` (or the other way round), or the folders cannot be written.
    """
    target = Path(os.path.realpath(check_folder(target, names)))  # a link to a folder: replace the folder
    if _is_mount(target):
        with _filled_in_place(target, set(replaces)) as stage:
            yield stage
        return
    with output_errors(target):
        stage = _temporary(target, directory=True)
    try:
        yield stage
        with output_errors(target):
            if target.is_dir():
                _keep_the_others(target, stage, set(replaces))
            _set_mode(stage, target, directory=True)
            _replace(stage, target, directory=True)
    finally:
        shutil.rmtree(stage, ignore_errors=True)


def _keep_the_others(target: Path, stage: Path, replaced: set[str]) -> None:
    """Hard-link (or copy) into ``stage`` every entry of ``target`` that the run did not write, but ``replaced``."""
    for item in target.iterdir():
        new = stage / item.name
        if item.name in replaced and not (new.exists() or new.is_symlink()):
            continue
        if new.exists() or new.is_symlink():
            if new.is_dir() != item.is_dir():
                kind = "a folder" if item.is_dir() else "a file"
                raise OutputError(f"cannot write {str(item)!r}: {kind} of that name is in the way")
            continue
        if item.is_dir() and not item.is_symlink():
            shutil.copytree(item, new, symlinks=True, copy_function=_link_or_copy)
        else:
            _link_or_copy(item, new)


def _link_or_copy(source, destination) -> None:
    if os.path.islink(source):
        os.symlink(os.readlink(source), destination)
        return
    try:
        os.link(source, destination)
    except OSError:  # no hard links on this file system
        shutil.copy2(source, destination)


def _is_mount(target: Path) -> bool:
    """A folder that is a mount point (e.g. a container's bind mount): it cannot be renamed or replaced."""
    return target.is_dir() and os.path.ismount(target)


def _probe_inside(target: Path) -> None:
    """Make a staging folder inside ``target`` and move a file from it into ``target``, as the end of a job will."""
    stage = Path(tempfile.mkdtemp(prefix=f".{target.name}.", suffix=".tmp", dir=target))
    try:
        probe = stage / "probe"
        probe.touch()
        landed = target / f".{stage.name}.probe"
        os.replace(probe, landed)
        landed.unlink()
    finally:
        shutil.rmtree(stage, ignore_errors=True)


@contextlib.contextmanager
def _filled_in_place(target: Path, replaced: set[str]) -> Iterator[Path]:
    """Stage inside a mount point and move each file into it at the end.

    A mount point cannot be replaced as a whole, and renames from its parent's file
    system fail (EXDEV); the files then land one by one, each by an atomic rename, all
    after the job has finished, and the files already there that the job does not
    write are kept, but those ``replaced`` (removed last).
    """
    with output_errors(target):
        stage = Path(tempfile.mkdtemp(prefix=f".{target.name}.", suffix=".tmp", dir=target))
    try:
        yield stage
        with output_errors(target):
            written = set()
            for item in sorted(stage.iterdir()):
                _set_mode(item, target / item.name, item.is_dir())
                os.replace(item, target / item.name)
                written.add(item.name)
            for name in sorted(replaced - written):
                with contextlib.suppress(FileNotFoundError, IsADirectoryError):
                    (target / name).unlink()
    finally:
        shutil.rmtree(stage, ignore_errors=True)
