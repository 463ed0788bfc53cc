"""``spinectl sweep``: minimum PCSA and counter torques on an E x Lambda grid, to NetCDF."""

from __future__ import annotations

import sys
import time

from ..atomic import check_distinct
from ._common import (
    add_mass_option,
    add_model_options,
    body_aliases,
    float_list,
    load_model,
    lordosis_grid,
    refuse_set_twice,
)

DEFAULT_AXIS = "0:0.08:81"
"""The paper's grid: 0 to 8 cm in 1 mm steps (paper, Methods)."""


def register(sub) -> None:
    """Add the ``sweep`` sub-command to the ``spinectl`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command action of :func:`spinectl.cli.build_parser`.
    """
    parser = sub.add_parser(
        "sweep",
        help="minimum PCSA and counter torques on an E x Lambda grid (NetCDF)",
        description="Solve the minimum-PCSA LP and the least-counter-torque problem at every grid point "
        "(paper, Figures 3 and 4) and write an xarray Dataset as NetCDF.",
    )
    parser.defer(_options)
    parser.set_defaults(func=run)


def _options(parser) -> None:
    """The options, their choices and defaults from :mod:`spinectl.landscape.sweep` (xarray)."""
    from ..landscape import sweep

    parser.add_argument("--E", default=DEFAULT_AXIS, metavar="START:STOP:NUM", help="eccentricity axis [m]")
    parser.add_argument("--Lambda", metavar="START:STOP:NUM", help=f"lordosis axis [m] (default {DEFAULT_AXIS})")
    parser.add_argument(
        "--lordosis-angle",
        metavar="START:STOP:NUM",
        help="lordosis axis as the angle between the spine line's end tangents [deg], instead of --Lambda "
        "(even in degrees; docs/atlas.md)",
    )
    parser.add_argument(
        "--K",
        type=float_list("--K"),
        metavar="NMRAD,...",
        help="passive stiffness K [N m/rad]; several values give a K dimension (default: the model's)",
    )
    add_mass_option(parser)
    parser.add_argument("--method", choices=sweep.METHODS, default="fast", help="solution path (default: fast)")
    parser.add_argument("--chunk-size", type=int, default=sweep.DEFAULT_CHUNK, help="grid points per stacked solve")
    parser.add_argument(
        "--coupled", action="store_true", help="also the coupled chain's least local stiffness and joint optimum (SDPs)"
    )
    parser.add_argument(
        "--out", required=True, metavar="FILE.nc", help="NetCDF file to write (atomically; must end in .nc)"
    )
    add_model_options(parser)


def run(args) -> int:
    """Run ``spinectl sweep``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments (see :func:`register`).

    Returns
    -------
    int
        Exit code 0.
    """
    from ..landscape import sweep

    check_distinct({"--out": args.out}, {"--config": args.config})
    if args.K:
        refuse_set_twice(args.assignments or [], {"passive.stiffness": "--K"})
    model = load_model(args, body_aliases(args))
    geometry = model.geometry
    e_axis = sweep.parse_grid(args.E, "--E", geometry.eccentricity_range)
    l_axis = lordosis_grid(model, args.Lambda, args.lordosis_angle, DEFAULT_AXIS)
    options = {"stiffnesses": args.K, "method": args.method, "chunk_size": args.chunk_size, "coupled": args.coupled}
    options["notify"] = lambda line: print(line, file=sys.stderr)
    start = time.perf_counter()
    dataset = sweep.write_sweep(model, e_axis, l_axis, args.out, **options)
    print(f"wrote {args.out}: {sweep.describe(dataset)} in {time.perf_counter() - start:.1f} s")
    return 0
