"""``spinectl plot``: Figures 3, 4 and S1 from a sweep's NetCDF file; two landscapes compared; a study's slices."""

from __future__ import annotations

from pathlib import Path

from ._common import add_dpi_option, finite_float, input_name


def register(sub) -> None:
    """Add the ``plot`` sub-command to the ``spinectl`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command action of :func:`spinectl.cli.build_parser`.
    """
    parser = sub.add_parser(
        "plot",
        help="draw Figures 3, 4 (and S1 for K > 0) from a sweep's NetCDF file",
        description="Filled contours of the minimum PCSA (Fig. 3; Fig. S1 for K > 0) and of ||CT|| "
        "(Fig. 4, with the +-30 N m limit), on any grid: positions A-D where they lie inside it, the "
        "grid's other corners by their coordinates, the ridge Lambda = 1.7 E and the paper's optimum; "
        "for a 'sweep --coupled' also the ratio coupled / per segment of the global PCSA; "
        "as PNG, PDF or SVG files.",
    )
    parser.defer(_options)
    parser.set_defaults(func=run)


def _options(parser) -> None:
    """The options, their choices and defaults from :mod:`spinectl.paper.figures` (matplotlib)."""
    from ..paper import figures

    parser.add_argument(
        "results",
        metavar="RESULTS",
        type=input_name,
        help="a NetCDF file written by 'spinectl sweep' or 'reproduce', or a study's Zarr store (a folder: "
        "each E x Lambda slice's minimum PCSA and ||CT||)",
    )
    parser.add_argument(
        "--vs",
        metavar="OTHER.nc",
        type=input_name,
        help="compare with this landscape on the same grid: difference and ratio maps (RESULTS minus, over, OTHER)",
    )
    parser.add_argument("--out", required=True, metavar="DIR", help="folder for the figure files")
    parser.add_argument("--format", choices=figures.FORMATS, default="png", help="file format (default png)")
    add_dpi_option(parser)
    scale = parser.add_argument_group("colour scale of the minimum-PCSA figures")
    scale.add_argument("--vmin", type=finite_float("--vmin"), help="lower end [cm^2] (default: the data's)")
    scale.add_argument("--vmax", type=finite_float("--vmax"), help="upper end [cm^2] (default: the data's)")
    scale.add_argument(
        "--shared-scale", action="store_true", help="Figures 3 and S1 on one scale, the range over every K"
    )
    extra = parser.add_argument_group("extra figures")
    extra.add_argument(
        "--ratio", action="store_true", help="also the minimum PCSA at K > 0 over K = 0 (the paper's halving)"
    )
    parser.add_argument(
        "--lordosis-axis",
        choices=figures.LORDOSIS_AXES,
        default="lambda",
        help="the landscapes' lordosis axis: Lambda [cm] or the lordosis angle [deg] (docs/atlas.md)",
    )
    extra.add_argument(
        "--insets", action="store_true", help="the model drawn at the grid's corners around Figures 3 and S1"
    )


def run(args) -> int:
    """Run ``spinectl plot``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments (see :func:`register`).

    Returns
    -------
    int
        Exit code 0.
    """
    if args.vs:
        from ..paper.comparison import draw_comparison

        written = draw_comparison(args.results, args.vs, args.out, args.format, args.dpi)
    elif Path(args.results).is_dir():
        from ..paper.slices import draw_study

        written = draw_study(args.results, args.out, args.format, args.dpi)
    else:
        written = _draw_figures(args)
    for path in written:
        print(path)
    return 0


def _draw_figures(args):
    from ..landscape import netcdf
    from ..paper import figures

    options = figures.FigureOptions(
        format=args.format,
        dpi=args.dpi,
        vmin=args.vmin,
        vmax=args.vmax,
        shared_scale=args.shared_scale,
        ratio=args.ratio,
        insets=args.insets,
        lordosis_axis=args.lordosis_axis,
    )
    return figures.draw_figures(netcdf.load(args.results), args.out, options=options)
