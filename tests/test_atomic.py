"""``spinectl.atomic``: the folder swap moves only what it can move back and remove; temporaries of dead runs go.

The mounts and file attributes are real (tmpfs, a bind mount, ``chattr +i``): those
tests need root and skip, saying why, where the machine does not allow them.
"""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

from spinectl import atomic
from spinectl.atomic import Owner, atomic_path, atomic_write_text, staged_directory
from spinectl.errors import OutputError


def _run(*argv) -> bool:
    """Run a system command quietly; whether it worked."""
    if shutil.which(argv[0]) is None:
        return False
    return subprocess.run(argv, capture_output=True).returncode == 0


@pytest.fixture
def mounted(tmp_path):
    """A folder ``out`` holding ``notes.txt`` and a tmpfs mounted at ``out/archive`` with one file."""
    out = tmp_path / "out"
    (out / "archive").mkdir(parents=True)
    (out / "notes.txt").write_text("mine")
    if not _run("mount", "-t", "tmpfs", "tmpfs", str(out / "archive")):
        pytest.skip("cannot mount a tmpfs here (needs root, or a container allowing mounts)")
    (out / "archive" / "data.txt").write_text("archived")
    yield out
    _run("umount", str(out / "archive"))


@pytest.fixture
def pinned(tmp_path):
    """A folder ``out`` holding ``notes.txt`` and an immutable ``pinned.txt`` (``chattr +i``)."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    (out / "pinned.txt").write_text("cannot go")
    if not _run("chattr", "+i", str(out / "pinned.txt")):
        pytest.skip("cannot set the immutable attribute here (needs root and a file system with attributes)")
    yield out
    _run("chattr", "-i", str(out / "pinned.txt"))


def _write(out: Path) -> None:
    with staged_directory(out, ["fig.png"]) as stage:
        (stage / "fig.png").write_text("new")


def _replace_whole(out: Path) -> None:
    with atomic_path(out, directory=True) as tmp:
        (tmp / "chunk").write_text("new")


def test_a_mount_point_inside_the_output_folder_is_refused_and_kept(mounted):
    """A tmpfs mounted inside the output folder: one OutputError naming it, before anything moves; the
    mounted files stay where they were (before: the mount was swapped into the hidden old folder, whose
    removal emptied it)."""
    for write in (_write, _replace_whole):
        with pytest.raises(OutputError, match="'archive' in it is a mount point") as info:
            write(mounted)
        assert len(str(info.value).splitlines()) == 1
        assert (mounted / "archive" / "data.txt").read_text() == "archived" and os.path.ismount(mounted / "archive")
        assert sorted(p.name for p in mounted.parent.iterdir()) == ["out"]


def test_a_bind_mount_on_the_same_device_is_refused(tmp_path):
    """A bind mount has the device of its parent: it is found in the table of mounts, not by st_dev."""
    out, elsewhere = tmp_path / "out", tmp_path / "elsewhere"
    (out / "bound").mkdir(parents=True)
    elsewhere.mkdir()
    (elsewhere / "data.txt").write_text("bound")
    if not _run("mount", "--bind", str(elsewhere), str(out / "bound")):
        pytest.skip("cannot bind-mount here (needs root, or a container allowing mounts)")
    try:
        with pytest.raises(OutputError, match="'bound' in it is a mount point"):
            _write(out)
        assert (elsewhere / "data.txt").read_text() == "bound"
    finally:
        _run("umount", str(out / "bound"))


def test_an_immutable_file_in_the_output_folder_is_refused_and_kept(pinned):
    """``chattr +i`` on a file of the output folder: refused in one line naming it, the file where it was
    (before: it was swapped into the hidden old folder, which then could not be removed)."""
    with pytest.raises(OutputError, match="'pinned.txt' in it is immutable") as info:
        _write(pinned)
    assert len(str(info.value).splitlines()) == 1
    assert sorted(p.name for p in pinned.iterdir()) == ["notes.txt", "pinned.txt"]
    assert sorted(p.name for p in pinned.parent.iterdir()) == ["out"]


def test_a_file_made_immutable_during_the_run_is_refused_at_the_swap(tmp_path):
    """``chattr +i`` after the run checked its folder, while it writes: the swap refuses it (Linux will not
    hard-link such a file), and the folder is as it was, with no staging folder left."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    try:
        with pytest.raises(OutputError, match="'notes.txt' in it is immutable"):
            with staged_directory(out, ["fig.png"]) as stage:
                (stage / "fig.png").write_text("new")
                if not _run("chattr", "+i", str(out / "notes.txt")):
                    pytest.skip(
                        "cannot set the immutable attribute here (needs root and a file system with attributes)"
                    )
        assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]
        assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]
    finally:
        _run("chattr", "-i", str(out / "notes.txt"))


