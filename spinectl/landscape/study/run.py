"""Running a study: chunks solved in-process or on a ``dask.distributed`` cluster, written as they finish.

Where the chunks run (:func:`run_study`):

- ``scheduler=None``: a local cluster started for the run, one single-threaded
  process per worker (cvxpy model building is pure Python and not
  thread-safe), listening on 127.0.0.1 only, no dashboard; closed at the end
  whatever happens. A study with at most one chunk left runs in-process.
- ``scheduler="synchronous"``: in-process, one chunk after another.
- ``scheduler="tcp://host:port"``: an existing cluster; its workers need the same spinectl.

The client writes every finished chunk (:class:`spinectl.landscape.study.store.Writer`) and
keeps at most two chunks per worker thread submitted, so neither the
scheduler nor the client holds more than a few chunks, however large the
study; an interrupted run loses at most those.
"""

from __future__ import annotations

import contextlib
import itertools
import logging
import os
import re
import signal
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from tqdm import tqdm  # plain: tqdm.auto warns in kernels without ipywidgets (as the sweep)

from ...errors import ParameterError
from ...model import config
from ...model.params import Model
from .. import columns
from . import store
from .spec import Study

SYNCHRONOUS = "synchronous"
"""The ``scheduler`` that runs every chunk in this process, one after another."""

ADDRESS = re.compile(r"^(tcp|tls|ucx|inproc|ws|wss)://\S+$")
"""A ``dask.distributed`` scheduler address."""

CONNECT_TIMEOUT = 10.0
"""Seconds to wait for a remote scheduler before giving up [s]."""

MALLOC_TRIM_SETTING = "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_"
"""Dask sets ``MALLOC_TRIM_THRESHOLD_=65536`` in its workers so that glibc hands freed memory back at
once; the fast path allocates and frees many arrays of a few hundred kB per chunk and then runs about
15 % slower (measured on one chunk of 4010 points). Local workers keep glibc's own threshold; a chunk's
memory is bounded anyway (the benchmark's peak, docs/studies.md)."""

WORKERS_PER_CORE = 4
"""Most local workers per core: the solver is CPU-bound, more only costs memory."""


@dataclass(frozen=True)
class Task:
    """What a worker needs for one chunk: the model, the tile and the outputs (no store, no study file).

    Attributes
    ----------
    index : int
        The chunk (:meth:`spinectl.landscape.study.Study.chunk`).
    model : Model
        The base model.
    overrides : dict
        Parameters of the chunk's combination, by dotted name.
    eccentricity, lordosis : numpy.ndarray
        The tile's axes [m].
    outputs : tuple of str
        Variables to return.
    """

    index: int
    model: Model
    overrides: dict
    eccentricity: np.ndarray
    lordosis: np.ndarray
    outputs: tuple[str, ...]


def solve_chunk(task: Task) -> tuple[int, dict[str, np.ndarray]]:
    """Solve one chunk: its whole tile as one stacked problem of the fast path.

    One problem per chunk, whatever the worker: the answer depends only on the
    chunk, so 1 and N workers give the same bits (and so does
    :func:`spinectl.landscape.sweep.sweep` with ``chunk_size`` equal to a chunk of whole rows).

    Parameters
    ----------
    task : Task
        The chunk.

    Returns
    -------
    index : int
        ``task.index``.
    outputs : dict of str to numpy.ndarray
        On the tile, as :func:`spinectl.landscape.study.store.encode` gives them.
    """
    model = config.set_parameters(task.model, task.overrides)
    e_grid, l_grid = (a.ravel() for a in np.meshgrid(task.eccentricity, task.lordosis, indexing="ij"))
    solved, _ = columns.point_columns(model, e_grid, l_grid, chunk_size=e_grid.size)
    return task.index, store.encode(solved, task.outputs, (task.eccentricity.size, task.lordosis.size))


def tasks(study: Study, indices) -> Iterator[Task]:
    """The :class:`Task` of each chunk in ``indices``, made when asked for.

    Parameters
    ----------
    study : Study
        The study.
    indices : iterable of int
        Chunks, in the order to run them.

    Yields
    ------
    Task
        One chunk: its index, the base model, the parameter overrides of its
        combination, its tile of the E and Lambda axes [m] and the outputs to compute.
    """
    e_axis, l_axis = np.asarray(study.eccentricity), np.asarray(study.lordosis)
    for index in indices:
        chunk = study.chunk(index)
        overrides = study.overrides(chunk.combination)
        tile = e_axis[chunk.eccentricity], l_axis[chunk.lordosis]
        yield Task(int(index), study.model, overrides, *tile, study.outputs)


