"""Running a study: its chunks on the executor (:mod:`spinectl.landscape.study.executor`), written as they finish.

The store is locked for the run (:func:`spinectl.landscape.study.store.locked`): a second run on the
same store stops at once with a line naming the first. The client writes every finished chunk
(:class:`spinectl.landscape.study.store.Writer`); the executor keeps few in flight, so an interrupted
run loses at most those.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from tqdm import tqdm  # plain: tqdm.auto warns in kernels without ipywidgets (as the sweep)

from ..._validate import show
from ...errors import ModelError, ParameterError
from ...model import config
from ...model.params import Model
from .. import budget, columns, schema
from . import store
from .executor import CONNECT_TIMEOUT, WORKER_TIMEOUT, check_options, executor, local_processes
from .interrupt import saved_on_interrupt
from .spec import Study

RESUME = "continue with --resume"
"""How an interrupted study continues (:func:`.interrupt.interrupted_text`)."""


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

    Raises
    ------
    ModelError
        The model's arithmetic fails on the tile; the message names the chunk's combination.
    """
    model = config.set_parameters(task.model, task.overrides)
    e_grid, l_grid = (a.ravel() for a in np.meshgrid(task.eccentricity, task.lordosis, indexing="ij"))
    coupled = any(name in schema.ON_REQUEST for name in task.outputs)
    try:
        solved, _ = columns.point_columns(model, e_grid, l_grid, chunk_size=e_grid.size, coupled=coupled)
    except ModelError as exc:  # e.g. K = 1e308 overflows the reflex columns: say which combination
        values = ", ".join(f"{name} = {show(value)}" for name, value in task.overrides.items())
        raise ModelError(f"{exc} (study combination {values})" if values else str(exc)) from None
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
    worker_timeout: float = WORKER_TIMEOUT,
    notify: Callable[[str], None] | None = None,
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
        Seconds to wait for a remote ``scheduler``'s answer, connection and handshake [s].
    worker_timeout : float
        Seconds to wait for the first worker of a remote ``scheduler`` that has none, and for a
        worker again once every worker of the cluster has gone mid-run [s].
    notify : callable or None
        Called with a line of text for what the user should know while it runs (a
        remote scheduler's worker count, a wait for a worker, chunks found missing, the estimate of a long run).

    Returns
    -------
    StudyResult
        The store, the chunks of the study, those done before and now, the wall time
        [s] and where the chunks ran.

    Raises
    ------
    ParameterError
        Bad ``scheduler``, ``workers`` or ``max_chunks``; an unreachable scheduler, something
        else than a scheduler at its address, or no worker within ``worker_timeout``;
        ``resume`` of a foreign store; more than the available memory holds (:func:`estimate`).
    OutputError
        ``out`` exists and ``resume`` is false, it cannot be written, another run holds it, or the
        store estimated would not fit on its file system's free space.
    """
    timeouts = {"connect_timeout": connect_timeout, "worker_timeout": worker_timeout}
    check_run_options(scheduler, workers, max_chunks, **timeouts)
    start = time.perf_counter()
    notify = notify or (lambda line: None)
    with store.locked(out):  # before the existence check: two runs cannot both pass it
        done = store.existing(study, out, resume, notify)  # before the cluster starts: a refusal costs nothing
        indices = np.arange(study.n_chunks) if done is None else np.flatnonzero(done == 0)
        todo = indices[: None if max_chunks is None else max_chunks]
        probe = _probe(study)
        cost = estimate(study, todo.size, probe, local_processes(scheduler, workers, todo.size))
        budget.check(cost, out)  # before any cluster or store: what cannot fit is refused at once
        if cost.long:
            notify(cost.line())
        again = "the store holds every chunk finished; start a worker and run again with --resume"
        with executor(scheduler, workers, todo.size, **timeouts, notify=notify, again=again) as chunks:
            # a cluster's first chunks are submitted now: its workers start on them while the store is made
            prefix = f"spinectl-{study.digest()[:16]}"
            results = chunks.as_completed(solve_chunk, tasks(study, todo), key=lambda task: f"{prefix}-{task.index}")
            if done is None:  # after connecting: an unreachable scheduler leaves no store behind
                done = store.create(study, out, probe)
            done_before = int(np.count_nonzero(done))
            _run_chunks(study, out, done, results, progress)
        if np.all(done > 0):
            store.consolidate(out)
    seconds = time.perf_counter() - start
    return StudyResult(Path(out), study.n_chunks, done_before, todo.size, seconds, chunks.where, chunks.addresses)


def check_run_options(scheduler, workers, max_chunks, **timeouts) -> None:
    """Refuse in one line a run's options (:func:`~.executor.check_options`, and ``max_chunks``), before any work.

    Parameters
    ----------
    scheduler, workers, max_chunks :
        As :func:`run_study` takes them.
    **timeouts
        ``connect_timeout`` and ``worker_timeout`` [s].

    Raises
    ------
    ParameterError
        Naming the option and what it allows.
    """
    check_options(scheduler, workers, **timeouts)
    if max_chunks is not None and (isinstance(max_chunks, bool) or not isinstance(max_chunks, int) or max_chunks < 0):
        raise ParameterError("max_chunks", f"must be an integer >= 0 (got {max_chunks!r})")


def estimate(study: Study, n_todo: int, probe: dict[str, np.ndarray], processes: int = 1) -> budget.Estimate:
    """What running ``n_todo`` chunks of ``study`` costs: points, memory, disk and CPU time.

    Parameters
    ----------
    study : Study
        The study.
    n_todo : int
        Chunks to run (all of a new store, those left of a resumed one).
    probe : dict of str to numpy.ndarray
        The outputs at one point as stored (:func:`spinectl.landscape.study.store.encode`): their bytes.
    processes : int
        Processes solving chunks on this machine (the local workers; 1 in-process or for a remote cluster).

    Returns
    -------
    spinectl.landscape.budget.Estimate
        Memory: each process's interpreter and one chunk's working memory, the client's window of
        two finished chunks per process and the store's per-chunk counts; disk: the chunks' files after
        compression (:data:`~spinectl.landscape.budget.STORE_BYTES_PER_BYTE`); time: the benchmark's cost
        per point, on one core.
    """
    per_chunk = math.prod(study.grid_shape) / math.prod(study.tiles)  # points, on average over the tiles
    points = round(n_todo * per_chunk)
    per_point = sum(values.nbytes for values in probe.values())
    chunk = math.prod(study.tile)
    coupled = any(name in schema.ON_REQUEST for name in study.outputs)
    memory = processes * (budget.PROCESS_BYTES + chunk * (budget.WORKING_BYTES_PER_POINT + 2 * per_point))
    seconds = points * (budget.STUDY_SECONDS_PER_POINT + coupled * budget.COUPLED_SECONDS_PER_POINT)
    disk = points * per_point * budget.STORE_BYTES_PER_BYTE
    return budget.Estimate("study", points, memory + 24 * study.n_chunks, disk, seconds)


def _run_chunks(study: Study, out, done: np.ndarray, results, progress: bool | None) -> None:
    """Write each chunk of ``results`` as it comes, with a progress bar of the whole study."""
    writer = store.Writer(study, out, done)
    initial = int(np.count_nonzero(done))
    saved = saved_on_interrupt(lambda: int(np.count_nonzero(done)), study.n_chunks, str(out), RESUME)
    bar = tqdm(total=study.n_chunks, initial=initial, unit="chunk", desc="study", disable=_disabled(progress))
    with saved, bar:  # the bar closed first: the interruption's line comes after it
        for index, outputs in results:
            writer.write(study.chunk(index), outputs)
            bar.update()


def _probe(study: Study) -> dict[str, np.ndarray]:
    """The outputs at one point (the first of the first chunk): their dtypes and shapes, for the store."""
    first = next(tasks(study, [0]))
    one = Task(0, first.model, first.overrides, first.eccentricity[:1], first.lordosis[:1], first.outputs)
    return solve_chunk(one)[1]


def _disabled(progress: bool | None) -> bool | None:
    return None if progress is None else not progress  # None: tqdm shows it on a terminal only


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