def _writing_during_the_swap(monkeypatch, before=None, after=None):
    """Wrap ``atomic._swap``: another process's writes, as files ``before`` into the folder just before the
    swap and ``after`` into the old folder just after it (a writer that looked up the folder before)."""
    swap = atomic._swap

    def racing(tmp, target, directory):
        for name, text in (before or {}).items():
            (target / name).write_text(text)
        old = swap(tmp, target, directory)
        for name, text in (after or {}).items():
            (old / name).write_text(text)
        return old

    monkeypatch.setattr(atomic, "_swap", racing)


def test_files_written_into_the_folder_during_the_swap_are_kept(tmp_path, monkeypatch):
    """Files another process writes into the output folder after it was read (before: lost with the old
    folder, 2 of 600 in a race), a new version of a kept file, and a file in a kept subfolder all end up
    in the new folder; the run's own file is the run's."""
    out = tmp_path / "out"
    (out / "sub").mkdir(parents=True)
    (out / "notes.txt").write_text("old notes")
    (out / "fig.png").write_text("old figure")
    _writing_during_the_swap(monkeypatch, before={"early.txt": "e"}, after={"late.txt": "l", "notes.txt": "newer"})
    _write(out)
    assert {p.name: p.read_text() for p in out.iterdir() if p.is_file()} == {
        "fig.png": "new",
        "notes.txt": "newer",
        "early.txt": "e",
        "late.txt": "l",
    }
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_a_file_of_the_run_s_name_written_during_the_swap_is_kept_aside(tmp_path, monkeypatch):
    """Another process writes ``fig.png`` into the old folder after the swap: the run's file stays, the
    other is kept in a visible folder beside, with a warning naming it (nothing is deleted)."""
    out = tmp_path / "out"
    out.mkdir()
    _writing_during_the_swap(monkeypatch, after={"fig.png": "theirs"})
    with pytest.warns(atomic.OutputWarning, match="1 file\\(s\\) written into .* kept in") as record:
        _write(out)
    assert (out / "fig.png").read_text() == "new"
    kept = [p for p in tmp_path.iterdir() if p.name != "out"]
    assert len(kept) == 1 and kept[0].name.startswith("out.kept-") and str(kept[0]) in str(record[0].message)
    assert (kept[0] / "fig.png").read_text() == "theirs"


def test_a_whole_folder_replacement_keeps_what_came_meanwhile(tmp_path, monkeypatch):
    """``atomic_path(directory=True)`` (a study store): the old folder's files go, one written into the
    old folder after the swap moves into the new one."""
    out = tmp_path / "s.zarr"
    out.mkdir()
    (out / "old_chunk").write_text("old")
    _writing_during_the_swap(monkeypatch, after={"late.txt": "l"})
    with atomic_path(out, directory=True) as tmp:
        (tmp / "chunk").write_text("new")
    assert sorted(p.name for p in out.iterdir()) == ["chunk", "late.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.zarr"]


def test_a_real_concurrent_writer_loses_no_file(tmp_path):
    """A thread writes 300 files into the folder while it is swapped again and again: all 300 are there at
    the end (before: some were lost with the old folder; this is the race, not a timing claim)."""
    import threading

    out = tmp_path / "out"
    out.mkdir()
    names, done = [], threading.Event()

    def writer():
        for i in range(300):
            (out / f"other{i}.txt").write_text("x")
            names.append(f"other{i}.txt")
        done.set()

    thread = threading.Thread(target=writer)
    thread.start()
    while not done.is_set():
        _write(out)
    thread.join()
    assert set(names) <= {p.name for p in out.iterdir()} and len(names) == 300


def _dead() -> Owner:
    """An Owner of this host whose process has ended (its pid free; reuse within the test is unlikely)."""
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return Owner(child.pid, 1, socket.gethostname())


def test_an_owner_is_gone_when_its_pid_runs_another_process():
    """This process is not gone; the same pid with another start time is another process (a pid reused);
    an ended pid is gone; one of another host is never judged gone."""
    me = Owner.me()
    assert not me.gone()
    if me.start:  # /proc: the start time is known
        assert Owner(me.pid, me.start + 1, me.host).gone()
    assert _dead().gone()
    assert not Owner(_dead().pid, 1, "another-host.invalid").gone()


def _litter(folder: Path, owner: Owner, name: str, directory: bool) -> Path:
    path = folder / f".{name}.~{owner.token()}~abcdefgh.tmp"
    if directory:
        (path / "big").mkdir(parents=True)
        (path / "big" / "chunk").write_bytes(b"0" * 100)
    else:
        path.write_bytes(b"half")
    return path


def test_temporaries_of_dead_runs_are_removed_by_the_next_write(tmp_path):
    """The next write beside them removes the temporaries of runs that ended (a folder and a file), and
    keeps those of this live process, of another host, and any file not named as a temporary."""
    dead, me = _dead(), Owner.me()
    stale = [_litter(tmp_path, dead, "out", True), _litter(tmp_path, dead, "x.nc", False)]
    kept = [
        _litter(tmp_path, me, "live", True),
        _litter(tmp_path, Owner(dead.pid, 1, "another-host.invalid"), "far", False),
        tmp_path / ".out.mine.tmp",
    ]
    kept[-1].write_text("not ours")
    atomic_write_text(tmp_path / "y.json", "{}")
    assert not any(p.exists() for p in stale) and all(p.exists() for p in kept)


