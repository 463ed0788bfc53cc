"""``spinectl margins``: delayed-reflex margins of every segment."""

from __future__ import annotations

import sys
from pathlib import Path

from ..atomic import check_distinct
from ..errors import ParameterError
from ._common import (
    add_mass_option,
    add_model_options,
    add_position_options,
    add_stiffness_option,
    body_aliases,
    check_position,
    emit_json,
    finite_float,
    load_model,
)


def register(sub) -> None:
    """Add the ``margins`` sub-command to the ``spinectl`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command action of :func:`spinectl.cli.build_parser`.
    """
    parser = sub.add_parser(
        "margins",
        help="delay, gain and phase margins of a delayed PD reflex at each segment",
        description="Close each segment's loop with a delayed PD reflex -(kp alpha + kd omega)(t - tau), "
        "its torque lagged by the force generation 1/(T_a s + 1), and report the exact delay margin "
        "(quasi-polynomial), its Pade estimate, gain and phase margins, "
        "the stabilising range of kp and whether the loop is stable at the delay: each joint alone, the others "
        "fixed (the paper's criterion); beside it the chain's verdict, all CoRs free, under the same reflex. "
        "See docs/reflex.md.",
    )
    add_position_options(parser)
    parser.add_argument("--delay", type=finite_float("--delay"), help="reflex delay tau [s] (default: config, 0.1)")
    parser.add_argument(
        "--activation-lag",
        type=finite_float("--activation-lag"),
        metavar="T_A",
        help="time constant T_a [s] of the force generation after the delay, a lag 1/(T_a s + 1) "
        "(default: config, 0.05; 0: the pure delay)",
    )
    parser.add_argument("--kp", type=finite_float("--kp"), help="proportional gain [N m/rad] (default: the rule)")
    parser.add_argument("--kd", type=finite_float("--kd"), help="derivative gain [N m s/rad] (default: the rule)")
    parser.add_argument(
        "--activation",
        type=finite_float("--activation"),
        help="fraction of the minimum stabilising PCSA: 0 reflex only, 1 self-stable (default: config, 0.5)",
    )
    parser.add_argument("--pade-order", type=int, help="order of the Pade delay in the python-control models")
    parser.add_argument(
        "--coupled",
        action="store_true",
        help="the whole chain under a diagonal reflex: exact delay margin, Pade margin, disk margins (docs/chain.md)",
    )
    add_stiffness_option(parser)
    add_mass_option(parser)
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    parser.add_argument("--plot", metavar="DIR", help="write bode.png, nyquist.png and response.png into DIR")
    add_model_options(parser)
    parser.set_defaults(func=run)


OVERRIDES = (
    ("delay", "reflex.delay"),
    ("activation_lag", "reflex.activation_time_constant"),
    ("activation", "reflex.activation"),
    ("pade_order", "reflex.pade_order"),
)
"""Command-line options that are aliases of ``--set reflex.FIELD=VALUE`` (``--kp`` and ``--kd`` are no
parameters of the model: :func:`spinectl.reflex.margins.margins_report` takes and checks them)."""


def run(args) -> int:
    """Run ``spinectl margins``: print the table, or JSON with ``--json``; plots with ``--plot``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments: ``E``, ``Lambda`` [m], the reflex options, ``json``, ``plot``
        and the model options.

    Returns
    -------
    int
        Exit code 0 (also for an infeasible optimum, reported as a status).
    """
    from ..model import clinical
    from ..reflex.chain_verdict import margins_with_chain

    if args.plot:
        from ..reflex.plots import PLOT_FILES

        check_distinct({"--plot": [Path(args.plot, name) for name in PLOT_FILES]}, {"--config": args.config})
    aliases = {dotted: ("--" + option.replace("_", "-"), getattr(args, option)) for option, dotted in OVERRIDES}
    aliases |= body_aliases(args)  # --K and --mass, as on stability and sweep
    model = load_model(args, aliases)  # --kp and --kd go to margins_report, which checks them
    check_position(model, args)
    if args.coupled:
        return _coupled(model, args)
    report = margins_with_chain(model, args.E, args.Lambda, kp=args.kp, kd=args.kd)
    if args.plot:
        from ..reflex import plots

        written = plots.write_plots(report, args.plot, model)
        skipped = sorted(set(plots.PLOT_FILES) - {p.name for p in written})
        if skipped:
            print(f"spinectl: note: not written (nothing to draw): {', '.join(skipped)}", file=sys.stderr)
    if args.json:
        emit_json(clinical.with_lordosis_angle(report.to_dict(), model))
    else:
        print(report.table())
    return 0


def _coupled(model, args) -> int:
    """``--coupled``: the chain's margins (:func:`spinectl.reflex.chain_margins.coupled_margins`)."""
    if args.plot:
        raise ParameterError("--plot", "is not available with --coupled")
    from ..model import clinical
    from ..reflex.chain_margins import coupled_margins

    result = coupled_margins(model, args.E, args.Lambda, kp=args.kp, kd=args.kd)
    if args.json:
        emit_json(clinical.with_lordosis_angle(result.to_dict(model), model))
    else:
        print(result.table(model))
    return 0
