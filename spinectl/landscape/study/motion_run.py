"""Running a study of motions (:mod:`.motion_spec`) on the study engine's executor, into a resumable store.

Each chunk is a trial's range of frames, solved by :func:`spinectl.anatomy.motion.motion_response` with that
range (``frames``), so a chunk's numbers are those of the trial run alone, bit for bit. The executor, the
store's lock, the progress bar, the resume rules and the closing line are the parameter study's
(:mod:`.executor`, :func:`.store.locked`, :func:`.run.describe`).

The store (a folder, made atomically) holds ``motion_study.json`` (the study's digest and file) and
``chunks/<index>.nc``, each chunk's Dataset as a NetCDF file with its checksums
(:func:`spinectl.landscape.netcdf.save`, written to a temporary name and renamed): a chunk is done when its
file is there and its checksums hold, so a killed run leaves whole chunks or none, and a resume computes only
the others. Once every chunk of a trial is done, the trial's Dataset (its chunks along ``time``) is written
beside them as ``<trial>.nc``; :func:`load_motions` reads those back.

Who writes: the store is made by this process, at the first chunk that finishes (a model that does not
load leaves no store). Where the workers share this machine's files (a local cluster, or in-process), a
worker then writes its chunk's file itself, the same way, and a trial's file is assembled by a worker as
soon as the trial's chunks are all done (:class:`TrialTask`), while the others are computed; the worker reads
its file back (its checksums) and sends the CRC-32 of its bytes, and this process counts the chunk done once
the file holds those bytes. The NetCDF encoding (a tenth of a second a chunk)
is then spread over the workers instead of queued in this one, which also shares their cores. An existing
cluster's workers (``--scheduler``) may not see the store: they return each chunk's Dataset, which this
process writes, and it assembles the trials at the end.

A worker loads each model once (:func:`_anatomy`, a cache per process): loading MyoTorso or an ``.osim`` takes
seconds, a chunk of frames less.
"""

from __future__ import annotations

import functools
import json
import os
import time
import zlib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from ..._threads import with_one_blas_thread
from ...atomic import atomic_path
from ...errors import ParameterError
from .. import netcdf
from . import store
from .executor import CONNECT_TIMEOUT, SYNCHRONOUS, WORKER_TIMEOUT, executor
from .interrupt import saved_on_interrupt
from .motion_spec import MOTION_FORMAT, MotionStudy
from .run import RESUME, StudyResult, check_run_options

MANIFEST = "motion_study.json"
"""The store's description: format, the study's digest and file."""

CHUNKS = "chunks"
"""The store's folder of chunk files."""


@dataclass(frozen=True)
class MotionTask:
    """What a worker needs for one chunk (no store, no study file).

    Attributes
    ----------
    index : int
        The chunk.
    model, mapping, coordinates, activations : str or None
        As the trial names them (absolute paths, or ``"myotorso"``).
    optimise, plane, joint_stiffness, least_stiffness :
        As :func:`spinectl.anatomy.motion.motion_response` takes them.
    frames : tuple of int
        ``(first, last, step)`` of the file's frames.
    trial : str
        The trial's name, for messages.
    store : str or None
        The store's folder (absolute), where the worker writes the chunk's file once the store exists
        (:func:`run_motion_task`); None: the Dataset is returned, for the caller to write.
    recordings : tuple
        The coordinates' and the activations' :class:`~spinectl.anatomy.recordings.Recording` as the study
        read them (:attr:`MotionStudy.recordings`), or None each: the worker reads the file.
    """

    index: int
    model: str
    mapping: str | None
    coordinates: str
    activations: str | None
    optimise: str
    frames: tuple
    plane: str
    joint_stiffness: object
    least_stiffness: float | None
    trial: str = ""
    store: str | None = None
    recordings: tuple = (None, None)