def test_a_killed_run_s_staging_folder_is_removed_by_the_next_run(tmp_path):
    """A run SIGKILLed while its staging folder is full leaves it (hidden, beside the output); the next run
    into that folder removes it."""
    out = tmp_path / "out"
    code = (
        "import os, signal, sys\n"
        "from spinectl.atomic import staged_directory\n"
        "with staged_directory(sys.argv[1], ['fig.png']) as stage:\n"
        "    (stage / 'fig.png').write_bytes(b'0' * 100000)\n"
        "    os.kill(os.getpid(), signal.SIGKILL)\n"
    )
    env = {**os.environ, "PYTHONPATH": str(Path(atomic.__file__).parents[1])}
    killed = subprocess.run([sys.executable, "-c", code, str(out)], env=env)
    assert killed.returncode == -signal.SIGKILL
    litter = [p for p in tmp_path.iterdir() if p.name != "out"]
    assert len(litter) == 1 and atomic.TEMPORARY.fullmatch(litter[0].name)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _write(out)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def _recording_syncs_and_renames(monkeypatch) -> list[tuple]:
    """Record, in order, every ``os.fsync`` (as the path of its file descriptor) and every rename of
    ``atomic`` (``os.replace``, and ``renameat2`` through ``atomic._exchange``), as ``(what, path...)``."""
    if not os.path.isdir("/proc/self/fd"):
        pytest.skip("needs /proc/self/fd to name the file a descriptor is open on (Linux)")
    events: list[tuple] = []
    fsync, replace, exchange = os.fsync, os.replace, atomic._exchange

    def recorded_fsync(fd):
        events.append(("fsync", os.readlink(f"/proc/self/fd/{fd}")))
        return fsync(fd)

    def recorded_replace(a, b, *args, **kwargs):
        events.append(("rename", os.fspath(a), os.fspath(b)))
        return replace(a, b, *args, **kwargs)

    def recorded_exchange(a, b, *args):
        done = exchange(a, b, *args)
        if done:
            events.append(("rename", os.fspath(a), os.fspath(b)))
        return done

    monkeypatch.setattr(os, "fsync", recorded_fsync)
    monkeypatch.setattr(os, "replace", recorded_replace)
    monkeypatch.setattr(atomic, "_exchange", recorded_exchange)
    return events


def test_a_file_is_on_disk_before_its_rename_and_the_rename_after(tmp_path, monkeypatch):
    """A file write: the temporary's descriptor is fsynced, then it is renamed onto the target, then the
    folder holding the new name is fsynced, so that a power cut leaves the old file or the whole new
    one (before: no fsync at all, a rename could reach the disk before the bytes it names)."""
    events = _recording_syncs_and_renames(monkeypatch)
    target = tmp_path / "x.json"
    target.write_text("old")
    with atomic_path(target) as tmp:
        tmp.write_text("new")
    assert events == [("fsync", str(tmp)), ("rename", str(tmp), str(target)), ("fsync", str(tmp_path))]
    assert target.read_text() == "new"


@pytest.mark.parametrize("exchange", [True, False], ids=["renameat2", "two renames"])
@pytest.mark.parametrize("writer", ["atomic_path", "staged_directory"])
def test_a_folder_and_its_files_are_on_disk_before_the_swap(tmp_path, monkeypatch, exchange, writer):
    """A folder swap (a study store, a folder of figures), in one step or in two: every file written and
    the new folder itself are fsynced before the rename that swaps it in, and the folder holding it after."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("old")
    if not exchange:  # no renameat2 here: the old folder is moved aside, the new one in
        real = atomic._exchange
        refused = atomic.RENAME_EXCHANGE
        monkeypatch.setattr(atomic, "_exchange", lambda a, b, flags=refused: flags != refused and real(a, b, flags))
    events = _recording_syncs_and_renames(monkeypatch)
    writing = atomic_path(out, directory=True) if writer == "atomic_path" else staged_directory(out, ["fig.png"])
    with writing as tmp:
        (tmp / "sub").mkdir()
        (tmp / "sub" / "fig.png").write_text("new")
    swap = next(i for i, e in enumerate(events) if e[0] == "rename" and e[1:] == (str(tmp), str(out)))
    synced = [e[1] for e in events[:swap] if e[0] == "fsync"]
    assert synced.index(str(tmp / "sub" / "fig.png")) < synced.index(str(tmp / "sub")) < synced.index(str(tmp))
    assert ("fsync", str(tmp_path)) in events[swap + 1 :]
    assert (out / "sub" / "fig.png").read_text() == "new"
