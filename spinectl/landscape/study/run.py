"""Running a study: chunks solved in-process or on a ``dask.distributed`` cluster, written as they finish.

Where the chunks run (:func:`run_study`):

- ``scheduler=None``: a local cluster started for the run, one single-threaded
  process per worker (cvxpy model building is pure Python and not
  thread-safe), listening on 127.0.0.1 only, no dashboard; closed at the end
  whatever happens. A study with at most one chunk left runs in-process.
- ``scheduler="synchronous"``: in-process, one chunk after another.
- ``scheduler="tcp://host:port"``: an existing cluster; its workers need the same spinectl.
  The connection and the handshake give up after ``connect_timeout`` (anything that
  listens there but is no Dask scheduler included), and the run waits at most
  ``worker_timeout`` for a first worker, before the store is made.

The store is locked for the run (:func:`spinectl.landscape.study.store.locked`): a
second run on the same store stops at once with a line naming the first.

The client writes every finished chunk (:class:`spinectl.landscape.study.store.Writer`) and
keeps at most two chunks per worker thread submitted, so neither the
scheduler nor the client holds more than a few chunks, however large the
study; an interrupted run loses at most those.
"""

from __future__ import annotations

import contextlib
import itertools
import logging
import math
import multiprocessing
import os
import re
import signal
import sys
import tempfile
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
from .spec import Study

SYNCHRONOUS = "synchronous"
"""The ``scheduler`` that runs every chunk in this process, one after another."""

ADDRESS = re.compile(r"^tcp://\S+$")
"""A ``dask.distributed`` scheduler address that spinectl can use: plain TCP."""

UNUSABLE_SCHEMES = {
    "tls": "needs certificates, which spinectl does not configure",
    "wss": "needs certificates, which spinectl does not configure",
    "ws": "is not tested with spinectl (its listener binds every interface): use tcp://",
    "ucx": "needs ucx-py, which spinectl does not install",
    "inproc": "reaches only a scheduler inside this process",
}
"""The other schemes of ``dask.distributed`` addresses, and why a study cannot use them."""

CONNECT_TIMEOUT = 10.0
"""Seconds to wait for a remote scheduler's answer (connection and handshake) before giving up [s]."""

WORKER_TIMEOUT = 60.0
"""Seconds to wait for the first worker of a remote scheduler that has none, or for a worker again once
every worker of the run has gone [s]."""

POLL = 1.0
"""Seconds between looks at the workers while no chunk finishes [s]."""

MALLOC_TRIM_SETTING = "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_"
"""Dask sets ``MALLOC_TRIM_THRESHOLD_=65536`` in its workers so that glibc hands freed memory back at
once; the fast path allocates and frees many arrays of a few hundred kB per chunk and then runs about
15 % slower (measured on one chunk of 4010 points). Local workers keep glibc's own threshold; a chunk's
memory is bounded anyway (the benchmark's peak, docs/studies.md)."""

START_METHOD = "forkserver" if "forkserver" in multiprocessing.get_all_start_methods() else "spawn"
"""How local worker processes start: forked from a fresh server process where the platform allows
(Linux, macOS), rather than dask's default, a new interpreter each (``spawn``). Both start from a clean
process (never a fork of the client and its threads); a forked worker ends with ``os._exit``, without the
interpreter's shutdown, which took 1.2 s of a closing cluster of two workers (0.05 s now; load 5)."""

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
    _check_options(scheduler, workers, max_chunks, timeouts)
    start = time.perf_counter()
    notify = notify or (lambda line: None)
    with store.locked(out):  # before the existence check: two runs cannot both pass it
        done = store.existing(study, out, resume, notify)  # before the cluster starts: a refusal costs nothing
        indices = np.arange(study.n_chunks) if done is None else np.flatnonzero(done == 0)
        todo = indices[: None if max_chunks is None else max_chunks]
        probe = _probe(study)
        cost = estimate(study, todo.size, probe, _processes(scheduler, workers, todo.size))
        budget.check(cost, out)  # before any cluster or store: what cannot fit is refused at once
        if cost.long:
            notify(cost.line())
        with _executor(scheduler, workers, todo.size, tuple(timeouts.values()), notify) as executor:
            # a cluster's first chunks are submitted now: its workers start on them while the store is made
            results = executor.run(tasks(study, todo), f"spinectl-{study.digest()[:16]}")
            if done is None:  # after connecting: an unreachable scheduler leaves no store behind
                done = store.create(study, out, probe)
            done_before = int(np.count_nonzero(done))
            _run_chunks(study, out, done, results, progress)
        if np.all(done > 0):
            store.consolidate(out)
    seconds = time.perf_counter() - start
    return StudyResult(Path(out), study.n_chunks, done_before, todo.size, seconds, executor.where, executor.addresses)


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


