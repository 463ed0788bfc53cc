"""``spinectl design``: the least co-contraction and local stiffness for which a reflex delay is stable."""

from __future__ import annotations

import sys

from ._common import (
    add_mass_option,
    add_model_options,
    add_position_options,
    add_stiffness_option,
    body_aliases,
    check_position,
    emit_json,
    finite_float,
    float_list,
    load_model,
    refuse_set_unused,
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
        "stable at the delay, with its certificate. A delay no design meets is an answer (the status names "
        "which failed, e.g. 'status (the rule, joint by joint): infeasible', with the largest delay met). See "
        "docs/reflex.md.",
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
    parser.add_argument(
        "--gains",
        choices=("rule", "search"),
        help="the chain's reflex: rule (default) answers for the rule's gains handed over to the local muscles; "
        "search also answers over every diagonal PD reflex, a seeded gain search certified by the exact margin "
        "and the rightmost root (tens of seconds)",
    )
    parser.add_argument(
        "--margin",
        type=finite_float("--margin"),
        metavar="R",
        help="a delay-margin ratio R >= 1: the design holds every delay up to R x the delay (the design at R x "
        "the delay); default 1, with the cost of 1.1 shown",
    )
    parser.add_argument(
        "--decay-rate",
        type=finite_float("--decay-rate"),
        metavar="SIGMA",
        help="instead of --margin, a least decay rate sigma [1/s]: both answers (the least co-contraction joint "
        "by joint, the chain's least local stiffness) with every characteristic root at the delay at "
        "Re s <= -sigma (disturbances die out at least as exp(-sigma t)), certified as the delay is, on the "
        "loops shifted by sigma; below 1/T_a",
    )
    parser.add_argument(
        "--passive",
        metavar="START:STOP:NUM",
        help="instead: the chain's least global PCSA alone and least local stiffness against the passive "
        "stiffness per joint [N m/rad], e.g. 0:80:41, with Crisco et al. 1992's buckling stiffness marked",
    )
    parser.add_argument(
        "--delays",
        metavar="START:STOP:NUM",
        help="instead: the design curve, both criteria's required design against the delay [s], e.g. 0:0.2:41",
    )
    parser.add_argument(
        "--lags",
        type=float_list("--lags"),
        metavar="T_A,...",
        help="with --delays: one curve per activation lag [s], e.g. 0,0.05,0.1 (default: config)",
    )
    parser.add_argument(
        "--plot", metavar="DIR", help="with --passive: write passive.png; with --delays: design_curve.png, into DIR"
    )
    add_stiffness_option(parser)
    add_mass_option(parser)
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    add_model_options(parser)
    parser.set_defaults(func=run)


PASSIVE_EXAMPLE = "in N m/rad, e.g. 0:80:41"
DELAYS_EXAMPLE = "in seconds, e.g. 0:0.2:41"
"""The forms of ``--passive`` and ``--delays``, for a malformed one."""

STATIC_ONLY = ("--delay", "--activation-lag", "--activation", "--kp", "--kd", "--gains", "--margin", "--decay-rate")
"""The reflex's options, which ``--passive`` does not use: refused with it rather than ignored."""

PASSIVE_IS_STATIC = (
    "cannot go with --passive, whose answers are static (no reflex: the global PCSA alone and the least local "
    "stiffness at the minimum PCSA); a reflex's design is --delay or --delays without --passive"
)
PASSIVE_VARIES_K = "cannot go with --passive, which varies K"
"""Why ``--passive`` refuses the reflex's options (and ``--set reflex.*``), and ``--K`` (``--set passive.stiffness``
is the model's own K, where the fixed global PCSA is solved: it is used)."""

ONE_DELAY_ONLY = ("--delay", "--gains", "--margin", "--decay-rate")
"""Options of the one-delay design, refused with ``--delays`` rather than ignored."""

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
    from math import inf

    from .._validate import in_range, non_negative
    from ..errors import ParameterError
    from ..model import clinical
    from ..model.params import MAX_DELAY
    from ..reflex.design import answer

    aliases = {dotted: ("--" + option.replace("_", "-"), getattr(args, option)) for option, dotted in OVERRIDES}
    aliases |= body_aliases(args)  # --K and --mass, as on stability and margins
    if args.passive is not None and args.K is not None:
        raise ParameterError("--K", PASSIVE_VARIES_K)
    for option in STATIC_ONLY if args.passive is not None else ():
        if getattr(args, option.lstrip("-").replace("-", "_")) is not None:  # before: ignored without a word
            raise ParameterError(option, PASSIVE_IS_STATIC)
    if args.passive is not None:  # the same fields by --set: refused as their options are, not ignored
        refuse_set_unused(args.assignments or [], {"reflex.": PASSIVE_IS_STATIC})
    model = load_model(args, aliases)
    check_position(model, args)
    kp = None if args.kp is None else non_negative("--kp", args.kp)
    kd = None if args.kd is None else non_negative("--kd", args.kd)
    if args.plot is not None and args.passive is None and args.delays is None:
        raise ParameterError("--plot", "needs --passive or --delays")
    if args.lags is not None and args.delays is None:
        raise ParameterError("--lags", "needs --delays")
    if args.passive is not None and args.delays is not None:
        raise ParameterError("--passive", "cannot go with --delays (one curve at a time)")
    for option in ONE_DELAY_ONLY if args.delays is not None else ():
        if getattr(args, option.lstrip("-").replace("-", "_")) is not None:  # --delay was ignored without a word
            why = "whose delays are the curve's axis" if option == "--delay" else "which it does not take"
            raise ParameterError(option, f"cannot go with --delays, {why}: the one-delay design is --delay")
    if args.passive is not None:
        return _passive(model, args)
    if args.delays is not None:
        return _delays(model, args, kp, kd)
    delay = model.reflex.delay
    ratio = 1.0 if args.margin is None else in_range("--margin", args.margin, 1.0, MAX_DELAY / delay if delay else inf)
    decay = _decay_rate(args, model)
    result = answer(model, args.E, args.Lambda, kp=kp, kd=kd, search=args.gains == "search", ratio=ratio, decay=decay)
    if args.json:
        emit_json(clinical.with_lordosis_angle(result.to_dict(), model))
    else:
        print(result.table())
    return 0


def _decay_rate(args, model) -> float:
    """``--decay-rate`` [1/s] checked (0 without it): one robustness requirement, on the rule's design."""
    from ..errors import ParameterError
    from ..reflex.design.decay import checked_decay_rate

    if args.decay_rate is None:
        return 0.0
    for option, given in (("--margin", args.margin is not None), ("--gains search", args.gains == "search")):
        if given:
            raise ParameterError(
                "--decay-rate", f"cannot go with {option}: one robustness requirement, on the rule's design"
            )
    reflex = model.reflex
    return checked_decay_rate("--decay-rate", args.decay_rate, reflex.delay, reflex.activation_time_constant)


def _axis(option: str, text: str, high: float, unit: str, example: str):
    """START:STOP:NUM (or one value) in [0, high], by the rule of every range (``_validate.range_spec``)."""
    from .._validate import range_spec
    from ..model.params.bounds import MAX_CURVE_POINTS

    return range_spec(option, text, MAX_CURVE_POINTS, example, bounds=(0.0, high), unit=unit)


def _announce(designs: int, passive: bool = False) -> None:
    """A curve estimated to take long is announced on stderr first, as a sweep or a study is."""
    from ..landscape.budget import design_estimate

    cost = design_estimate(designs, passive)
    if cost.long:
        print(cost.line(), file=sys.stderr)


def _passive(model, args) -> int:
    """``--passive``: the chain's verdicts against the passive stiffness; the figure with ``--plot``."""
    from ..model.params.bounds import MAX_PASSIVE_STIFFNESS, passive_axis
    from ..reflex.design import passive_curve

    stiffnesses = passive_axis(_axis("--passive", args.passive, MAX_PASSIVE_STIFFNESS, "N m/rad", PASSIVE_EXAMPLE))
    _announce(len(stiffnesses), passive=True)
    curve = passive_curve(model, args.E, args.Lambda, stiffnesses)
    if args.plot is not None:
        from ..reflex.design_plots import passive_figure, write_figures

        write_figures({"passive.png": passive_figure(curve)}, args.plot)
    if args.json:
        emit_json(curve.to_dict())
    else:
        print(curve.table())
    return 0


def _delays(model, args, kp, kd) -> int:
    """``--delays``: the design curve against the delay (one per lag); the figure with ``--plot``."""
    from ..model.params import MAX_DELAY
    from ..model.params.bounds import design_axes
    from ..reflex.design import delay_curve

    lags = [model.reflex.activation_time_constant] if args.lags is None else args.lags
    delays, lags = design_axes(_axis("--delays", args.delays, MAX_DELAY, "s", DELAYS_EXAMPLE).tolist(), lags)
    _announce(len(delays) * len(lags))
    curve = delay_curve(model, args.E, args.Lambda, delays, args.lags, kp, kd)
    if args.plot is not None:
        from ..reflex.design_plots import delay_figure, write_figures

        write_figures({"design_curve.png": delay_figure(curve)}, args.plot)
    if args.json:
        emit_json(curve.to_dict())
    else:
        print(curve.table())
    return 0
