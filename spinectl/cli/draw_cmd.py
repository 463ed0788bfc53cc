"""``spinectl draw``: the model drawn at one (E, Lambda), as PNG, PDF or SVG."""

from __future__ import annotations

from ..atomic import check_distinct
from ._common import (
    add_dpi_option,
    add_model_options,
    add_position_options,
    check_position,
    float_list,
    load_model,
    note_pcsa_slip,
    pcsa_option,
)


def register(sub) -> None:
    """Add the ``draw`` sub-command to the ``spinectl`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command action of :func:`spinectl.cli.build_parser`.
    """
    parser = sub.add_parser(
        "draw",
        help="draw the model at one E and Lambda (spine, CoRs, fibres, point mass)",
        description="The planar model to scale in cm: the spine line through P1, P3, P2 with the "
        "centres of rotation and vertebrae, the symmetry axis, E and Lambda dimensioned, every muscle "
        "fibre (width proportional to its muscle's PCSA), the point mass and its line of gravity, and "
        "optionally the counter torque at each CoR.",
    )
    parser.defer(_options)
    parser.set_defaults(func=run)


def _options(parser) -> None:
    """The options; ``--dpi`` takes its default from :mod:`spinectl.paper.figures` (matplotlib)."""
    add_position_options(parser)
    activation = parser.add_mutually_exclusive_group()
    activation.add_argument(
        "--pcsa",
        type=float_list("--pcsa"),
        metavar="CM2,...",
        help="PCSA [cm^2], one value per pair or one per muscle (default: the optimum of solve_point)",
    )
    activation.add_argument("--geometry-only", action="store_true", help="no activation: every fibre drawn alike")
    parser.add_argument(
        "--counter-torque", action="store_true", help="arrows for the counter torques CT_k [N m] at the CoRs"
    )
    parser.add_argument("--out", required=True, metavar="FILE", help="the figure: .png, .pdf or .svg")
    add_dpi_option(parser)
    add_model_options(parser)


def run(args) -> int:
    """Run ``spinectl draw``: draw, save, print the file's path.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments: ``E``, ``Lambda`` [m], ``pcsa`` [cm^2], ``geometry_only``,
        ``counter_torque``, ``out``, ``dpi`` and the model options.

    Returns
    -------
    int
        Exit code 0.
    """
    from ..paper import drawing, figures

    check_distinct({"--out": args.out}, {"--config": args.config})  # before the work: never the input
    model = load_model(args)
    check_position(model, args)
    pcsa = None if args.geometry_only else ("optimum" if args.pcsa is None else pcsa_option(args.pcsa))
    fig = drawing.draw_model(
        model, args.E, args.Lambda, pcsa=pcsa, counter_torque=args.counter_torque, slip_check=False
    )
    print(figures.save_figure(fig, args.out, args.dpi))
    note_pcsa_slip(None if args.geometry_only else args.pcsa)
    return 0