def _processes(scheduler: str | None, workers: int | None, n_todo: int) -> int:
    """Processes of this machine that will solve chunks (as :func:`_executor` starts them)."""
    if scheduler is None and n_todo > 1:
        return min(workers or _cores(), n_todo)
    return 1


def _run_chunks(study: Study, out, done: np.ndarray, results, progress: bool | None) -> None:
    """Write each chunk of ``results`` as it comes, with a progress bar of the whole study."""
    writer = store.Writer(study, out, done)
    initial = int(np.count_nonzero(done))
    with tqdm(total=study.n_chunks, initial=initial, unit="chunk", desc="study", disable=_disabled(progress)) as bar:
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


def _check_options(scheduler, workers, max_chunks, timeouts: dict) -> None:
    if scheduler is not None and not (scheduler == SYNCHRONOUS or ADDRESS.match(str(scheduler))):
        allowed = f"{SYNCHRONOUS!r} or a dask.distributed address such as tcp://host:8786"
        scheme = str(scheduler).partition("://")[0]
        why = f": {scheme}:// {UNUSABLE_SCHEMES[scheme]}" if scheme in UNUSABLE_SCHEMES else ""
        raise ParameterError("scheduler", f"must be {allowed} (got {scheduler!r}){why}")
    if scheduler is not None and scheduler != SYNCHRONOUS:
        _check_host_port(scheduler)
    if workers is not None:
        if scheduler is not None:
            raise ParameterError("workers", "sets the size of the local cluster: not with a scheduler")
        most = WORKERS_PER_CORE * _cores()
        if isinstance(workers, bool) or not isinstance(workers, int) or not 1 <= workers <= most:
            allowed = f"an integer in [1, {most}] ({WORKERS_PER_CORE} per core)"
            raise ParameterError("workers", f"must be {allowed} (got {workers!r})")
    if max_chunks is not None and (isinstance(max_chunks, bool) or not isinstance(max_chunks, int) or max_chunks < 0):
        raise ParameterError("max_chunks", f"must be an integer >= 0 (got {max_chunks!r})")
    for name, seconds in timeouts.items():
        if isinstance(seconds, bool) or not isinstance(seconds, int | float) or not 0 < seconds < math.inf:
            raise ParameterError(name, f"must be a number of seconds > 0 (got {seconds!r})")


def _check_host_port(scheduler: str) -> None:
    """Refuse at once an address without a host, or with a port that is not an integer in [1, 65535]:
    such an address used to fail only after the connection's timeout, or with Python's own words."""
    from distributed.comm.addressing import parse_host_port

    try:
        host, port = parse_host_port(scheduler.removeprefix("tcp://"))
    except ValueError as exc:
        host, port = None, str(exc)
    if not host or isinstance(port, str) or not 1 <= port <= 65535:
        raise ParameterError(
            "scheduler",
            "must be tcp://HOST:PORT with a host and a port in [1, 65535], e.g. tcp://127.0.0.1:8786 "
            f"(got {scheduler!r})",
        )


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
    """Chunks on a ``dask.distributed`` cluster, at most two per worker thread in flight.

    While no chunk finishes, the workers are counted every :data:`POLL` seconds: once
    the cluster has had none for ``worker_timeout`` seconds (they were stopped, or lost
    their network), the run stops with one line; the store holds every chunk written.
    """

    def __init__(self, client, where: str, worker_timeout: float = WORKER_TIMEOUT):
        self.client, self.where, self.worker_timeout = client, where, worker_timeout
        info = client.scheduler_info()
        self.addresses = (info["address"], *sorted(info["workers"]))

    def run(self, chunks: Iterator[Task], prefix: str) -> Iterator[tuple[int, dict[str, np.ndarray]]]:
        """Submit the first chunks at once; return the chunks' results as they finish, submitting one as one ends."""
        from distributed import as_completed

        window = 2 * max(1, sum(self.client.nthreads().values()))

        def submit(task: Task):
            return self.client.submit(solve_chunk, task, key=f"{prefix}-{task.index}")

        pending = as_completed([submit(task) for task in itertools.islice(chunks, window)], loop=self.client.loop)
        return self._results(pending, chunks, submit)

    def _results(self, pending, chunks: Iterator[Task], submit):
        watch = _Watch(self.client, self.where, self.worker_timeout)  # one for the run
        while not pending.is_empty():
            self._wait_for_one(pending, watch)
            for future in pending.next_batch(block=False):
                result = self._result(future, watch)  # a chunk's error ends the run here; the cluster is closed after
                future.release()
                watch.alive()
                yield result
                task = next(chunks, None)
                if task is not None:
                    pending.add(submit(task))

    @staticmethod
    def _wait_for_one(pending, watch: _Watch) -> None:
        """Return once a future of ``pending`` has finished, as long as the cluster has a worker."""
        while not pending.has_ready():
            time.sleep(0.01)
            watch()

    @staticmethod
    def _result(future, watch: _Watch):
        """The chunk of a finished future. Its data lives on the worker that solved it: a worker gone
        before the data came back leaves the scheduler waiting for another, so this wait is bounded too."""
        while True:
            try:
                return future.result(timeout=POLL)
            except TimeoutError:
                watch()


