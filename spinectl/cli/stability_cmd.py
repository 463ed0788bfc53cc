"""``spinectl stability``: self-stability and counter torque of every segment."""

from __future__ import annotations

from ._common import (
    add_mass_option,
    add_model_options,
    add_position_options,
    body_aliases,
    check_position,
    emit_json,
    finite_float,
    float_list,
    load_model,
    note_pcsa_slip,
    pcsa_option,
    require,
    sagittal_load,
)


def register(sub) -> None:
    """Add the ``stability`` sub-command to the ``spinectl`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command action of :func:`spinectl.cli.build_parser`.
    """
    parser = sub.add_parser(
        "stability",
        help="eigenvalues, self-stability and counter torque of each segment",
        description="Linearise every lumbar segment about the upright posture and report its "
        "stiffness, damping, eigenvalues (paper, eq. 1), self-stability and local counter torque: each CoR alone, "
        "the others fixed (the paper's criterion); beside it the chain's verdict, all CoRs free (its modes and "
        "their time constants; --coupled for the full chain report).",
    )
    add_position_options(parser)
    parser.add_argument(
        "--pcsa",
        type=float_list("--pcsa"),
        metavar="CM2,...",
        help="PCSA [cm^2]: one value per pair (each muscle of the pair) or one per muscle "
        "(default: the minimum stabilising PCSA, the optimiser's chosen activation)",
    )
    parser.add_argument(
        "--K",
        type=finite_float("--K"),
        help="passive stiffness K [N m/rad] (alias of --set passive.stiffness=K; not both)",
    )
    add_mass_option(parser)
    parser.add_argument(
        "--coupled",
        action="store_true",
        help="free all CoRs at once: the chain's stiffness, damping and mass matrices, its static margin, "
        "dynamic eigenvalues and least local stiffness (docs/chain.md)",
    )
    parser.add_argument(
        "--load",
        type=sagittal_load,
        action="append",
        default=[],
        metavar="FX,FY",
        help="with --coupled: a force [N] held at the point mass, fixed in the ground (x ventral, y up; e.g. "
        "0,-200 for about 20 kg held), in the chain's K and its least local stiffness; repeatable (docs/chain.md)",
    )
    parser.add_argument(
        "--contributions",
        action="store_true",
        help="also each pair's part of each CoR's stiffness and of the chain's least eigenvalue of -K (which pair "
        "stabilises each CoR and the chain), and the chain without each pair (docs/contributions.md)",
    )
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    add_model_options(parser)
    parser.set_defaults(func=run)


def run(args) -> int:
    """Run ``spinectl stability``: print the table, or JSON with ``--json``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments: ``E``, ``Lambda`` [m], ``pcsa`` [cm^2], ``K``, ``coupled``, ``json`` and the
        model options.

    Returns
    -------
    int
        Exit code 0.
    """
    from ..model import clinical
    from ..optimise.stabilising import NoStabilisingActivation, stability_at

    model = load_model(args, body_aliases(args))
    check_position(model, args)
    given = args.pcsa is not None  # else the minimum stabilising PCSA
    require(args.coupled or not args.load, "--load", "goes with --coupled (the chain's K; each segment alone: not yet)")
    analysis, loaded = stability_at, {}
    if args.coupled:  # only here: the chain's semidefinite programs import cvxpy
        from ..optimise.coupled import coupled_stability_at as analysis

        loaded = {"loads": args.load}
    try:
        result = analysis(model, args.E, args.Lambda, pcsa_option(args.pcsa), slip_check=False, **loaded)
    except NoStabilisingActivation as exc:  # the library names its argument; the user types the option
        raise NoStabilisingActivation(str(exc).replace("(argument pcsa, [m^2])", "with --pcsa [cm2]")) from None
    source = "given" if given else "min_pcsa"
    pairs = _pair_contributions(model, args, result.pcsa, loaded.get("loads", ())) if args.contributions else None
    if args.json:
        doc = clinical.with_lordosis_angle(result.to_dict(model, pcsa_source=source), model)
        emit_json(doc if pairs is None else {**doc, "contributions": pairs.to_dict()})
    else:
        print(result.table(model, pcsa_source=source))
        if pairs is not None:
            print(pairs.table())
    note_pcsa_slip(args.pcsa)
    return 0


def _pair_contributions(model, args, pcsa, loads=()):
    """--contributions: each pair's part at the analysed PCSA (the point's, computed or checked: any size)."""
    from ..model.contributions import pair_contributions
    from ..model.operating_point import OperatingPoint

    return pair_contributions(OperatingPoint(model, args.E, args.Lambda, pcsa, slip_check=False, loads=loads))
