"""``spinectl reproduce``: the paper's study end to end (the main job).

E and Lambda from 0 to 8 cm at 1 mm, K = 0 and K = 15 N m/rad with the
model's convention for K, and K = 15 with the other convention (for the
halving landmark); the landscapes as NetCDF, Figures 3, 4 and S1 as PNG, and
a Markdown report with the paper's landmarks beside spinectl's. Everything is
staged and moved into ``--out`` at the end (:func:`spinectl.io.staged_directory`).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from .. import landmarks, plotting, report, sweep
from ..config import set_parameter
from ..errors import ParameterError
from ..io import staged_directory
from ..params import Model
from ._common import add_model_options, load_model

PAPER_RANGE = (0.0, 0.08)
"""E and Lambda [m] of the paper's grid (paper, Methods)."""

PAPER_POINTS = 81
"""Grid points per axis: 1 mm steps (paper, Methods; design page)."""

CONVENTIONS = ("physical", "paper")

LANDSCAPES = "landscapes.nc"


def register(sub) -> None:
    """Add the ``reproduce`` sub-command to the ``spinectl`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command action of :func:`spinectl.cli.build_parser`.
    """
    parser = sub.add_parser(
        "reproduce",
        help="run the paper's study: landscapes, figures and a landmark report",
        description="Reproduce Figures 3, 4 and S1 of Wagner et al. (2012) at 1 mm resolution for "
        "K = 0 and 15 N m/rad and compare the paper's landmarks with spinectl's in report.md.",
    )
    parser.add_argument("--out", default="results", metavar="DIR", help="output folder (default: results)")
    parser.add_argument(
        "--points", type=int, default=PAPER_POINTS, help=f"grid points per axis (default {PAPER_POINTS}: 1 mm)"
    )
    add_model_options(parser)
    parser.set_defaults(func=run)


def run(args) -> int:
    """Run ``spinectl reproduce``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments (see :func:`register`).

    Returns
    -------
    int
        Exit code 0.
    """
    if args.points < 3:
        raise ParameterError("--points", f"must be >= 3 (got {args.points})")
    source = f"config file {args.config}" if args.config else f"preset `{args.preset or 'default'}`"
    paths = reproduce(load_model(args), args.out, points=args.points, source=source)
    for path in paths:
        print(path)
    return 0


def reproduce(model: Model, out_dir, *, points: int = PAPER_POINTS, source: str = "", progress=None) -> list[Path]:
    """Run the study and write it into ``out_dir``; return the files written.

    Parameters
    ----------
    model : Model
        Its passive stiffness is replaced by 0 and by :data:`spinectl.landmarks.PAPER_STIFFNESS`.
    out_dir : str or Path
    points : int
        Grid points per axis.
    source : str
        Where the parameters came from, for the report.
    progress : bool or None
        Progress bars (None: on a terminal only).
    """
    start = time.perf_counter()
    axis = np.linspace(*PAPER_RANGE, points)
    k15 = landmarks.PAPER_STIFFNESS
    both = sweep.stiffness_sweep(model, [0.0, k15], axis, axis, progress=progress)
    other_convention = next(c for c in CONVENTIONS if c != model.passive.convention)
    other_model = set_parameter(set_parameter(model, "passive.convention", other_convention), "passive.stiffness", k15)
    other = sweep.sweep(other_model, axis, axis, progress=progress)
    measured = landmarks.measure(landmarks.Landmarks(both.sel(K=0.0), both.sel(K=k15), other))
    other_name = f"landscape_K{k15:g}_{other_convention}.nc"
    with staged_directory(out_dir) as stage:
        sweep.save(both, stage / LANDSCAPES)
        sweep.save(other, stage / other_name)
        figures = plotting.draw_figures(both, stage, model.fibre.specific_tension)
        names = (LANDSCAPES, other_name, *(f.name for f in figures), "report.md")
        run_facts = report.Run(
            preset=source or "the given model",
            convention=model.passive.convention,
            other_convention=other_convention,
            points=points,
            seconds=time.perf_counter() - start,
            files=names,
            specific_tension=model.fibre.specific_tension,
        )
        (stage / "report.md").write_text(report.render(measured, run_facts))
    return [Path(out_dir) / name for name in names]