@dataclass(frozen=True)
class StudyResult:
    """What a run did.

    Attributes
    ----------
    store : Path
        The Zarr store.
    chunks : int
        Chunks of the study.
    done_before : int
        Chunks already done when the run started (a resume).
    computed : int
        Chunks solved and written by this run.
    seconds : float
        Wall time of the run [s].
    where : str
        Where the chunks ran: ``'in-process'``, ``'2 local workers'`` or the scheduler's address.
    addresses : tuple of str
        The scheduler's and the workers' addresses (empty in-process).
    """

    store: Path
    chunks: int
    done_before: int
    computed: int
    seconds: float
    where: str
    addresses: tuple[str, ...] = ()

    @property
    def complete(self) -> bool:
        """Every chunk of the study is done."""
        return self.done_before + self.computed == self.chunks


def run_study(
    study: Study,
    out: str | Path,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    resume: bool = False,
    max_chunks: int | None = None,
    progress: bool | None = None,
    connect_timeout: float = CONNECT_TIMEOUT,
) -> StudyResult:
    """Run ``study`` into the Zarr store ``out``: every chunk not yet done, written as it finishes.

    Parameters
    ----------
    study : Study
        The validated study (:func:`spinectl.landscape.study.load_study`).
    out : str or Path
        The store (a folder), created atomically; an existing one is refused unless ``resume``.
    scheduler : str or None
        None: a local cluster (in-process for at most one chunk); ``'synchronous'``: in-process;
        ``'tcp://host:port'``: an existing ``dask.distributed`` scheduler.
    workers : int or None
        Local worker processes (default: one per core, at most one per chunk); local cluster only.
    resume : bool
        Continue the study in ``out``, skipping the chunks done; refused if ``out`` holds another study.
    max_chunks : int or None
        Stop after this many chunks (the store stays resumable); None: run to the end.
    progress : bool or None
        A progress bar of chunks on stderr; None: only on a terminal.
    connect_timeout : float
        Seconds to wait for a remote ``scheduler`` [s].

    Returns
    -------
    StudyResult
        The store, the chunks of the study, those done before and now, the wall time
        [s] and where the chunks ran.

    Raises
    ------
    ParameterError
        Bad ``scheduler``, ``workers`` or ``max_chunks``; an unreachable scheduler; ``resume`` of a foreign store.
    OutputError
        ``out`` exists and ``resume`` is false, or it cannot be written.
    """
    _check_options(scheduler, workers, max_chunks)
    start = time.perf_counter()
    done = store.existing(study, out, resume)  # before the cluster starts: a refusal costs nothing
    indices = np.arange(study.n_chunks) if done is None else np.flatnonzero(done == 0)
    todo = indices[: None if max_chunks is None else max_chunks]
    with _executor(scheduler, workers, todo.size, connect_timeout) as executor:
        if done is None:  # after connecting: an unreachable scheduler leaves no store behind
            done = store.create(study, out, _probe(study))
        done_before = int(np.count_nonzero(done))
        writer = store.Writer(study, out, done)
        bar = tqdm(total=study.n_chunks, initial=done_before, unit="chunk", desc="study", disable=_disabled(progress))
        with bar:
            for index, outputs in executor.run(tasks(study, todo), f"spinectl-{study.digest()[:16]}"):
                writer.write(study.chunk(index), outputs)
                bar.update()
    if np.all(done > 0):
        store.consolidate(out)
    seconds = time.perf_counter() - start
    return StudyResult(Path(out), study.n_chunks, done_before, todo.size, seconds, executor.where, executor.addresses)


def _probe(study: Study) -> dict[str, np.ndarray]:
    """The outputs at one point (the first of the first chunk): their dtypes and shapes, for the store."""
    first = next(tasks(study, [0]))
    one = Task(0, first.model, first.overrides, first.eccentricity[:1], first.lordosis[:1], first.outputs)
    return solve_chunk(one)[1]


def _disabled(progress: bool | None) -> bool | None:
    return None if progress is None else not progress  # None: tqdm shows it on a terminal only


