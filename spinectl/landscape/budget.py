"""What a sweep or a study will cost, estimated before the work: points, memory, disk, time.

A landscape's cost grows with every axis that multiplies its points (E x Lambda, the K
values, the parameter axes and draws of a study), so a request is bounded by what it
costs rather than by one axis: :func:`check` refuses in one line what cannot fit in the
available memory or on the free disk, and :meth:`Estimate.line` states the estimate
before work long enough to deserve one. The bytes come from the outputs at one point (their
dtypes and shapes, so the number of muscles and segments counts too); the time from the
per-point costs measured by the benchmarks of docs/optimisation.md and docs/studies.md.
"""

from __future__ import annotations

import os
import shutil
from dataclasses import dataclass
from pathlib import Path

from ..errors import OutputError, ParameterError

SWEEP_SECONDS_PER_POINT = 40e-6
"""CPU time of the fast path per landscape point and K [s]: 0.25 s for the 81 x 81 grid with every
stage, the reflex columns and the coupled margin (docs/optimisation.md, "Benchmark")."""

STUDY_SECONDS_PER_POINT = 90e-6
"""CPU time of a study per point, all outputs, in-process [s]: 13.9 s for 401 x 401 points
(docs/studies.md, "Benchmark")."""

COUPLED_SECONDS_PER_POINT = 2.7e-3
"""Added per point by the coupled chain's SDPs [s] (:data:`spinectl.landscape.schema.ON_REQUEST`, docs/chain.md)."""

ATLAS_SECONDS_PER_DRAW = 53e-6
"""CPU time of an atlas draw on the fast path, joint by joint [s]: 73 728 draws of eight priors in 3.9 s
of CPU (``benchmarks/bench_atlas.py``, docs/atlas.md "Speed")."""

ATLAS_PER_DRAW_SECONDS = 29.3e-3
"""Time of an atlas draw solved as one model (a prior outside ``atlas.FAST``) [s] (same benchmark,
wall-clock at a load of 11: an upper bound of its CPU time)."""

ATLAS_CHAIN_SECONDS_PER_DRAW = 0.55e-3
"""CPU time added per atlas draw by the chain's stacked SDP [s] (same benchmark)."""

ATLAS_BYTES_PER_DRAW = 240
"""An atlas's files per draw [B]: its chunk in ``DIR/chunks`` and its row of ``draws.npz`` (measured:
the shipped atlas's five priors with the chain, N = 256: 94 B a draw in its chunk, 142 B in ``draws.npz``)."""

ATLAS_DESIGN_BYTES_PER_VALUE = 16
"""Peak memory of Saltelli's design per value, N (D + 2) x D of them [B]: SALib's array and its clipped copy
(tracemalloc peak of ``atlas.saltelli_unit``, N = 4096, five priors: 16.0 B)."""

ATLAS_DRAW_BYTES_PER_VALUE = 16
"""Peak memory of the draws' parameters per draw and column (D priors and the three of the position) [B]:
the array and a quantile's temporary (tracemalloc peak of ``atlas.draw``: 107 B a draw for 8 columns)."""

ATLAS_OUTPUT_BYTES_PER_DRAW = 200
"""Memory of a draw's outputs while the chunks are joined [B]: the chunks' and their concatenation's
(measured: 68 B a draw without the chain, 92 B with it, times two)."""

ATLAS_BOOTSTRAP_BYTES = 72
"""Peak memory of SALib's Sobol' analysis per base sample and bootstrap resample [B]: its resampled
indices and the outputs they pick (tracemalloc peak of ``atlas.sobol_indices``: 64-66 B)."""

DESIGN_SECONDS = 50e-3
"""CPU time of one design of ``spinectl design --delays`` (one delay at one lag, both criteria) [s]: 201 delays
took 9.9 s of CPU beyond the command's start, 101 delays at 2 lags 6.8 s (one BLAS thread, E = Lambda = 0)."""

PASSIVE_SECONDS = 12e-3
"""CPU time of one point of ``spinectl design --passive`` [s]: 201 stiffnesses took 2.5 s of CPU beyond the
command's start, from 0 to 80 as from 0 to 1e4 N m/rad (one BLAS thread, E = Lambda = 0)."""

