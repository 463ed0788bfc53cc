"""Atomic output: write to a temporary name beside the target, then rename.

An interrupted run leaves either the previous file or the new one, never a
half-written file; a power cut too: the new file (a folder: every file in it, and
itself) is written to disk (``fsync``) before the rename, its folder after it. A
folder replaces a folder in one step where the OS can (Linux's ``renameat2`` with
``RENAME_EXCHANGE``), else in two (the old one moved aside, the new one in), so
that a set of files changes as a whole.

The folder swap moves only what it can move back and remove. Before it, the old
folder is read whole (:func:`~spinectl._folder_swap.inventory`): a mount point inside it (another
device, or one of the system's table of mounts: a rename would carry the
mounted file system into the hidden old folder, whose removal would empty it), an
immutable or append-only entry (``chattr +i``: it could be swapped away but never
removed) or a folder whose entries this user cannot remove is refused with one line,
before anything moves. After the swap the old folder is removed entry by entry
(:func:`~spinectl._folder_swap.settle`), never as a tree: an entry goes only if it was there when the run
read the folder (it was kept in the new folder, or replaced by this run's file) or
is a hard link to the entry of the new folder; an entry that another process wrote
during the swap is moved back into the new folder, and one that cannot be (the
run wrote that name too) is kept in a visible folder beside, with a warning.

Every temporary is named ``.<target>.~<pid>-<start>-<host>~<random>.tmp``: the
process id, its start time (``/proc/<pid>/stat`` field 22, clock ticks after boot;
0 where there is no ``/proc``) and a hash of the host name (:class:`Owner`). A run
removes the temporaries beside its output whose process has ended (a SIGKILL's
litter; :func:`remove_stale`): a process id that runs again with another start
time is another process; one of another host is never judged.

The operating system's own calls (``renameat2``, ``fsync``, file attributes, the table of
mounts, process start times) are in :mod:`spinectl._oscalls`.
"""

from __future__ import annotations

import contextlib
import dataclasses
import errno
import functools
import os
import re
import shutil
import socket
import tempfile
import zlib
from collections.abc import Iterator
from pathlib import Path

from ._folder_swap import OutputWarning, check_removable, inventory, settle  # noqa: F401 (OutputWarning public here)
from ._oscalls import FS_IOC_GETFLAGS, PINNED_FLAGS, RENAME_EXCHANGE, RENAME_NOREPLACE  # noqa: F401 (public here)
from ._oscalls import check_way as _check_way
from ._oscalls import exchange as _exchange
from ._oscalls import start_time as _start_time
from ._oscalls import synced as _synced
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
        made = _make_folder(target.parent)
        try:
            tmp = _temporary(target, directory)
        except BaseException:
            _remove_made(made)
            raise
    try:
        with output_errors(target, errnos=DEVICE_ERRORS):  # the writer meets a full disk
            yield tmp
        with output_errors(target):
            _set_mode(tmp, target, directory)
            # an old folder: refused if a swap could not move or remove it all, before anything moves
            seen = inventory(target) if directory and target.is_dir() else {}
            written = frozenset(os.listdir(tmp)) if directory else frozenset()
            _synced(tmp)
            old = _swap(tmp, target, directory)
    except BaseException:
        if tmp.is_dir():
            shutil.rmtree(tmp, ignore_errors=True)
        else:
            tmp.unlink(missing_ok=True)
        _remove_made(made)  # nothing written: not even the folders made for it
        raise
    if old is not None:  # the old folder, now at the temporary's name: only what was read goes
        settle(old, target, seen, written)
    with output_errors(target):
        _synced(target.parent, tree=False)  # the rename itself (after the swap: a failure must not undo it)


def _named(target: str | Path, resolve: bool = True) -> Path:
    """``target`` as a Path (``resolve``: a symbolic link as the file it leads to, which is written), or
    :class:`OutputError` if its name has a line break or control character, or its path cannot lead to it.

    Such a name is valid on POSIX, but it breaks the one-line listings and messages
    that name the outputs, and the command line that a preset's header records.
    """
    text = str(target)
    if not _as_utf8(text).isprintable():
        raise OutputError(f"cannot write {show(text)}: the name must be printable (no line breaks or control codes)")
    path = Path(target)
    _check_way(path)
    return Path(os.path.realpath(path)) if resolve and path.is_symlink() else path


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


