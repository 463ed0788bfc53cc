"""The main job: the paper's study end to end, written into one folder.

E and Lambda from 0 to 8 cm at 1 mm, K = 0 and K = 15 N m/rad with the
model's convention for K, and K = 15 with the other convention (for the
halving landmark; :mod:`spinectl.paper.grid`); the landscapes as NetCDF,
Figures 3, 4 and S1 as PNG, and a Markdown report with the paper's landmarks
beside spinectl's and a verdict for each (docs/reproduction.md). The folder is
checked before the work, everything is staged, and the staging folder replaces
the output folder as a whole at the end (:func:`spinectl.atomic.staged_directory`).
On Linux a worker process draws the figures while this one writes the landscapes
and the report (benchmarks/bench_reproduce.py).
"""

from __future__ import annotations

import math
import multiprocessing
import signal
import sys
import threading
import time
from concurrent import futures
from pathlib import Path

from ..atomic import atomic_write_text, check_distinct, check_folder, staged_directory
from ..errors import ParameterError
from ..landscape import netcdf, sweep
from ..model.config import DEFAULT_PRESET, apply_overrides, load_config
from ..model.params import Model
from ..model.source import origin, source_of
from . import assumptions, figures, grid, landmarks, report, verdicts

__all__ = ["DEFAULT_PRESET", "reproduce", "reproduce_model"]

LANDSCAPES = "landscapes.nc"
"""File name of the K = 0 and K = 15 N m/rad landscapes in the output folder."""

REPORT = "report.md"
"""File name of the landmarks report in the output folder."""

MIN_POINTS = 3
"""Fewest grid points per axis: the corners A-D and one point between them."""

MAX_POINTS = math.isqrt(sweep.MAX_GRID_POINTS)
"""Most grid points per axis: points x points is the limit of one sweep."""


def reproduce(
    out_dir,
    *,
    preset: str | None = None,
    config=None,
    overrides=(),
    points: int = grid.PAPER_POINTS,
    progress: bool | None = None,
) -> list[Path]:
    """Run the paper's study with a preset or a configuration file and write it into ``out_dir``.

    Parameters
    ----------
    out_dir : str or Path
        The output folder; replaced as a whole when the study has finished.
    preset : str, optional
        A built-in preset; default :data:`~spinectl.model.config.DEFAULT_PRESET` (the calibrated ``wagner2012``).
    config : str or Path, optional
        A TOML file with any subset of the parameters; without ``preset`` it keeps
        its own base preset.
    overrides : sequence of str
        ``SECTION.FIELD=VALUE`` assignments on top (:func:`spinectl.model.config.apply_overrides`).
    points : int
        Grid points per axis, :data:`MIN_POINTS` to :data:`MAX_POINTS` (81: the paper's 1 mm).
    progress : bool or None
        Progress bars on stderr (None: on a terminal only).

    Returns
    -------
    list of Path
        The files written: the landscapes, the figures and ``report.md``.

    Raises
    ------
    ParameterError
        ``points`` out of range.
    ConfigError
        An unknown preset or a bad configuration file.
    OutputError
        ``out_dir`` cannot take the output (:func:`spinectl.atomic.check_folder`), or its landscapes'
        names cannot reach the NetCDF library (:func:`spinectl.landscape.netcdf.check_name`), before any solve.
    """
    check_points(points)
    model = apply_overrides(load_config(config, preset=preset), overrides)
    check_distinct({"--out": [Path(out_dir, name) for name in output_names(model)]}, {"--config": config})
    src = source_of(model)  # not `origin`: that is the imported function reproduce_model uses
    calibrated = src.preset == verdicts.PRESET and not (src.config or src.overridden)
    return reproduce_model(model, out_dir, points=points, calibrated=calibrated, progress=progress)


def check_points(points: int) -> None:
    """Raise :class:`~spinectl.errors.ParameterError` unless ``points`` per axis is a grid the study can run.

    Parameters
    ----------
    points : int
        Grid points per axis.
    """
    if not MIN_POINTS <= points <= MAX_POINTS:
        raise ParameterError("--points", f"must be {MIN_POINTS} to {MAX_POINTS} per axis (got {points})")


def output_names(model: Model) -> tuple[str, ...]:
    """The files that the study of ``model`` writes into its folder, in the order :func:`reproduce_model` returns them.

    Parameters
    ----------
    model : Model
        Its passive-stiffness convention names the landscape of the other convention.

    Returns
    -------
    tuple of str
        The landscapes, the other convention's landscape, Figures 3, 4 (K = 0) and S1, 4
        (K = 15 N m/rad), the report.
    """
    other_name = _other_landscape(grid.other_convention(model))
    figure_names = [name for k in (0.0, grid.PAPER_STIFFNESS) for name in figures.figure_names(k)]
    return (LANDSCAPES, other_name, *figure_names, REPORT)


