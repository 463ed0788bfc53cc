"""``spinectl design``: the least co-contraction and local stiffness for which a reflex delay is stable."""

from __future__ import annotations

from ._common import (
    add_model_options,
    add_position_options,
    check_position,
    emit_json,
    finite_float,
    load_model,
    with_lordosis_angle,
)


def register(sub) -> None:
    """Add the ``design`` sub-command to the ``spinectl`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command action of :func:`spinectl.cli.build_parser`.
    """
    parser = sub.add_parser(
        "design",
        help="the least co-contraction (joint by joint) and local stiffness (chain) a reflex delay needs",
        description="Answer the design question at one (E, Lambda) and delay: joint by joint (each CoR alone, the "
        "others fixed; the paper's criterion), the least activation of the minimum stabilising PCSA for which "
        "every segment's exact delay margin with the lag is at least the delay; for the chain (all CoRs free), "
        "at the reflex's activation, the least local stiffness for which the chain under the delayed reflex is "
        "stable at the delay, with its certificate. A delay no design meets is an answer (status infeasible, "
        "with the largest delay met). See docs/reflex.md.",
    )
    add_position_options(parser)
    parser.add_argument("--delay", type=finite_float("--delay"), help="reflex delay tau [s] (default: config, 0.1)")
    parser.add_argument(
        "--activation-lag",
        type=finite_float("--activation-lag"),
        metavar="T_A",
        help="time constant T_a [s] of the force generation after the delay (default: config, 0.05)",
    )
    parser.add_argument(
        "--activation",
        type=finite_float("--activation"),
        help="the chain's global activation, a fraction of the minimum stabilising PCSA (default: config, 0.5)",
    )
    parser.add_argument("--kp", type=finite_float("--kp"), help="proportional gain [N m/rad] (default: the rule)")
    parser.add_argument("--kd", type=finite_float("--kd"), help="derivative gain [N m s/rad] (default: the rule)")
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    add_model_options(parser)
    parser.set_defaults(func=run)


OVERRIDES = (
    ("delay", "reflex.delay"),
    ("activation_lag", "reflex.activation_time_constant"),
    ("activation", "reflex.activation"),
)
"""Options that are aliases of ``--set reflex.FIELD=VALUE``."""


def run(args) -> int:
    """Run ``spinectl design``: print the table, or JSON with ``--json``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments: ``E``, ``Lambda`` [m], the reflex options, ``json`` and the model options.

    Returns
    -------
    int
        Exit code 0 (also for a delay no design meets: status 'infeasible').
    """
    from .._validate import non_negative
    from ..reflex.design import design

    aliases = {dotted: ("--" + option.replace("_", "-"), getattr(args, option)) for option, dotted in OVERRIDES}
    model = load_model(args, aliases)
    check_position(model, args)
    kp = None if args.kp is None else non_negative("--kp", args.kp)
    kd = None if args.kd is None else non_negative("--kd", args.kd)
    result = design(model, args.E, args.Lambda, kp=kp, kd=kd)
    if args.json:
        emit_json(with_lordosis_angle(result.to_dict(), model))
    else:
        print(result.table())
    return 0