FULL_BELOW = 1 << 20
"""Free bytes below which a library's failed write names the full disk [B]: netCDF-C and OpenSim report it
in their own words, without the error number."""


def full_disk_note(target: str | Path) -> str:
    """``'; No space left on device'`` if the file system of ``target`` has (almost) no space left, else ``''``.

    Parameters
    ----------
    target : str or Path
        An output whose writer (a library that hides the error number) failed.

    Returns
    -------
    str
    """
    try:
        stats = os.statvfs(Path(target).resolve().parent)
    except OSError:
        return ""
    return "; No space left on device" if stats.f_bavail * stats.f_frsize < FULL_BELOW else ""


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


def _missing_folders(folder: Path) -> list[Path]:
    """``folder`` and its parents that do not exist yet, deepest first (the nearest that exists is the last's
    parent)."""
    missing = []
    while not folder.exists() and folder != folder.parent:
        missing.append(folder)
        folder = folder.parent
    return missing


def _make_folder(folder: Path) -> list[Path]:
    """Make ``folder`` and its missing parents; return those made, deepest first (for :func:`_remove_made`)."""
    made = _missing_folders(folder)
    folder.mkdir(parents=True, exist_ok=True)
    return made


def _remove_made(made: list[Path]) -> None:
    """Remove the folders :func:`_make_folder` made, deepest first, while they are empty."""
    for folder in made:
        try:
            folder.rmdir()
        except OSError:  # another writer's file in it meanwhile: it stays
            return


def _in_nearest_folder(target: Path) -> Path:
    """``target``'s name in the nearest folder that exists on its way: where a check can probe writing without
    making the folders a write would make (an export refused after its check left an empty folder)."""
    missing = _missing_folders(target.parent)
    folder = missing[-1].parent if missing else target.parent
    if not folder.is_dir():
        raise NotADirectoryError(errno.ENOTDIR, f"{str(folder)!r} is not a folder")
    return folder / target.name


def _temporary(target: Path, directory: bool) -> Path:
    """A new temporary beside ``target``, named after it and after this process (:class:`Owner`)."""
    remove_stale(target.parent)
    marker = f".~{Owner.me().token()}~"
    tail = ".tmp" + (target.suffix if not directory else "")
    room = NAME_MAX - len(os.fsencode(marker + tail)) - 8 - 1  # 8: mkstemp's random part; 1: the leading dot
    # a long name: its first bytes, decoded as the file system encodes (under a C locale a UTF-8 name is held
    # as surrogate escapes, which only os.fsdecode gives back; a cut character round-trips the same way)
    name = os.fsdecode(os.fsencode(target.name)[: max(room, 1)]) or "out"
    prefix = f".{name}{marker}"
    if directory:
        return Path(tempfile.mkdtemp(prefix=prefix, suffix=tail, dir=target.parent))
    fd, path = tempfile.mkstemp(prefix=prefix, suffix=tail, dir=target.parent)
    os.close(fd)
    return Path(path)


def temporary_beside(target: str | Path) -> Path:
    """A new empty file beside ``target``, named as the temporaries of :func:`atomic_path` are.

    For a writer that puts it in place itself (e.g. by a hard link); if the run is killed,
    a later run removes it (:func:`remove_stale`).

    Parameters
    ----------
    target : str or Path
        The file it stands for.

    Returns
    -------
    Path
        The temporary (the caller removes it).
    """
    return _temporary(Path(target), directory=False)


NAME_MAX = 255
"""The longest file name of the usual file systems [bytes]."""


