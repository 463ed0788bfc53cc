"""``spinectl atlas``: the population stability atlas of a cohort's priors (docs/atlas.md)."""

from __future__ import annotations

from ._common import add_model_options, add_scheduler_options, emit_json, finite_float, scheduler_options


def register(sub) -> None:
    """Add the ``atlas`` sub-command to the ``spinectl`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command action of :func:`spinectl.cli.build_parser`.
    """
    parser = sub.add_parser(
        "atlas",
        help="probabilities of the stability verdicts and Sobol' indices over a cohort's priors",
        description="Draw the priors of PRIORS.toml (docs/atlas.md) in Saltelli's design, solve the "
        "joint-by-joint optimum, the exact delay margin and the chain's least local stiffness at every "
        "draw, and report the probability of each verdict (Wilson intervals) and the first- and "
        "total-order Sobol' indices (SALib, bootstrap intervals). The chunks of draws run as spinectl study's "
        "do, but in this process by default (a local cluster pays only where cores are free): on a local Dask "
        "cluster with --workers N, an existing one (--scheduler tcp://...), each saved in --out as it finishes: "
        "a second run resumes from them. "
        "The model is --preset/--config if given, else the file's [atlas] model, else the default preset; "
        "--set goes on top.",
    )
    parser.add_argument("priors", metavar="PRIORS.toml", help="the atlas file: [atlas] and [[prior]] tables")
    parser.add_argument("--out", required=True, metavar="DIR", help="folder for chunks, atlas.json, report.md, figure")
    parser.add_argument(
        "--lordosis-angle",
        type=finite_float("--lordosis-angle"),
        metavar="DEG",
        help="the lordosis angle [deg] where no prior varies it (default: [atlas] lordosis_m, 4 cm)",
    )
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    add_scheduler_options(
        parser,
        default="in this process; with --workers N a local cluster",
        workers="none: the draws run in this process; N starts a local Dask cluster of N processes",
    )
    add_model_options(parser)
    parser.set_defaults(func=run)


def run(args) -> int:
    """Run ``spinectl atlas``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments (see :func:`register`).

    Returns
    -------
    int
        Exit code 0.
    """
    from ..landscape import atlas  # SALib, scipy and the solvers only for this command
    from ..model.config import load_config

    # --preset or --config replaces the file's [atlas] model; --set goes over whichever it is
    model = load_config(args.config, preset=args.preset) if args.preset or args.config else None
    result = atlas.atlas_file(
        args.priors,
        args.out,
        lordosis_angle=args.lordosis_angle,
        model=model,
        assignments=args.assignments,
        config=args.config,
        **scheduler_options(args),
    )
    if args.json:
        emit_json(result.to_dict())
    else:
        print(result.table())
    return 0