def _check_options(scheduler, workers, max_chunks) -> None:
    if scheduler is not None and not (scheduler == SYNCHRONOUS or ADDRESS.match(str(scheduler))):
        allowed = f"{SYNCHRONOUS!r} or a dask.distributed address such as tcp://host:8786"
        raise ParameterError("scheduler", f"must be {allowed} (got {scheduler!r})")
    if workers is not None:
        if scheduler is not None:
            raise ParameterError("workers", "sets the size of the local cluster: not with a scheduler")
        most = WORKERS_PER_CORE * _cores()
        if isinstance(workers, bool) or not isinstance(workers, int) or not 1 <= workers <= most:
            allowed = f"an integer in [1, {most}] ({WORKERS_PER_CORE} per core)"
            raise ParameterError("workers", f"must be {allowed} (got {workers!r})")
    if max_chunks is not None and (isinstance(max_chunks, bool) or not isinstance(max_chunks, int) or max_chunks < 0):
        raise ParameterError("max_chunks", f"must be an integer >= 0 (got {max_chunks!r})")


def _cores() -> int:
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


class _InProcess:
    """Every chunk in this process, in order."""

    where = "in-process"
    addresses: tuple[str, ...] = ()

    @staticmethod
    def run(chunks: Iterator[Task], prefix: str):
        for task in chunks:
            yield solve_chunk(task)


class _Distributed:
    """Chunks on a ``dask.distributed`` cluster, at most two per worker thread in flight."""

    def __init__(self, client, where: str):
        self.client, self.where = client, where
        info = client.scheduler_info()
        self.addresses = (info["address"], *sorted(info["workers"]))

    def run(self, chunks: Iterator[Task], prefix: str):
        from distributed import as_completed

        window = 2 * max(1, sum(self.client.nthreads().values()))

        def submit(task: Task):
            return self.client.submit(solve_chunk, task, key=f"{prefix}-{task.index}")

        pending = as_completed([submit(task) for task in itertools.islice(chunks, window)], loop=self.client.loop)
        for future in pending:
            result = future.result()  # a chunk's error ends the run here; the cluster is closed on the way out
            future.release()
            yield result
            task = next(chunks, None)
            if task is not None:
                pending.add(submit(task))


@contextlib.contextmanager
def _executor(scheduler: str | None, workers: int | None, n_todo: int, connect_timeout: float):
    if scheduler == SYNCHRONOUS or (scheduler is None and n_todo <= 1):
        yield _InProcess()
        return
    import dask
    from distributed import Client, LocalCluster

    if scheduler is not None:
        try:
            client = Client(scheduler, timeout=connect_timeout, set_as_default=False)
        except (OSError, TimeoutError) as exc:
            raise ParameterError("scheduler", f"cannot connect to {scheduler}: {exc}") from None
        with client:
            yield _Distributed(client, scheduler)
        return
    n = min(workers or _cores(), n_todo)
    with dask.config.set({MALLOC_TRIM_SETTING: None}):  # unset in the workers' environment, see MALLOC_TRIM_SETTING
        cluster = LocalCluster(
            n_workers=n,
            threads_per_worker=1,  # cvxpy is not thread-safe; one process per worker
            processes=True,
            host="127.0.0.1",  # loopback only: nothing listens on another address
            dashboard_address=None,
            silence_logs=logging.ERROR,
        )
    with cluster, Client(cluster, set_as_default=False) as client:
        client.run(_ignore_interrupts)
        yield _Distributed(client, f"{n} local worker{'s' * (n != 1)}")


def _ignore_interrupts() -> None:
    """In a local worker: leave Ctrl-C to the command, which closes the cluster (no worker tracebacks)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def describe(result: StudyResult) -> str:
    """One line: chunks done, this run's share, wall time, where, the store.

    Parameters
    ----------
    result : StudyResult
        From :func:`run_study`.

    Returns
    -------
    str
        The line, without a newline; it ends with how to resume if chunks are left.
    """
    done = result.done_before + result.computed
    tail = "" if result.complete else f"; {result.chunks - done} left: run again with --resume"
    return (
        f"study: {done} of {result.chunks} chunks done ({result.computed} computed now, {result.done_before} before) "
        f"in {result.seconds:.1f} s, {result.where}; store {str(result.store)!r}{tail}"
    )