@dataclasses.dataclass(frozen=True)
class Owner:
    """A process that writes: its id, start time and host (that of a temporary, or a lock's holder).

    Parameters
    ----------
    pid : int
        Process id.
    start : int
        Its start time: clock ticks after boot (``/proc/<pid>/stat`` field 22), 0 where unknown
        (no ``/proc``, or a lock written by an older version).
    host : str
        Host name, or the 8 hex digits of its CRC-32 (as a temporary's name holds it).
    """

    pid: int
    start: int
    host: str

    @classmethod
    def me(cls) -> Owner:
        """This process.

        Returns
        -------
        Owner
        """
        return cls(os.getpid(), _start_time(os.getpid()) or 0, socket.gethostname())

    def token(self) -> str:
        """``<pid>-<start>-<crc32 of host>``, the part of a temporary's name that names its owner.

        Returns
        -------
        str
        """
        return f"{self.pid}-{self.start}-{_host_hash(self.host)}"

    def gone(self) -> bool:
        """Whether this process has ended: its id runs no more, or runs another process (another start time).

        A process of another host is never gone (it cannot be checked from here); one whose
        start time is unknown is gone only once its id runs no more.

        Returns
        -------
        bool
        """
        if self.host not in (socket.gethostname(), _host_hash(socket.gethostname())):
            return False
        try:
            os.kill(self.pid, 0)
        except ProcessLookupError:
            return True
        except PermissionError:  # runs, as another user: compare its start time below
            pass
        now = _start_time(self.pid)
        return bool(self.start) and now is not None and now != self.start


def _host_hash(host: str) -> str:
    return f"{zlib.crc32(host.encode()):08x}"


TEMPORARY = re.compile(r"\..*\.~(\d+)-(\d+)-([0-9a-f]{8})~.{8}\.tmp.*", re.DOTALL)
"""The name of a temporary of :func:`_temporary` (its owner's pid, start time and host hash)."""


def remove_stale(folder: str | Path) -> list[Path]:
    """Remove the temporaries in ``folder`` of runs that have ended (e.g. killed by SIGKILL).

    Only names of :func:`_temporary` count, and only those whose owner is gone
    (:meth:`Owner.gone`); a folder goes only if nothing in it lies on another file
    system or is pinned (:func:`~spinectl._folder_swap.inventory`). Best effort: what cannot be removed stays.

    Parameters
    ----------
    folder : str or Path
        Where to look (not below).

    Returns
    -------
    list of Path
        The temporaries removed.
    """
    removed = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    for entry in entries:
        match = TEMPORARY.fullmatch(entry.name)
        if match is None or not Owner(int(match[1]), int(match[2]), match[3]).gone():
            continue
        with contextlib.suppress(OSError, OutputError):
            if entry.is_dir(follow_symlinks=False):
                inventory(Path(entry.path))  # nothing mounted or pinned inside
                shutil.rmtree(entry.path)
            else:
                os.unlink(entry.path)
            removed.append(Path(entry.path))
    return removed


def _set_mode(tmp: Path, target: Path, directory: bool) -> None:
    """Give ``tmp`` the mode of the output it replaces, or the umask's default (mkstemp makes 0600)."""
    if target.exists():
        mode = target.stat().st_mode
    else:
        umask = os.umask(0)  # the only way to read it; restored at once (sweeps use processes, not threads)
        os.umask(umask)
        mode = (0o777 if directory else 0o666) & ~umask
    os.chmod(tmp, mode & 0o7777)