class _Watch:
    """Call while waiting: every :data:`POLL` seconds without a finished chunk it counts the
    cluster's workers, and raises once there has been none for ``worker_timeout`` seconds.

    A finished chunk (:meth:`alive`) shows a worker: no question to the scheduler while chunks come.
    """

    def __init__(self, client, where: str, worker_timeout: float):
        self.client, self.where, self.worker_timeout = client, where, worker_timeout
        self.idle_since, self.looked = None, time.monotonic()

    def alive(self) -> None:
        """A chunk has just finished: the cluster had a worker now."""
        self.idle_since, self.looked = None, time.monotonic()

    def __call__(self) -> None:
        if time.monotonic() - self.looked < POLL:
            return
        self.looked = time.monotonic()
        if self.client.scheduler_info(n_workers=0).get("n_workers", 1) > 0:
            self.idle_since = None
        elif self.idle_since is None:
            self.idle_since = self.looked
        elif self.looked - self.idle_since > self.worker_timeout:
            raise ParameterError(
                "scheduler",
                f"{self.where}: every worker has gone, and none joined within {self.worker_timeout:g} s: the "
                "store holds every chunk finished; start a worker and run again with --resume",
            )


@contextlib.contextmanager
def _executor(scheduler: str | None, workers: int | None, n_todo: int, timeouts: tuple[float, float], notify):
    if scheduler == SYNCHRONOUS or (scheduler is None and n_todo <= 1):
        yield _InProcess()
        return
    if scheduler is not None:
        with _remote(scheduler, *timeouts, notify) as client:
            n_workers = len(client.scheduler_info()["workers"])
            yield _Distributed(client, _where(scheduler, n_workers), timeouts[1])
        return
    n = min(workers or _cores(), n_todo)
    with _local_cluster(n) as client:
        yield _Distributed(client, f"{n} local worker{'s' * (n != 1)}", timeouts[1])


def _where(scheduler: str, n_workers: int) -> str:
    return f"{scheduler} ({n_workers} worker{'s' * (n_workers != 1)})"


@contextlib.contextmanager
def _local_cluster(n: int):
    """A client of a new local cluster of ``n`` single-threaded worker processes on 127.0.0.1, closed after.

    Ctrl-C is held (SIGINT blocked) while the cluster starts and while it closes, and acts
    in between: the worker processes inherit the blocked signal, so they print no
    tracebacks of their own, and distributed is never asked to close a half-started
    cluster (it asserts then).
    """
    import dask
    from distributed import Client, LocalCluster

    previous = _block_interrupts()
    try:
        settings = {MALLOC_TRIM_SETTING: None, "distributed.worker.multiprocessing-method": START_METHOD}
        with dask.config.set(settings), _workers_stderr():  # see there for all three
            cluster = LocalCluster(
                n_workers=n,
                threads_per_worker=1,  # cvxpy is not thread-safe; one process per worker
                processes=True,
                host="127.0.0.1",  # loopback only: nothing listens on another address
                dashboard_address=None,
                # no dashboard, but the scheduler's HTTP server (health routes) would take port 8787 and
                # warn on stderr when another cluster has it: a free loopback port instead
                scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
                silence_logs=logging.ERROR,
            )
        try:
            client = Client(cluster, set_as_default=False)
            try:
                _restore_interrupts(previous)  # a Ctrl-C of the start-up acts here
                yield client
            finally:
                _block_interrupts()
                client.close()
        finally:
            cluster.close()
    finally:
        _restore_interrupts(previous)


