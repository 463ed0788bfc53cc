"""``spinectl reproduce``: the paper's study end to end (the main job, :func:`spinectl.paper.reproduce`)."""

from __future__ import annotations

from ._common import add_model_options


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
        description="Reproduce Figures 3, 4 and S1 of Wagner et al. (2012) (E and Lambda from 0 to 8 cm; "
        "1 mm steps by default, see --points) for K = 0 and 15 N m/rad and compare the paper's landmarks "
        "with spinectl's in report.md.",
    )
    parser.defer(_options)
    parser.set_defaults(func=run)


def _options(parser) -> None:
    """The options, their defaults from :mod:`spinectl.paper` (imported when the command is used)."""
    from ..paper import grid

    parser.add_argument("--out", default="results", metavar="DIR", help="output folder (default: results)")
    parser.add_argument(
        "--points",
        type=int,
        default=grid.PAPER_POINTS,
        help=f"grid points per axis (default {grid.PAPER_POINTS}: 1 mm)",
    )
    add_model_options(parser)


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
    from ..paper.reproduction import reproduce

    for path in reproduce(
        args.out, preset=args.preset, config=args.config, overrides=args.assignments, points=args.points
    ):
        print(path)
    return 0