SWEEP_MEMORY_PER_BYTE = 2.5
"""Peak memory of a sweep per byte of its answer: the chunks' columns, their concatenation and the
Dataset (tracemalloc peak of ``write_sweep`` over 101 x 101 x 4 K: 3.1 kB a point for 1.22 kB of answer)."""

NETCDF_BYTES_PER_BYTE = 1.25
"""A sweep's NetCDF file per byte of its answer in memory: statuses stored as fixed-width text
(measured: 1.51-1.52 kB a point for 1.22 kB)."""

STORE_BYTES_PER_BYTE = 0.5
"""A study store per byte of its outputs as stored, after Zarr's default compressor (measured: a
41 x 41 x 2 study of all outputs, 970 B a point on disk for 1941 B uncompressed)."""

WORKING_BYTES_PER_POINT = 16_000
"""Working memory of a stacked problem per point of its chunk [B] (tracemalloc peak of
:func:`spinectl.landscape.columns.point_columns`; :data:`spinectl.landscape.study.spec.MAX_CHUNK_POINTS`)."""

PROCESS_BYTES = 150e6
"""Resident memory of a worker process before its chunk [B]: the interpreter, numpy, scipy, the solver
(peak resident memory of an in-process study of two chunks: 155 MB)."""

NOTICE_SECONDS = 10.0
"""Work estimated to take at least this long [s] is announced (one line on stderr) before it starts."""


@dataclass(frozen=True)
class Estimate:
    """The cost of one piece of work, estimated before it starts.

    Attributes
    ----------
    what : str
        ``"sweep"``, ``"study"``, ``"atlas"`` or ``"design"``: the line's prefix.
    points : int
        Points to solve (every axis multiplied).
    memory : float
        Peak memory [B]; 0: not estimated (not stated by :meth:`line`).
    disk : float
        Bytes to be written [B]; 0: not stated by :meth:`line`.
    seconds : float
        CPU time on one core [s].
    field : str
        The field a memory refusal names (default: ``what``).
    fewer : str
        What a memory refusal advises to use fewer of.
    unit : str
        What ``points`` counts, in the lines: ``"points"``, an atlas's ``"draws"``, ``"designs"``.
    """

    what: str
    points: int
    memory: float
    disk: float
    seconds: float
    field: str = ""
    fewer: str = "points (a coarser grid, fewer K values or axis values)"
    unit: str = "points"

    @property
    def long(self) -> bool:
        """Whether the work deserves its :meth:`line` first (at least :data:`NOTICE_SECONDS`)."""
        return self.seconds >= NOTICE_SECONDS

    def line(self) -> str:
        """One line: ``"study: 100,000,000 points, about 97 GB on disk, 0.6 GB of memory, 2.5 h of CPU"``.

        Returns
        -------
        str
            Without a newline.
        """
        parts = [
            f"{size(self.disk)} on disk" if self.disk else "",
            f"{size(self.memory)} of memory" if self.memory else "",
        ]
        costs = ", ".join([p for p in parts if p] + [f"{duration(self.seconds)} of CPU (estimated)"])
        return f"{self.what}: {self.points:,} {self.unit}, about {costs}"


def design_estimate(designs: int, passive: bool = False) -> Estimate:
    """What a curve of ``spinectl design`` costs: its CPU time (it writes one figure at most, and holds little).

    Parameters
    ----------
    designs : int
        Delays times lags (``--delays``), or the stiffnesses of ``--passive``.
    passive : bool, optional
        ``--passive``'s points (:data:`PASSIVE_SECONDS` each) rather than designs (:data:`DESIGN_SECONDS`).

    Returns
    -------
    Estimate
        ``what`` ``"design"``; its :meth:`Estimate.line` reads ``design: 10,000 designs, about 8.3 min of CPU``.
    """
    each = PASSIVE_SECONDS if passive else DESIGN_SECONDS
    return Estimate("design", designs, 0.0, 0.0, designs * each, unit="points" if passive else "designs")