def _swap(tmp: Path, target: Path, directory: bool) -> Path | None:
    """Put ``tmp`` in the place of ``target``; return where the old folder went (None: no old folder).

    The old folder is not removed here: :func:`~spinectl._folder_swap.settle` removes what the run read of it.
    """
    if not (directory and target.exists()):
        os.replace(tmp, target)
        return None
    if _exchange(tmp, target):  # one step: the new folder at target, the old one at tmp
        return tmp
    # A folder cannot be renamed over a non-empty one: move the old aside first (onto an
    # empty temporary: a rename may replace an empty folder), and put it back if the new
    # one cannot take its place.
    old = _temporary(target, directory=True)
    os.replace(target, old)
    try:
        os.replace(tmp, target)
    except BaseException:
        os.replace(old, target)
        raise
    return old


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
        _temporary(_in_nearest_folder(target), directory=False).unlink()  # makes no folder: a check writes nothing
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
        replaced as a whole), holds what a swap cannot move or remove (a mount point, an
        immutable or append-only entry, a folder whose entries cannot be removed), one of
        ``names`` is a folder in it, or its folder cannot be created or written.
    """
    target = _named(target, resolve=False)  # a link to a folder: the folder is replaced (staged_directory)
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
        _temporary(_in_nearest_folder(target), directory=True).rmdir()
        if target.is_dir():
            inventory(target)  # a mount point or a pinned file inside: refused before the work
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
        made = _make_folder(target.parent)
        try:
            stage = _temporary(target, directory=True)
        except BaseException:
            _remove_made(made)
            raise
    old = None
    try:
        yield stage
        with output_errors(target):
            written = frozenset(os.listdir(stage))
            seen = _keep_the_others(target, stage, set(replaces)) if target.is_dir() else {}
            _set_mode(stage, target, directory=True)
            _synced(stage)
            old = _swap(stage, target, directory=True)
    finally:
        if old is None:  # not swapped: the staging folder holds this run's files and links only
            shutil.rmtree(stage, ignore_errors=True)
            _remove_made(made)
    if old is not None:
        settle(old, target, seen, written)
    with output_errors(target):
        _synced(target.parent, tree=False)  # the rename itself


def _keep_the_others(target: Path, stage: Path, replaced: set[str]) -> dict[str, tuple]:
    """Hard-link (or copy) into ``stage`` every entry of ``target`` that the run did not write, but ``replaced``.

    Returns the :func:`~spinectl._folder_swap.inventory` of ``target`` read before (what the swap may remove).
    """
    seen = inventory(target, files=False)  # the files kept are checked by their link (below)
    link = functools.partial(_link_or_copy, root=target)
    for item in target.iterdir():
        new = stage / item.name
        if (item.name in replaced and not (new.exists() or new.is_symlink())) or new.exists() or new.is_symlink():
            if (new.exists() or new.is_symlink()) and new.is_dir() != item.is_dir():
                kind = "a folder" if item.is_dir() else "a file"
                raise OutputError(f"cannot write {str(item)!r}: {kind} of that name is in the way")
            if item.is_dir() and not item.is_symlink():
                inventory(item)  # not linked: its files are checked here
            else:
                check_removable(item, os.lstat(item), target)
            continue
        if item.is_dir() and not item.is_symlink():
            shutil.copytree(item, new, symlinks=True, copy_function=link)
        else:
            link(item, new)
    return seen


def _link_or_copy(source, destination, root: Path | None = None) -> None:
    """Hard-link ``source`` as ``destination`` (a symbolic link as itself), or copy it where links fail.

    Linux refuses to link an immutable or append-only file (EPERM): that is an
    :class:`OutputError` (via :func:`check_removable`), since the swap could not remove it.
    """
    if os.path.islink(source):
        os.symlink(os.readlink(source), destination)
        return
    try:
        os.link(source, destination)
    except OSError as exc:  # no hard links on this file system, or a file that may not be linked
        if exc.errno == errno.EPERM and root is not None:
            check_removable(Path(source), os.lstat(source), root)
        shutil.copy2(source, destination)


def _is_mount(target: Path) -> bool:
    """A folder that is a mount point (e.g. a container's bind mount): it cannot be renamed or replaced."""
    return target.is_dir() and os.path.ismount(target)


def _probe_inside(target: Path) -> None:
    """Make a staging folder inside ``target`` and move a file from it into ``target``, as the end of a job will."""
    stage = _temporary(target / target.name, directory=True)  # inside target, named after it
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
        stage = _temporary(target / target.name, directory=True)  # inside target, named after it
    try:
        yield stage
        with output_errors(target):
            written = set()
            for item in sorted(stage.iterdir()):
                _set_mode(item, target / item.name, item.is_dir())
                _synced(item)
                os.replace(item, target / item.name)
                written.add(item.name)
            _synced(target, tree=False)
            for name in sorted(replaced - written):
                with contextlib.suppress(FileNotFoundError, IsADirectoryError):
                    (target / name).unlink()
    finally:
        shutil.rmtree(stage, ignore_errors=True)
