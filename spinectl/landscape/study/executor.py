"""Where chunks of work run: in this process, on a local ``dask.distributed`` cluster, or on an existing one.

The engine's executor, shared by the study (:func:`spinectl.landscape.study.run_study`) and the atlas
(:func:`spinectl.landscape.atlas.run_atlas`): :func:`executor` opens one for a run, chosen by the
options of ``spinectl study`` (``--scheduler``, ``--workers``, ``--worker-timeout``), and its
:meth:`~Distributed.as_completed` maps a picklable function over the chunks, returning each result
as it completes. What a chunk is, how the results are saved and shown and what a resume skips stay
with the caller.

- ``scheduler=None``: a local cluster started for the run, one single-threaded
  process per worker (cvxpy model building is pure Python and not
  thread-safe), listening on 127.0.0.1 only, no dashboard; closed at the end
  whatever happens. A run with at most one chunk runs in-process.
- ``scheduler="synchronous"``: in-process, one chunk after another.
- ``scheduler="tcp://host:port"``: an existing cluster; its workers need the same spinectl.
  The connection and the handshake give up after ``connect_timeout`` (anything that
  listens there but is no Dask scheduler included), and the run waits at most
  ``worker_timeout`` for a first worker.

On a cluster at most two chunks per worker thread are submitted at a time, one more as
one completes, so neither the scheduler nor the client holds more than a few chunks,
however many there are; an interrupted run loses at most those.
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
import threading
import time
from collections.abc import Callable, Iterable, Iterator

from ...errors import ParameterError

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
"""The other schemes of ``dask.distributed`` addresses, and why spinectl cannot use them."""

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

AGAIN = "every chunk finished is kept; start a worker and run again"
"""The end of the line of the error once every worker of a cluster has gone, unless the caller says more."""

WORKERS_PER_CORE = 4
"""Most local workers per core: the solver is CPU-bound, more only costs memory."""


def check_options(
    scheduler: str | None = None,
    workers: int | None = None,
    connect_timeout: float = CONNECT_TIMEOUT,
    worker_timeout: float = WORKER_TIMEOUT,
) -> None:
    """Refuse in one line options that :func:`executor` cannot use, before any work or cluster.

    Parameters
    ----------
    scheduler : str or None
        None (a local cluster), :data:`SYNCHRONOUS` or ``'tcp://host:port'``.
    workers : int or None
        Local worker processes, in [1, :data:`WORKERS_PER_CORE` per core]; only with ``scheduler=None``.
    connect_timeout, worker_timeout : float
        Seconds, finite and > 0 [s].

    Raises
    ------
    ParameterError
        Naming the option (``scheduler``, ``workers``, ``connect_timeout`` or ``worker_timeout``) and what it allows.
    """
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
    for name, seconds in {"connect_timeout": connect_timeout, "worker_timeout": worker_timeout}.items():
        if isinstance(seconds, bool) or not isinstance(seconds, int | float) or not 0 < seconds < math.inf:
            raise ParameterError(name, f"must be a number of seconds > 0 (got {seconds!r})")


def local_processes(scheduler: str | None, workers: int | None, n_chunks: int) -> int:
    """Processes of this machine that will solve chunks, as :func:`executor` starts them.

    Parameters
    ----------
    scheduler : str or None
        As for :func:`executor`.
    workers : int or None
        As for :func:`executor`.
    n_chunks : int
        Chunks to run.

    Returns
    -------
    int
        The local workers; 1 in-process or for a remote cluster (whose workers are elsewhere).
    """
    if scheduler is None and n_chunks > 1:
        return min(workers or _cores(), n_chunks)
    return 1


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


class InProcess:
    """Every chunk in this process, in order: ``--scheduler synchronous``, or a run of at most one chunk.

    Attributes
    ----------
    where : str
        ``'in-process'``.
    addresses : tuple of str
        Empty: no scheduler, no workers.
    """

    where = "in-process"
    addresses: tuple[str, ...] = ()

    @staticmethod
    def as_completed(function: Callable, items: Iterable, key: Callable | None = None) -> Iterator:
        """``function(item)`` for each item, one after another, each returned before the next is solved.

        Parameters
        ----------
        function : callable
            Takes one item; its result should name its item (e.g. start with the chunk's index), as on a cluster.
        items : iterable
            The chunks, taken one at a time.
        key : callable or None
            Unused here (see :meth:`Distributed.as_completed`).

        Yields
        ------
        object
            ``function(item)``, in the order of ``items``.
        """
        for item in items:
            yield function(item)


class Distributed:
    """Chunks on a ``dask.distributed`` cluster, at most two per worker thread in flight.

    While no chunk finishes, the workers are counted every :data:`POLL` seconds: once
    the cluster has had none for ``worker_timeout`` seconds (they were stopped, or lost
    their network), the run stops with one line; the caller keeps every chunk it has saved.

    Parameters
    ----------
    client : distributed.Client
        A client of the cluster, with at least one worker.
    where : str
        The cluster for a reader, e.g. ``'2 local workers'``.
    worker_timeout : float
        Seconds to wait for a worker again once every worker has gone [s].
    again : str
        The end of that error's line: what is kept and how to continue.

    Attributes
    ----------
    where : str
        ``where``.
    addresses : tuple of str
        The scheduler's and the workers' addresses.
    """

    def __init__(self, client, where: str, worker_timeout: float = WORKER_TIMEOUT, again: str = AGAIN):
        self.client, self.where, self.worker_timeout, self.again = client, where, worker_timeout, again
        info = client.scheduler_info()
        self.addresses = (info["address"], *sorted(info["workers"]))

    def as_completed(self, function: Callable, items: Iterable, key: Callable | None = None) -> Iterator:
        """``function(item)`` for each item on the cluster, returned as each completes (``distributed.as_completed``).

        The first chunks are submitted at once (the workers start on them while the caller
        prepares); another is taken from ``items`` as one completes. A chunk's error ends the
        run with that error when its result is reached.

        Parameters
        ----------
        function : callable
            Picklable (a module's function); takes one item and returns what names its item, since
            the results come in the order they complete.
        items : iterable
            Picklable chunks, taken as they are submitted.
        key : callable or None
            ``key(item)``: the task's name on the cluster, unique to what it computes (a
            cluster shares the result of equal keys); None: dask's hash of the function and the item.

        Returns
        -------
        iterator
            ``function(item)`` for each item, in the order they complete.
        """
        from distributed import as_completed

        items = iter(items)
        window = 2 * max(1, sum(self.client.nthreads().values()))

        def submit(item):
            return self.client.submit(function, item, **({} if key is None else {"key": key(item)}))

        pending = as_completed([submit(item) for item in itertools.islice(items, window)], loop=self.client.loop)
        return self._results(pending, items, submit)

    def _results(self, pending, items: Iterator, submit):
        watch = _Watch(self.client, self.where, self.worker_timeout, self.again)  # one for the run
        while not pending.is_empty():
            self._wait_for_one(pending, watch)
            for future in pending.next_batch(block=False):
                result = self._result(future, watch)  # a chunk's error ends the run here; the cluster is closed after
                future.release()
                watch.alive()
                yield result
                item = next(items, None)
                if item is not None:
                    pending.add(submit(item))

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

    def __init__(self, client, where: str, worker_timeout: float, again: str):
        self.client, self.where, self.worker_timeout, self.again = client, where, worker_timeout, again
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
                f"{self.where}: every worker has gone, and none joined within {self.worker_timeout:g} s: {self.again}",
            )


@contextlib.contextmanager
def executor(
    scheduler: str | None,
    workers: int | None,
    n_chunks: int,
    *,
    connect_timeout: float = CONNECT_TIMEOUT,
    worker_timeout: float = WORKER_TIMEOUT,
    notify: Callable[[str], None] | None = None,
    name: str = "study",
    again: str = AGAIN,
) -> Iterator[InProcess | Distributed]:
    """Where a run's chunks go, as ``spinectl study`` chooses it; a cluster started here is closed after.

    Parameters
    ----------
    scheduler : str or None
        None: a local cluster of ``workers`` single-threaded processes on 127.0.0.1 (in-process for at
        most one chunk); :data:`SYNCHRONOUS`: in-process; ``'tcp://host:port'``: an existing
        ``dask.distributed`` scheduler, whose workers need the same spinectl.
    workers : int or None
        Local worker processes (default: one per core, at most one per chunk); local cluster only.
    n_chunks : int
        Chunks the run will map: no more local workers than that, and none for at most one.
    connect_timeout : float
        Seconds to wait for a remote ``scheduler``'s answer, connection and handshake [s].
    worker_timeout : float
        Seconds to wait for the first worker of a remote ``scheduler`` that has none, and for a
        worker again once every worker has gone mid-run [s].
    notify : callable or None
        Called with a line of text for the user (a remote scheduler's worker count, a wait for a worker).
    name : str
        The lines' prefix (``'study'``, ``'atlas'``).
    again : str
        The end of the line of the error once every worker has gone: what is kept and how to continue.

    Yields
    ------
    InProcess or Distributed
        Its ``as_completed(function, items, key)`` maps ``function`` over the chunks; ``where``
        and ``addresses`` say where they ran.

    Raises
    ------
    ParameterError
        Bad options (:func:`check_options`); an unreachable scheduler, something else than a
        scheduler at its address, or no worker within ``worker_timeout``.
    """
    check_options(scheduler, workers, connect_timeout, worker_timeout)
    notify = notify or (lambda line: None)
    if scheduler == SYNCHRONOUS or (scheduler is None and n_chunks <= 1):
        yield InProcess()
        return
    if scheduler is not None:
        with _remote(scheduler, connect_timeout, worker_timeout, notify, name) as client:
            n_workers = len(client.scheduler_info()["workers"])
            yield Distributed(client, _where(scheduler, n_workers), worker_timeout, again)
        return
    n = local_processes(scheduler, workers, n_chunks)
    with _local_cluster(n) as client:
        yield Distributed(client, f"{n} local worker{'s' * (n != 1)}", worker_timeout, again)


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

    held = _HeldInterrupt()
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
                _restore_interrupts(previous)
                held.release()  # a Ctrl-C of the start-up acts here
                yield client
            finally:
                _block_interrupts()
                held.hold()
                client.close()
        finally:
            cluster.close()
    finally:
        _restore_interrupts(previous)
        held.release()


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


class _HeldInterrupt:
    """Python's Ctrl-C handler, replaced by one that notes the interrupt while a cluster starts or closes.

    The blocked SIGINT (:func:`_block_interrupts`) holds a Ctrl-C sent to this thread, and so to the
    process group a terminal signals; but a SIGINT sent to the process alone (``kill -INT``, as job
    managers send it) is delivered to any thread that does not block it, one of those the cluster
    started before, and Python then raises KeyboardInterrupt in the main thread in the middle of the
    start, whatever its mask: distributed asserted after about a minute. While held, the handler
    notes it; :meth:`release` raises it then. Only Python's own handler is replaced: an ignored
    SIGINT stays ignored, and outside the main thread nothing changes (no handler can be set there).
    """

    def __init__(self):
        self.caught = False
        self.previous = None
        self.hold()

    def hold(self) -> None:
        """Note a Ctrl-C from now on, instead of raising it."""
        if threading.current_thread() is threading.main_thread() and (
            signal.getsignal(signal.SIGINT) is signal.default_int_handler
        ):
            self.previous = signal.signal(signal.SIGINT, self._note)

    def _note(self, signum, frame) -> None:
        self.caught = True

    def release(self) -> None:
        """Restore Python's handler, and raise KeyboardInterrupt if a Ctrl-C came while held."""
        if self.previous is not None:
            signal.signal(signal.SIGINT, self.previous)
            self.previous = None
        if self.caught:
            self.caught = False
            raise KeyboardInterrupt


def _block_interrupts():
    """Block SIGINT in this thread (and so in the threads and processes it starts); return the previous mask."""
    return signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT}) if hasattr(signal, "pthread_sigmask") else None


def _restore_interrupts(previous) -> None:
    """Restore the mask from :func:`_block_interrupts`: a SIGINT that came meanwhile is delivered now."""
    if previous is not None:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


@contextlib.contextmanager
def _remote(scheduler: str, connect_timeout: float, worker_timeout: float, notify, name: str):
    """A client of the scheduler at ``scheduler``, once it has answered and has a worker."""
    from distributed import Client

    n_workers = _handshake(scheduler, connect_timeout)
    notify(f"{name}: {_where(scheduler, n_workers)}")
    try:
        client = Client(scheduler, timeout=connect_timeout, set_as_default=False)
    except (OSError, TimeoutError) as exc:
        raise ParameterError("scheduler", f"cannot connect to {scheduler}: {exc}") from None
    with client:
        if not n_workers:
            notify(f"{name}: waiting up to {worker_timeout:g} s for a worker of {scheduler}")
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