@contextlib.contextmanager
def _workers_stderr():
    """Start worker processes with a temporary file as their standard error, not the terminal.

    The worker processes (or their fork server, :data:`START_METHOD`) are started from distributed's
    own threads, which do not share the blocked SIGINT; a Ctrl-C that reaches a new interpreter while it
    starts makes CPython print "Fatal Python error: init_import_site" and a traceback there. The workers log at
    error level only (``silence_logs``) and their failures reach the client as exceptions.
    """
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile() as log:
        os.dup2(log.fileno(), 2)
        try:
            yield
        finally:
            os.dup2(saved, 2)
            os.close(saved)


def _block_interrupts():
    """Block SIGINT in this thread (and so in the threads and processes it starts); return the previous mask."""
    return signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT}) if hasattr(signal, "pthread_sigmask") else None


def _restore_interrupts(previous) -> None:
    """Restore the mask from :func:`_block_interrupts`: a SIGINT that came meanwhile is delivered now."""
    if previous is not None:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


@contextlib.contextmanager
def _remote(scheduler: str, connect_timeout: float, worker_timeout: float, notify):
    """A client of the scheduler at ``scheduler``, once it has answered and has a worker."""
    from distributed import Client

    n_workers = _handshake(scheduler, connect_timeout)
    notify(f"study: {_where(scheduler, n_workers)}")
    try:
        client = Client(scheduler, timeout=connect_timeout, set_as_default=False)
    except (OSError, TimeoutError) as exc:
        raise ParameterError("scheduler", f"cannot connect to {scheduler}: {exc}") from None
    with client:
        if not n_workers:
            notify(f"study: waiting up to {worker_timeout:g} s for a worker of {scheduler}")
            try:
                client.wait_for_workers(1, timeout=worker_timeout)
            except TimeoutError:
                raise ParameterError(
                    "scheduler",
                    f"{scheduler} has no worker, and none joined within {worker_timeout:g} s: start one "
                    f"(dask worker {scheduler}) or wait longer (--worker-timeout)",
                ) from None
        yield client


def _handshake(scheduler: str, timeout: float) -> int:
    """Ask the scheduler who it is, within ``timeout`` [s] in all; return its number of workers.

    ``distributed.Client`` bounds the TCP connection but not every read of the
    handshake after it: something that listens but is no Dask scheduler (an HTTP
    server) would keep it waiting for ever.
    """
    import asyncio
    import socket
    import struct

    from distributed.comm.addressing import parse_host_port
    from distributed.core import rpc

    async def identity():
        host, port = parse_host_port(scheduler.removeprefix("tcp://"))
        # a name that does not resolve: said so (socket.gaierror), not "no answer within 10 s" after retries
        await asyncio.get_running_loop().getaddrinfo(host, port, type=socket.SOCK_STREAM)
        async with rpc(scheduler, timeout=timeout) as remote:
            return await remote.identity()

    try:
        info = asyncio.run(asyncio.wait_for(identity(), timeout))
    except TimeoutError:
        reason = f"no answer of a Dask scheduler within {timeout:g} s (is it one?)"
        raise ParameterError("scheduler", f"cannot connect to {scheduler}: {reason}") from None
    except (OSError, ValueError, TypeError, struct.error) as exc:  # refused, unreachable, garbage for a handshake
        raise ParameterError("scheduler", f"cannot connect to {scheduler}: {exc}") from None
    except MemoryError:  # a frame length of exabytes: something else's protocol
        info = None
    if not isinstance(info, dict) or info.get("type") != "Scheduler":
        raise ParameterError("scheduler", f"cannot connect to {scheduler}: it answers, but is no Dask scheduler")
    return int(info.get("n_workers", len(info.get("workers", ()))))


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
