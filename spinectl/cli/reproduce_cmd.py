"""``spinectl reproduce``: the paper's study end to end (the main job).

E and Lambda from 0 to 8 cm at 1 mm, K = 0 and K = 15 N m/rad with the
model's convention for K, and K = 15 with the other convention (for the
halving landmark); the landscapes as NetCDF, Figures 3, 4 and S1 as PNG, and
a Markdown report with the paper's landmarks beside spinectl's. Everything is
staged and moved into ``--out`` at the end (:func:`spinectl.io.staged_directory`).
"""

from __future__ import annotations

import math
import time
from pathlib import Path

from .. import calibration, landmarks, plotting, report, reproduction, sweep
from ..calibration import PAPER_POINTS
from ..errors import ParameterError
from ..io import staged_directory
from ..params import Model
from ._common import add_model_options, load_model

DEFAULT_PRESET = reproduction.PRESET
"""The calibrated preset (docs/reproduction.md): what ``reproduce`` runs unless told otherwise."""

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
    add_model_options(parser, default_preset=DEFAULT_PRESET)
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
    largest = math.isqrt(sweep.MAX_GRID_POINTS)  # points x points, the limit of one sweep
    if not 3 <= args.points <= largest:
        raise ParameterError("--points", f"must be 3 to {largest} per axis (got {args.points})")
    preset = args.preset or DEFAULT_PRESET
    source = f"config file {args.config}" if args.config else f"preset `{preset}`"
    calibrated = args.config is None and preset == reproduction.PRESET
    model = load_model(args, default_preset=DEFAULT_PRESET)
    paths = reproduce(model, args.out, points=args.points, source=source, calibrated=calibrated)
    for path in paths:
        print(path)
    return 0


def reproduce(
    model: Model, out_dir, *, points: int = PAPER_POINTS, source: str = "", calibrated: bool = False, progress=None
) -> list[Path]:
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
    calibrated : bool
        Whether they are the calibrated preset (the report says so).
    progress : bool or None
        Progress bars (None: on a terminal only).
    """
    start = time.perf_counter()
    k15 = landmarks.PAPER_STIFFNESS
    both, other = calibration.paper_landscapes(model, points, progress)
    other_convention = calibration.other_convention(model)
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
            calibrated=calibrated,
        )
        (stage / "report.md").write_text(report.render(measured, run_facts))
    return [Path(out_dir) / name for name in names]
