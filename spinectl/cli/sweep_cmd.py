"""``spinectl sweep``: minimum PCSA and counter torques on an E x Lambda grid, to NetCDF."""

from __future__ import annotations

import time

import numpy as np

from ..atomic import check_writable
from ..landscape import netcdf, sweep
from ..model.config import set_parameter
from ._common import add_model_options, float_list, load_model

DEFAULT_AXIS = "0:0.08:81"
"""The paper's grid: 0 to 8 cm in 1 mm steps (design page, What the paper reports)."""


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
    parser.add_argument("--E", default=DEFAULT_AXIS, metavar="START:STOP:NUM", help="eccentricity axis [m]")
    parser.add_argument("--Lambda", default=DEFAULT_AXIS, metavar="START:STOP:NUM", help="lordosis axis [m]")
    parser.add_argument(
        "--K",
        type=float_list("--K"),
        metavar="NMRAD,...",
        help="passive stiffness K [N m/rad]; several values give a K dimension (default: the model's)",
    )
    parser.add_argument("--method", choices=sweep.METHODS, default="fast", help="solution path (default: fast)")
    parser.add_argument("--chunk-size", type=int, default=sweep.DEFAULT_CHUNK, help="grid points per stacked solve")
    parser.add_argument("--out", required=True, metavar="FILE.nc", help="NetCDF file to write (atomically)")
    add_model_options(parser)
    parser.set_defaults(func=run)


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
    model = load_model(args)
    e_axis, l_axis = sweep.parse_grid(args.E, "--E"), sweep.parse_grid(args.Lambda, "--Lambda")
    options = {"method": args.method, "chunk_size": args.chunk_size}
    check_writable(args.out)  # before the solves
    start = time.perf_counter()
    stiffnesses = args.K or [model.passive.stiffness]
    if len(stiffnesses) == 1:
        model = set_parameter(model, "passive.stiffness", stiffnesses[0])
        dataset = sweep.sweep(model, e_axis, l_axis, **options)
    else:
        dataset = sweep.stiffness_sweep(model, stiffnesses, e_axis, l_axis, **options)
    netcdf.save(dataset, args.out)
    print(summary(dataset, args.out, time.perf_counter() - start))
    return 0


def summary(dataset, path, seconds: float) -> str:
    """One line: what was written, how many points solved, the ranges of both landscapes.

    Parameters
    ----------
    dataset : xarray.Dataset
        The sweep.
    path : str or Path
        Where it was written.
    seconds : float
        Wall time [s].
    """
    status = dataset["status"].values
    pcsa, torque = dataset["min_pcsa_cm2"].values, dataset["counter_torque_norm_Nm"].values
    ok = np.isfinite(pcsa)
    ranges = ""
    if ok.any():
        ranges = (
            f"; min PCSA {np.nanmin(pcsa):.1f}-{np.nanmax(pcsa):.1f} cm2, "
            f"||CT|| {np.nanmin(torque):.1f}-{np.nanmax(torque):.1f} N m"
        )
    return (
        f"wrote {path}: {status.size} points ({int(ok.sum())} solved, {int((~ok).sum())} infeasible or failed)"
        f"{ranges} in {seconds:.1f} s"
    )