def _other_landscape(convention: str) -> str:
    """File name of the K = 15 N m/rad landscape with the passive-stiffness ``convention`` not the model's."""
    return f"landscape_K{grid.PAPER_STIFFNESS:g}_{convention}.nc"


def _own_files() -> tuple[str, ...]:
    """Every name a run of the study may write whose name varies with the model: an earlier run's goes
    (a stale landscape of the other convention never stays beside this run's)."""
    return tuple(_other_landscape(convention) for convention in grid.CONVENTIONS)


def reproduce_model(
    model: Model,
    out_dir,
    *,
    points: int = grid.PAPER_POINTS,
    calibrated: bool = False,
    progress: bool | None = None,
) -> list[Path]:
    """Run the study for a given model and write it into ``out_dir``.

    Parameters
    ----------
    model : Model
        Its passive stiffness is replaced by 0 and by :data:`spinectl.paper.grid.PAPER_STIFFNESS`.
    out_dir : str or Path
        The output folder; replaced as a whole when the study has finished.
    points : int
        Grid points per axis.
    calibrated : bool
        Whether they are the calibrated preset (the report says so).
    progress : bool or None
        Progress bars (None: on a terminal only).

    Returns
    -------
    list of Path
        The files written, inside ``out_dir``; the folder's other files stay, but those of an
        earlier run of the study that this one does not write (the landscape of another convention).

    Raises
    ------
    OutputError
        ``out_dir`` cannot take the output (:func:`spinectl.atomic.check_folder`), or its landscapes'
        names cannot reach the NetCDF library (:func:`spinectl.landscape.netcdf.check_name`), before any solve.
    """
    start = time.perf_counter()
    k15 = grid.PAPER_STIFFNESS
    other_convention = grid.other_convention(model)
    names = output_names(model)
    other_name = names[1]
    for name in (LANDSCAPES, other_name):  # as the user named them: the staging folder, in the message, is not
        netcdf.check_name(Path(out_dir) / name)
    check_folder(out_dir, names)  # before minutes of solving
    both, other = grid.paper_landscapes(model, points, progress)
    measured = landmarks.measure(landmarks.Landmarks(both.sel(K=0.0), both.sel(K=k15), other))
    with _beside() as beside, staged_directory(out_dir, names, replaces=_own_files()) as stage:
        drawing = beside.submit(_draw_figures, both, model.fibre.specific_tension, stage)  # beside the rest
        try:
            netcdf.save(both, stage / LANDSCAPES)
            netcdf.save(other, stage / other_name)
            run_facts = report.Run(
                preset=origin(model),  # the run covers K = 0 and 15: the report names both (not the model's own K)
                convention=model.passive.convention,
                other_convention=other_convention,
                points=points,
                seconds=time.perf_counter() - start,
                files=names,
                specific_tension=model.fibre.specific_tension,
                calibrated=calibrated,
                presets=assumptions.calibrated_measurements(assumptions.TABLE_POINTS),
                preset_points=assumptions.TABLE_POINTS,
            )
            atomic_write_text(stage / REPORT, report.render(measured, run_facts))  # UTF-8; a full disk: OutputError
        finally:
            futures.wait([drawing])  # the staging folder stays until the figures are in it, or have failed
        drawing.result()  # the drawing's error, if any, here
    return [Path(out_dir) / name for name in names]


def _draw_figures(both, specific_tension: float, stage: Path) -> None:
    """Figures 3, 4 and S1 of ``both`` drawn and saved into the folder ``stage``."""
    for name, figure in figures.figure_set(both, specific_tension).items():
        figures.save_figure(figure, stage / name)


def _beside():
    """Where the figures are drawn and saved, beside the landscapes' files and the report.

    One worker process forked from this one (it inherits every module imported, so it starts at once),
    on Linux; a job's error comes back as itself (:meth:`concurrent.futures.Future.result`). Elsewhere,
    and inside a worker process of another pool (which cannot have children), each job runs here at once:
    macOS's system libraries do not survive a fork, and Windows cannot fork. A process running other
    Python threads (a notebook's kernel, an explorer, a threaded Dask worker) draws here too: a fork copies
    only the calling thread, and a lock another thread held would stay locked in the child.
    """
    if not _can_fork():
        return _Here()
    context = multiprocessing.get_context("fork")
    return futures.ProcessPoolExecutor(1, mp_context=context, initializer=_ignore_interrupts)


def _can_fork() -> bool:
    """Whether :func:`_beside` forks: on Linux, outside a daemon worker, with no other Python thread."""
    return sys.platform == "linux" and not multiprocessing.current_process().daemon and threading.active_count() == 1


def _ignore_interrupts() -> None:
    """Ctrl-C is this process's to handle: the worker ignores it, and ends when the pool is shut down."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


class _Here(futures.Executor):
    """An executor that runs each job in this process when it is submitted."""

    def submit(self, fn, /, *args, **kwargs) -> futures.Future:
        future = futures.Future()
        try:
            future.set_result(fn(*args, **kwargs))
        except Exception as error:
            future.set_exception(error)
        return future
