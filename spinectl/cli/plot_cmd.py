"""``spinectl plot``: the paper's Figures 3, 4 and S1 from a sweep's NetCDF file."""

from __future__ import annotations

from ..landscape import netcdf
from ..paper import figures


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
        "(Fig. 4, with the +-30 N m limit), positions A-D marked, as PNG files.",
    )
    parser.add_argument("results", metavar="RESULTS.nc", help="a file written by 'spinectl sweep' or 'reproduce'")
    parser.add_argument("--out", required=True, metavar="DIR", help="folder for the PNG files")
    parser.set_defaults(func=run)


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
    for path in figures.draw_figures(netcdf.load(args.results), args.out):
        print(path)
    return 0