def atlas_memory(samples: int, priors: int, bootstrap: int) -> float:
    """Peak memory of an atlas's arrays in the main process [B], before its design is built.

    The stages follow one another, each holding what the next needs: the design (Saltelli's
    N (D + 2) x D probabilities), the draws' parameters made from it, the outputs joined beside
    them, and SALib's bootstrap of the Sobol' indices beside both. The workers' own memory
    (their chunks) is not in it.

    Parameters
    ----------
    samples : int
        Saltelli's base samples N.
    priors : int
        The priors D.
    bootstrap : int
        SALib's bootstrap resamples.

    Returns
    -------
    float
        [B].
    """
    draws = samples * (priors + 2)
    parameters = draws * (priors + 3) * ATLAS_DRAW_BYTES_PER_VALUE  # the priors' and E, Lambda, the angle
    design = draws * priors * ATLAS_DESIGN_BYTES_PER_VALUE
    stages = (
        design,
        design / 2 + parameters,  # the design (one copy) while the draws are made
        parameters / 2 + draws * ATLAS_OUTPUT_BYTES_PER_DRAW,
        parameters / 2 + draws * ATLAS_OUTPUT_BYTES_PER_DRAW / 2 + samples * bootstrap * ATLAS_BOOTSTRAP_BYTES,
    )
    return float(max(stages))


def size(nbytes: float) -> str:
    """A number of bytes for a reader: ``"8.1 MB"``, ``"97 GB"`` (decimal units).

    Parameters
    ----------
    nbytes : float
        Bytes [B].

    Returns
    -------
    str
        Two or three significant digits and the unit.
    """
    for unit, scale in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if nbytes >= scale:
            return f"{nbytes / scale:.2g} {unit}" if nbytes / scale < 10 else f"{nbytes / scale:.0f} {unit}"
    return f"{nbytes:.0f} B"


def duration(seconds: float) -> str:
    """A duration for a reader: ``"40 s"``, ``"12 min"``, ``"2.5 h"``, ``"3.1 days"``.

    Parameters
    ----------
    seconds : float
        [s].

    Returns
    -------
    str
        Two significant digits and the unit.
    """
    for unit, scale in (("days", 86400), ("h", 3600), ("min", 60)):
        if seconds >= scale:
            return f"{seconds / scale:.2g} {unit}"
    return f"{seconds:.2g} s"


def available_memory() -> float | None:
    """Memory available to new work [B]: ``MemAvailable`` of /proc/meminfo, else free physical pages.

    Returns
    -------
    float or None
        [B]; None where neither can be read (then nothing is refused for memory).
    """
    try:
        with open("/proc/meminfo", encoding="ascii") as file:
            for line in file:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024  # the kernel writes kB, meaning KiB
    except (OSError, ValueError, IndexError):
        pass
    try:
        return float(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return None


def free_disk(path: str | Path) -> float | None:
    """Free bytes on the file system where ``path`` would be written (its nearest existing folder).

    Parameters
    ----------
    path : str or Path
        A file or folder to be written.

    Returns
    -------
    float or None
        [B]; None if no folder of it can be asked (then nothing is refused for disk).
    """
    folder = Path(os.path.abspath(path)).parent
    while not folder.is_dir() and folder != folder.parent:
        folder = folder.parent
    try:
        return float(shutil.disk_usage(folder).free)
    except OSError:
        return None


def check(estimate: Estimate, path: str | Path | None = None) -> None:
    """Refuse in one line work whose estimate does not fit in the available memory or on the free disk.

    Parameters
    ----------
    estimate : Estimate
        The work.
    path : str or Path, optional
        Where it is written (its file system's free space is compared with ``estimate.disk``).

    Raises
    ------
    ParameterError
        The memory estimate exceeds the available memory (field ``estimate.what``).
    OutputError
        The disk estimate exceeds the free space at ``path``.
    """
    available = available_memory()  # looked up here, so that tests can give tiny limits
    if available is not None and estimate.memory > available:
        raise ParameterError(
            estimate.field or estimate.what,
            f"{estimate.points:,} {estimate.unit} need about {size(estimate.memory)} of memory, and "
            f"{size(available)} is available: use fewer {estimate.fewer}",
        )
    free = None if path is None else free_disk(path)
    if free is not None and estimate.disk > free:
        raise OutputError(
            f"cannot write {str(path)!r}: {estimate.points:,} points need about {size(estimate.disk)}, and its "
            f"file system has {size(free)} free: use fewer points or write elsewhere"
        )
