"""``spinectl export``: the paper's model and its solution as an MJCF (MuJoCo) or ``.osim`` (OpenSim) file."""

from __future__ import annotations

from ..units import position_text
from ._common import add_model_options, add_position_options, check_position, float_list, load_model, pcsa_option


def register(sub) -> None:
    """Add the ``export`` sub-command to the ``spinectl`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command action of :func:`spinectl.cli.build_parser`.
    """
    parser = sub.add_parser(
        "export",
        help="write the paper's model and its solution for MuJoCo (MJCF) or OpenSim (.osim)",
        description="Write the paper's chain at (E, Lambda): pin joints at the CoRs, every fibre as a muscle "
        "with its attachments, the masses, the joints' stiffness and the per-segment optimum's activation "
        "(docs/interchange.md).",
    )
    add_position_options(parser)
    parser.add_argument("--format", choices=("mjcf", "osim"), help="file format (default: from the suffix of --out)")
    parser.add_argument(
        "--pcsa",
        type=float_list("--pcsa"),
        metavar="CM2,...",
        help="PCSA [cm^2], one per pair or per muscle (default: the per-segment optimum)",
    )
    parser.add_argument(
        "--with-local-stiffness",
        action="store_true",
        help="add the chain's least local stiffness as joint springs (docs/chain.md)",
    )
    parser.add_argument(
        "--osim-muscle",
        choices=("millard", "paper"),
        default="millard",
        help="OpenSim's fibres: Millard's muscle (re-imported by spinectl anatomy) or the paper's curves "
        "on a RigidTendonMuscle, with which OpenSim's linearisation is the chain's (default: millard)",
    )
    parser.add_argument("--out", required=True, metavar="FILE", help="the file to write (atomically)")
    add_model_options(parser)
    parser.set_defaults(func=run)


def run(args) -> int:
    """Run ``spinectl export``: write the file and print one line saying what it holds.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments: ``E``, ``Lambda`` [m], ``format``, ``pcsa`` [cm^2], ``with_local_stiffness``,
        ``osim_muscle``, ``out`` and the model options.

    Returns
    -------
    int
        Exit code 0.
    """
    from ..anatomy.interchange import check_output, export_model, export_verdicts

    fmt = check_output(args.out, args.format, {"--config": args.config})  # before the model and its solve
    model = load_model(args)
    check_position(model, args)
    solution = export_model(
        model,
        args.E,
        args.Lambda,
        args.out,
        fmt,
        pcsa=pcsa_option(args.pcsa),
        with_local_stiffness=args.with_local_stiffness,
        inputs={"--config": args.config},
        osim_muscle=args.osim_muscle,
    )
    written = args.out
    if fmt == "osim":
        from ..anatomy.export_osim import controls_path

        written = f"{args.out} and {controls_path(args.out)}"
    print(f"wrote {written} ({fmt}): {position_text(args.E, args.Lambda)}")
    for line in export_verdicts(solution, args.out, fmt, args.osim_muscle):
        print(line)
    return 0