@dataclass(frozen=True)
class TrialTask:
    """A trial whose chunks are all done: its file ``<name>.nc`` to assemble from them in the store.

    Attributes
    ----------
    trial : int
        The trial's position in the study.
    name : str
        Its name (the file's).
    store : str
        The store's folder (absolute).
    chunks : tuple of int
        The trial's chunks, in the order of its frames.
    """

    trial: int
    name: str
    store: str
    chunks: tuple


@functools.lru_cache(maxsize=8)
def _anatomy(model: str, mapping: str | None):
    """The model, loaded once per process: every chunk of every trial of it on this worker shares it."""
    from ...anatomy import load

    return load(model, mapping)


@functools.lru_cache(maxsize=64)
def _recording(path: str, field: str):
    """A coordinates or activations file, read once per process."""
    from ...anatomy.recordings import read_recording

    return read_recording(path, field)


@with_one_blas_thread  # many small matrices per frame, as the CLI's commands; picklable by its module's name
def solve_motion_chunk(task: MotionTask) -> tuple:
    """One chunk: :func:`~spinectl.anatomy.motion.motion_response` on the trial's frames ``task.frames``.

    Parameters
    ----------
    task : MotionTask

    Returns
    -------
    index : int
        ``task.index``.
    dataset : xarray.Dataset
        The frames' Dataset, as ``motion_response`` gives it.
    """
    from ...anatomy.motion import motion_response

    try:
        anatomy = _anatomy(task.model, task.mapping)
    except ParameterError as exc:  # a model or mapping that does not load: say which trial's
        raise type(exc)(exc.field, f"{exc.message} (trial {task.trial!r})") from None
    # as the study read them (no OpenSim to import, no file to parse in the worker), else from the files
    posture, activations = task.recordings
    if posture is None:
        posture = _recording(task.coordinates, "posture")
    if activations is None and task.activations is not None:
        activations = _recording(task.activations, "activations")
    result = motion_response(
        anatomy,
        posture,
        activations,
        task.optimise,
        frames=task.frames,
        plane=task.plane,
        joint_stiffness=task.joint_stiffness,
        least_stiffness=task.least_stiffness,
        progress=False,
    )
    return task.index, result.dataset


def run_motion_task(task: MotionTask | TrialTask) -> tuple:
    """What a worker does with a task: a chunk solved (and written, where it can be), or a trial assembled.

    Parameters
    ----------
    task : MotionTask or TrialTask
        A chunk: solved by :func:`solve_motion_chunk`; its file written in ``task.store`` if that store
        exists (it is made by the run, at the first chunk). A trial: its file assembled from its chunks' files.

    Returns
    -------
    kind : str
        ``"chunk"`` or ``"trial"``.
    index : int
        The chunk's index, or the trial's position.
    dataset : xarray.Dataset or None
        A chunk's Dataset when it was not written (no store to write it in yet, or none given); else None.
    crc : int or None
        The CRC-32 of the chunk file's bytes, once written and its checksums checked (read back); else None.

    Raises
    ------
    OutputError
        A file of the store cannot be written (a full disk): the message names it.
    ParameterError
        As :func:`solve_motion_chunk`; a chunk file that fails its checksums once written, or when its trial
        is assembled.
    """
    if isinstance(task, TrialTask):
        _write_trial(Path(task.store), task.name, task.chunks)
        return "trial", task.trial, None, None
    index, dataset = solve_motion_chunk(task)
    if task.store is None or not (Path(task.store) / MANIFEST).is_file():
        return "chunk", index, dataset, None
    path = netcdf.save(dataset, _chunk_path(task.store, index))
    _check_written(path)  # read back as a resume reads it, here rather than in the run's one process
    return "chunk", index, None, zlib.crc32(path.read_bytes())


def motion_tasks(study: MotionStudy, indices, store: str | None = None):
    """The :class:`MotionTask` of each chunk in ``indices``, made when asked for.

    Parameters
    ----------
    study : MotionStudy
        The study.
    indices : iterable of int
        Chunk positions (0 <= index < ``study.n_chunks``).
    store : str or None
        The store's folder, for workers that write their chunk's file (:attr:`MotionTask.store`).

    Returns
    -------
    iterator of MotionTask
        One per index, in their order.
    """
    for index in indices:
        chunk = study.chunk(index)
        t = study.trials[chunk.trial]
        yield MotionTask(
            int(index),
            t.model,
            t.mapping,
            t.coordinates,
            t.activations,
            t.optimise,
            chunk.frames,
            t.plane,
            t.joint_stiffness,
            t.least_stiffness,
            t.name,
            store,
            (study.recordings.get((t.coordinates, "posture")), study.recordings.get((t.activations, "activations"))),
        )


def run_motion_study(
    study: MotionStudy,
    out: str | Path,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    resume: bool = False,
    max_chunks: int | None = None,
    progress: bool | None = None,
    connect_timeout: float = CONNECT_TIMEOUT,
    worker_timeout: float = WORKER_TIMEOUT,
    notify: Callable[[str], None] | None = None,
) -> StudyResult:
    """Run ``study`` into the store ``out``: every chunk not yet done, written as it finishes.

    The options are those of :func:`spinectl.landscape.study.run_study`, with the same meaning.

    Parameters
    ----------
    study : MotionStudy
    out : str or Path
        The store (a folder), created atomically; an existing one is refused unless ``resume``.
    scheduler, workers, connect_timeout, worker_timeout :
        Where the chunks run (:func:`spinectl.landscape.study.executor.executor`).
    resume : bool
        Continue the study in ``out``, computing only its missing (or damaged) chunks.
    max_chunks : int or None
        Stop after this many chunks (the store stays resumable).
    progress : bool or None
        A progress bar of chunks on stderr; None: on a terminal only.
    notify : callable or None
        Told lines for the user (chunks found damaged, a remote cluster's workers).

    Returns
    -------
    StudyResult

    Raises
    ------
    ParameterError
        Bad options, a store of another study, a frame a model cannot read (from its worker).
    OutputError
        ``out`` exists without ``resume``, or cannot be written.
    """
    timeouts = {"connect_timeout": connect_timeout, "worker_timeout": worker_timeout}
    check_run_options(scheduler, workers, max_chunks, **timeouts)
    start, notify = time.perf_counter(), notify or (lambda line: None)
    out = Path(out)
    with store.locked(out):
        done = _existing(study, out, resume, notify)
        todo = [i for i in range(study.n_chunks) if i not in done][: None if max_chunks is None else max_chunks]
        done_before = len(done)
        again = "the store holds every chunk finished; start a worker and run again with --resume"
        # the workers of a local cluster (or this process) see the store: they write its files themselves
        shared = None if scheduler not in (None, SYNCHRONOUS) else os.path.abspath(out)
        trials = _Trials(study, out, done)
        with executor(scheduler, workers, len(todo), **timeouts, notify=notify, again=again, name="motions") as where:
            key = _task_key(study)
            tasks = _with_trials(motion_tasks(study, todo, shared), trials, shared)
            _write_chunks(study, out, done, where.as_completed(run_motion_task, tasks, key=key), progress, trials)
            if shared is not None:  # the trials whose last chunk came last
                for _ in where.as_completed(run_motion_task, trials.tasks(shared), key=key):
                    pass
        if out.exists():
            _assemble(study, out, done)  # what the workers did not: every trial on an existing cluster
    seconds = time.perf_counter() - start
    return StudyResult(out, study.n_chunks, done_before, len(todo), seconds, where.where, where.addresses)


def _create(study: MotionStudy, out: Path) -> None:
    """The store, atomically: its manifest and an empty folder of chunks."""
    manifest = {"format": MOTION_FORMAT, "study_digest": study.digest(), "study_toml": study.text}
    manifest |= {"trials": [t.name for t in study.trials], "chunks": study.n_chunks}
    with atomic_path(out, directory=True) as tmp:
        (tmp / CHUNKS).mkdir()
        (tmp / MANIFEST).write_text(json.dumps(manifest, indent=1), encoding="utf-8")


def _existing(study: MotionStudy, out: Path, resume: bool, notify) -> set:
    """The chunks done in an existing store (file present, checksums holding); empty if there is none yet."""
    if not (out.exists() or out.is_symlink()):
        return set()
    if not resume:
        store.refuse_existing(out)
    digest = _manifest(out).get("study_digest")
    if digest != study.digest():
        raise ParameterError(
            "store",
            f"{str(out)!r} holds another study (or its files changed since; digest {str(digest)[:12]}, this file "
            f"{study.digest()[:12]}): resume with the study and files that made it, or write to another store",
        )
    done, damaged = set(), []
    for index in range(study.n_chunks):
        path = _chunk_path(out, index)
        if path.is_file():
            try:
                netcdf._verify(path)
                done.add(index)
            except ParameterError:
                damaged.append(index)
    if damaged:
        notify(f"motions: {len(damaged)} chunk file(s) damaged ({damaged[:5]}); computing them again")
    return done


def _manifest(out: Path) -> dict:
    try:
        manifest = json.loads((out / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError):
        manifest = None
    if not isinstance(manifest, dict) or manifest.get("format") != MOTION_FORMAT:
        raise ParameterError("store", f"{str(out)!r} is not a spinectl motion study store (no {MANIFEST} of it)")
    return manifest


def _chunk_path(out: Path, index: int) -> Path:
    return Path(out) / CHUNKS / f"{index}.nc"


def _task_key(study: MotionStudy) -> Callable:
    """The tasks' names on the cluster: unique to the study (its digest) and the chunk or trial."""
    prefix = f"spinectl-motion-{study.digest()[:16]}"

    def key(task) -> str:
        return f"{prefix}-trial-{task.trial}" if isinstance(task, TrialTask) else f"{prefix}-{task.index}"

    return key


class _Trials:
    """Which trials have all their chunks done and no file yet: their :class:`TrialTask` are due.

    Told of each chunk done (:meth:`done`), it counts each trial's chunks left, so that a trial is due as
    soon as its last chunk is, without looking at every trial again.
    """

    def __init__(self, study: MotionStudy, out: Path, done: set):
        self.study, self.out = study, out
        self.members = [[] for _ in study.trials]
        for index in range(study.n_chunks):
            self.members[study.chunk(index).trial].append(index)
        self.left = [sum(i not in done for i in chunks) for chunks in self.members]
        self.due = [t for t, n in enumerate(self.left) if n == 0]

    def done(self, index: int) -> None:
        """Chunk ``index`` is done (counted once)."""
        t = self.study.chunk(index).trial
        self.left[t] -= 1
        if self.left[t] == 0:
            self.due.append(t)

    def tasks(self, store: str):
        """The :class:`TrialTask` of each trial due whose file is not there yet, each once."""
        while self.due:
            t = self.due.pop(0)
            name = self.study.trials[t].name
            if not (self.out / f"{name}.nc").exists():
                yield TrialTask(t, name, store, tuple(self.members[t]))


def _with_trials(tasks, trials: _Trials, store: str | None):
    """``tasks``, each after the trials due by then (:meth:`_Trials.tasks`), when the workers share the store.

    The executor takes a task as one completes, after the caller has written that one: a trial is due
    as soon as its last chunk is written, and assembled by a worker while the others compute.
    """
    for task in tasks:
        if store is not None:
            yield from trials.tasks(store)
        yield task


def _write_chunks(study: MotionStudy, out: Path, done: set, results, progress: bool | None, trials: _Trials) -> None:
    """Each chunk as it comes: written (atomically, with its checksums) or, written by its worker, checked;
    counted done, with a progress bar. A trial's result needs nothing more."""
    from tqdm import tqdm  # plain, as the parameter study's

    disable = None if progress is None else not progress
    saved = saved_on_interrupt(lambda: len(done), study.n_chunks, str(out), RESUME)
    bar = tqdm(total=study.n_chunks, initial=len(done), unit="chunk", desc="motions", disable=disable)
    with saved, bar:  # the bar closed first: the interruption's line comes after it
        for kind, index, dataset, crc in results:
            if kind == "trial":
                continue
            if dataset is None:  # its worker wrote it and checked it: the file must still hold those bytes
                _check_bytes(_chunk_path(out, index), crc)
            else:
                if not out.exists():  # at the first chunk: a model that does not load leaves no store behind
                    _create(study, out)
                netcdf.save(dataset, _chunk_path(out, index))
            done.add(index)
            trials.done(index)
            bar.update()


AGAIN = "run again with --resume, which computes that chunk again"
"""The end of the line of a chunk file found damaged once written."""


def _check_written(path: Path) -> None:
    """Raise :class:`ParameterError` (field ``store``) if a chunk file just written fails its checksums."""
    try:
        netcdf._verify(path)
    except ParameterError as exc:
        raise ParameterError("store", f"{exc.message.removesuffix('; write it again')}: {AGAIN}") from None


def _check_bytes(path: Path, crc: int) -> None:
    """Raise :class:`ParameterError` (field ``store``) unless the chunk file holds the bytes its worker wrote.

    The worker checked the file's own checksums (:func:`_check_written`) and sent the CRC-32 of its bytes: a
    read and a CRC here (a fraction of a millisecond) rather than the checksums of every variable again.
    """
    try:
        same = zlib.crc32(path.read_bytes()) == crc
    except OSError as exc:
        raise ParameterError("store", f"{str(path)!r} cannot be read ({exc.strerror}): {AGAIN}") from None
    if not same:
        raise ParameterError("store", f"{str(path)!r} is not the file its worker wrote (its bytes changed): {AGAIN}")


def _assemble(study: MotionStudy, out: Path, done: set) -> None:
    """Each trial whose chunks are all done and that has no file yet: ``<trial>.nc`` in the store."""
    for t, trial in enumerate(study.trials):
        chunks = study.chunks_of(t)
        if not (out / f"{trial.name}.nc").exists() and all(c.index in done for c in chunks):
            _write_trial(out, trial.name, [c.index for c in chunks])


def _write_trial(out: Path, name: str, chunks) -> None:
    """The trial ``name``'s chunks as one Dataset along time, written as ``<name>.nc`` in the store."""
    netcdf.save(_concatenated([_read_chunk(out, index) for index in chunks]), Path(out) / f"{name}.nc")


def _read_chunk(out: Path, index: int):
    import xarray as xr

    path = _chunk_path(out, index)
    netcdf._verify(path)
    return netcdf._unstamped(xr.load_dataset(path, engine="netcdf4"))


def _concatenated(datasets):
    """Chunks of one trial along ``time``, as :func:`motion_response` gives the whole trial."""
    import xarray as xr

    if len(datasets) == 1:
        return datasets[0]
    return xr.concat(
        datasets, dim="time", data_vars="minimal", coords="minimal", join="outer", combine_attrs="override"
    )


def load_motions(path: str | Path) -> dict:
    """The trials of a motion study's store, each one Dataset (dims time, joint, mode, ..., muscle).

    Parameters
    ----------
    path : str or Path
        The store of :func:`run_motion_study`.

    Returns
    -------
    dict of str to xarray.Dataset
        Trial name -> its Dataset, for the trials whose chunks are all done, in the study's order.

    Raises
    ------
    ParameterError
        Not a motion study's store, or a trial's file damaged (its checksums).
    """
    import xarray as xr

    out = Path(path)
    names = _manifest(out).get("trials", [])
    trials = {}
    for name in names:
        file = out / f"{name}.nc"
        if file.is_file():
            netcdf._verify(file)
            trials[name] = netcdf._unstamped(xr.load_dataset(file, engine="netcdf4"))
    return trials


__all__ = ["MotionTask", "TrialTask", "load_motions", "run_motion_study", "run_motion_task", "solve_motion_chunk"]
