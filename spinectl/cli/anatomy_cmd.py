"""``spinectl anatomy``: the paper's question and the chain's on a MuJoCo musculoskeletal model."""

from __future__ import annotations

import argparse
import dataclasses
import shlex

from ..anatomy.mapping import MAX_STIFFNESS
from ..errors import ParameterError
from ..model.params.bounds import MAX_ACTIVATION_TIME_CONSTANT
from ._common import anatomy_load, bounded_int, emit_json, finite_float, input_name, named_pattern, note_after

MAX_DERIVATIVE_GAIN = 1e6
"""Largest reflex derivative gain kd [N m s/rad]: the chain's delay margin scales as 1/kd from 1e3 to 1e6
(1.85e-5, 1.85e-8 s on MyoTorso at kp = 400, no lag), the arithmetic holding there."""

MAX_CONTROL = 1e6
"""Largest control of a muscle other than MuJoCo's (whose activation is in [0, 1]), e.g. the PCSA [cm^2] of
spinectl's export: 1000 times the plausible PCSA (1000 cm^2, :data:`spinectl.model.checks.MAX_PLAUSIBLE_PCSA`).
The export's chain stiffens by about 60 N m/rad per cm^2 (its largest eigenvalue of K 5.8e78 N m/rad at 1e77 cm^2),
so 6e7 N m/rad at the bound, within the 1e8 N m/rad up to which :data:`~spinectl.anatomy.mapping.MAX_STIFFNESS`
was measured to hold."""

STIFFNESS_WHY = " N m/rad, the bound of the chain's arithmetic (spinectl.anatomy.mapping.MAX_STIFFNESS)"


def register(sub) -> None:
    """Add the ``anatomy`` sub-command to the ``spinectl`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command action of :func:`spinectl.cli.build_parser`.
    """
    parser = sub.add_parser(
        "anatomy",
        help="stability of an anatomical model's lumbar chain (MuJoCo or OpenSim; MyoTorso built in)",
        description="Load a musculoskeletal model (the built-in 'myotorso' from myo-sim, an MJCF file read by "
        "MuJoCo or an .osim file read by OpenSim, with --mapping), linearise its lumbar chain at the reference "
        "posture (or --posture's) and the model's own controls (or --activation, --activations), and report "
        "each joint's stiffness (joint by joint, the others fixed), the chain's "
        "eigenvalues (every joint free, equality constraints off), the chain constrained by the model's "
        "lumbar rhythm (if it has one), and the global muscles' rank. Needs pip install 'spinectl[anatomy]' "
        "(and 'spinectl[opensim]' for .osim). "
        "See docs/anatomy.md.",
    )
    parser.add_argument(
        "model",
        nargs="?",
        default="myotorso",
        help="'myotorso', an MJCF file or an OpenSim .osim file (default: myotorso; also 'myofullbody', "
        "myo-sim's full body)",
    )
    parser.add_argument("--mapping", metavar="FILE", help="mapping TOML (default: the built-in one of the model)")
    parser.add_argument("--plane", default="sagittal", help="sagittal, coronal or 3d (default: sagittal)")
    parser.add_argument(
        "--activation",
        type=finite_float("--activation", high=MAX_CONTROL, why=" (a control; MuJoCo's muscles: [0, 1])"),
        default=None,
        metavar="A",
        help="activation of every muscle, in [0, 1] (or its control, e.g. a PCSA in cm^2 in spinectl's "
        "export) (default: the model's own controls: an MJCF's keyframe 0, an .osim's controllers at t = 0, "
        "spinectl's export's solution in both; else 0)",
    )
    parser.add_argument(
        "--posture",
        type=input_name,
        metavar="FILE",
        help="the posture from an OpenSim coordinates or states file (.mot, .sto: inverse kinematics, a "
        "states file; degrees or radians as its header's inDegrees says), every coordinate of the model by name "
        "or path (/jointset/J/C/value; an MJCF model's hinge and slide joints by name); needs OpenSim "
        "(default: the model's reference posture)",
    )
    parser.add_argument(
        "--activations",
        type=input_name,
        metavar="FILE",
        help="the activations from an OpenSim .sto (static optimisation, CMC, Moco, EMG normalised to [0, 1]): "
        "one column per muscle (an MJCF model's muscle actuators) by name or path ending /activation, every "
        "muscle given; needs OpenSim",
    )
    parser.add_argument(
        "--time",
        type=finite_float("--time"),
        metavar="T",
        help="the frame of --posture and --activations read [s] (default: each file's first; the table says which)",
    )
    parser.add_argument(
        "--joint-stiffness",
        type=_joint_stiffness,
        default="none",
        metavar="K",
        help="intervertebral stiffness added at each chain joint: none (the model's own, default), "
        "mapped (the mapping's cited value) or a number [N m/rad]",
    )
    add_load_option(parser)
    parser.add_argument(
        "--check",
        action="store_true",
        help="compare the eigenvalues with MuJoCo's own linearisation (mjd_transitionFD, free chain)",
    )
    parser.add_argument(
        "--optimise",
        action="store_true",
        help="the least muscle effort (volume-weighted sum of a_i^2) that holds the posture, "
        "with the stability criterion of --stability, beside the same without it",
    )
    parser.add_argument(
        "--stability",
        choices=("chain", "joints", "rhythm", "none"),
        default="chain",
        help="with --optimise: -K >= margin on the free chain (default), on each joint alone (the paper's), "
        "on the chain constrained by the rhythm, or none (classic static optimisation)",
    )
    parser.add_argument(
        "--equilibrium",
        choices=("rhythm", "free"),
        default="rhythm",
        help="with --optimise: net torque zero on the rhythm's coordinates, the model's equalities carrying "
        "the rest (default), or on every lumbar joint by muscles alone",
    )
    parser.add_argument(
        "--margin",
        type=finite_float("--margin", 0.0, MAX_STIFFNESS, STIFFNESS_WHY),
        default=1.0,
        help="with --optimise: the static margin mu of the stability criterion [N m/rad] (default: 1)",
    )
    add_reflex_options(parser)
    parser.add_argument(
        "--lordosis",
        metavar="START:STOP:N",
        help="also the three optima (classic, joint by joint, the chain) at N changes of the chain's summed "
        "angle from START to STOP [deg] along the model's rhythm (MuJoCo's joint equalities, OpenSim's "
        "coordinate couplers; positive: the model's positive flex_extension, extension for MyoTorso), e.g. -20:20:41",
    )
    parser.add_argument(
        "--plot",
        metavar="DIR",
        help="write sagittal.png (the model, muscles by class, CoRs), modes.png (each mode of -K as a bent "
        "spine, sagittal plane) and, with --lordosis, lordosis.png into DIR",
    )
    parser.add_argument(
        "--no-cache",
        action="store_true",
        help="compile the model anew, neither reading nor writing the cache of compiled models "
        "(an .osim file's: its linearisations) ($SPINECTL_CACHE_DIR, else $XDG_CACHE_HOME/spinectl, "
        "else ~/.cache/spinectl)",
    )
    parser.add_argument(
        "--contributions",
        nargs="?",
        const=10,
        type=bounded_int("--contributions", 1, 100000),
        metavar="N",
        help="also each muscle's contribution to the least eigenvalue of -K (d lambda/d a_i at the least-stable "
        "mode) on the free and the constrained chain: the N largest (default 10) with their class, per class, "
        "per --group, and the removal method (the optimum re-solved with --optimise); contributions.png with "
        "--plot. See docs/contributions.md",
    )
    parser.add_argument(
        "--group",
        action="append",
        type=named_pattern("--group"),
        metavar="NAME=REGEX",
        help="with --contributions: a named group of muscles, those whose names match REGEX at their start "
        "(a prefix is one: erector=IL|LTp); repeatable",
    )
    parser.add_argument(
        "--buckling",
        action="store_true",
        help="also the buckling load: the least load along gravity at the thorax's centre of mass at which the "
        "free and the constrained chain lose stability, at the analysed activations, posture, --joint-stiffness "
        "and --load s (docs/anatomy.md, 'Buckling load')",
    )
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    parser.set_defaults(func=run)


def add_load_option(parser, where: str = "") -> None:
    """``--load`` (repeatable, :func:`~spinectl.cli._common.anatomy_load`): of ``anatomy`` and ``motion``.

    Parameters
    ----------
    parser : argparse.ArgumentParser
    where : str
        Said after "in the equilibrium and the stiffness" (e.g. ", the same at every frame").
    """
    parser.add_argument(
        "--load",
        type=anatomy_load,
        action="append",
        default=[],
        metavar="BODY:FX,FY,FZ[@X,Y,Z]",
        help="an external force [N] held at a point of BODY (in its frame [m], default its origin), fixed in the "
        "ground, or in the body with a :body suffix; in the equilibrium and the stiffness (its load stiffness "
        f"through the geometry, as gravity's){where}; repeatable (docs/anatomy.md, Loads)",
    )


def add_reflex_options(parser, where: str = "") -> None:
    """``--kp``, ``--kd``, ``--activation-lag``: a delayed PD reflex's gains, of ``anatomy`` and ``motion``.

    Parameters
    ----------
    parser : argparse.ArgumentParser
    where : str
        Said after "the free chain's exact delay margin" (e.g. " at every frame").
    """
    parser.add_argument(
        "--kp",
        type=finite_float("--kp", 0.0, MAX_STIFFNESS, STIFFNESS_WHY),
        help=f"also the free chain's exact delay margin{where} under a delayed PD reflex with this proportional "
        "gain at every joint [N m/rad] (with --kd)",
    )
    parser.add_argument(
        "--kd",
        type=finite_float("--kd", 0.0, MAX_DERIVATIVE_GAIN, " N m s/rad"),
        default=0.0,
        help="the reflex's derivative gain [N m s/rad]",
    )
    parser.add_argument(
        "--activation-lag",
        type=finite_float("--activation-lag", 0.0, MAX_ACTIVATION_TIME_CONSTANT, " s"),
        default=0.05,
        metavar="T_A",
        help="time constant of the reflex's force generation [s] (default: 0.05)",
    )


def run(args) -> int:
    """Run ``spinectl anatomy``: print the table, or JSON with ``--json``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments: ``model``, ``mapping``, ``plane``, ``activation``, ``joint_stiffness``,
        ``check``, ``optimise``, ``stability``, ``equilibrium``, ``margin``, ``lordosis``, ``plot``, ``no_cache``,
        ``json``.

    Returns
    -------
    int
        Exit code 0 (an unstable chain and an infeasible optimum are answers).
    """
    from ..anatomy.engine import engine_output_to_stderr

    with engine_output_to_stderr():  # the engines' own prints (OpenSim's warnings) are not the table or JSON
        result, curve, buckling = _answers(args)
    if args.json:
        doc = result.to_dict()
        if curve is not None:
            doc["lordosis_curve"] = curve
        if buckling is not None:
            doc["buckling_load_N"] = buckling.to_dict()
        emit_json(doc)
    else:
        print(result.table())
        if buckling is not None:
            print(buckling.text())
        if curve is not None:
            print(_curve_table(curve))
    return 0


def _answers(args) -> tuple:
    """The analysis (or the optimum), the lordosis curve and the buckling load (None without the option); figures."""
    from ..anatomy import load
    from ..anatomy.analyses import analyse

    _refuse_combinations(args)
    anatomy = load(args.model, args.mapping, cache=not args.no_cache)
    reflex = None if args.kp is None else (args.kp, args.kd, args.activation_lag)
    loaded = {"loads": _loads(args.load)} if args.load else {}  # without: the calls as they were
    if args.optimise:
        from ..anatomy.optimum import optimised

        result = optimised(
            anatomy,
            plane=args.plane,
            stability=args.stability,
            margin=args.margin,
            joint_stiffness=args.joint_stiffness,
            equilibrium=args.equilibrium,
            check=args.check,
            reflex=reflex,
            posture=args.posture,
            time=args.time,
            **loaded,
        )
        result = dataclasses.replace(result, rerun=_rerun(args))
    else:
        result = analyse(
            anatomy,
            plane=args.plane,
            activation=args.activations if args.activations is not None else args.activation,
            joint_stiffness=args.joint_stiffness,
            check=args.check,
            reflex=reflex,
            posture=args.posture,
            time=args.time,
            **loaded,
        )
    curve = None
    if args.lordosis:
        from ..anatomy.optimum import lordosis_curve

        curve = lordosis_curve(
            anatomy,
            _degrees(args.lordosis),
            plane=args.plane,
            margin=args.margin,
            joint_stiffness=args.joint_stiffness,
            equilibrium=args.equilibrium,
            **loaded,
        )
    buckling = _buckling(args, anatomy, result.analysis if args.optimise else result) if args.buckling else None
    # before any figure is written: a group that matches no muscle is refused with nothing written
    parts = _contributions(args, anatomy, result) if args.contributions is not None or args.group else None
    if args.plot:
        from ..anatomy.figures import save_anatomy_figures

        analysis = result.analysis if args.optimise else result
        save_anatomy_figures(anatomy, analysis, curve, args.plot)
        _note_left_out(analysis)
    if parts is not None:
        if args.plot and parts.free is not None:
            from ..anatomy.contributions import save_contributions_figure

            save_contributions_figure(parts.free, args.plot, args.contributions)
        result = parts
    return result, curve, buckling


def _note_left_out(analysis) -> None:
    """A figure --plot does not draw for this analysis, said after the answer (anatomy.figures.figures_left_out)."""
    from ..anatomy.figures import figures_left_out

    if text := figures_left_out(analysis):
        note_after(text)


def _buckling(args, anatomy, analysis):
    """--buckling: the buckling load at the analysed operating point (its activations, posture and loads)."""
    from ..anatomy.buckling import buckling_load
    from ..anatomy.recordings import recorded_point

    return buckling_load(
        anatomy,
        plane=args.plane,
        posture=recorded_point(anatomy, args.posture, None, args.time).posture,  # the file's frame, as analysed
        joint_stiffness=args.joint_stiffness,
        activations=analysis.activations,
        loads=_loads(args.load) if args.load else (),
    )


def _refuse_combinations(args) -> None:
    """Options that cannot go together, refused before the model loads (before: one was ignored without a word)."""
    given = args.activation is not None or args.activations is not None
    if args.optimise and given:
        option = "--activation" if args.activation is not None else "--activations"
        raise ParameterError(option, "cannot go with --optimise, which finds the activations itself")
    if args.activation is not None and args.activations is not None:
        raise ParameterError("--activations", "cannot go with --activation: give the activations one way")
    if args.time is not None and args.posture is None and args.activations is None:
        raise ParameterError("--time", "selects a frame of --posture or --activations; neither was given")
    for option, value in (("--lordosis", args.lordosis), ("--plot", args.plot)):
        if value and args.posture is not None:  # both start from the model's reference posture
            raise ParameterError(option, "starts from the model's reference posture; it cannot go with --posture")


def _loads(parsed) -> tuple:
    """The --load options as the library's loads (their bodies checked when the model linearises)."""
    from ..anatomy.loads import body_loads

    return body_loads(parsed)


def _rerun(args) -> str:
    """What follows ``spinectl anatomy`` to optimise the same model again: the model, its mapping and the options
    that set the optimum (each only where given or not its default), quoted for a shell; the remedy's command."""
    words = [str(args.model)]
    options = (
        ("--mapping", args.mapping, None),
        ("--plane", args.plane, "sagittal"),
        ("--posture", args.posture, None),
        ("--time", args.time, None),
        ("--stability", args.stability, "chain"),
        ("--equilibrium", args.equilibrium, "rhythm"),
        ("--margin", args.margin, 1.0),
    )
    for option, value, default in options:
        if value is not None and value != default:
            words += [option, f"{value:g}" if isinstance(value, float) else str(value)]
    return shlex.join(words)


def _joint_stiffness(text: str):
    """--joint-stiffness: ``none``, ``mapped`` or a stiffness in [0, MAX_STIFFNESS] N m/rad."""
    if text in ("none", "mapped"):
        return text
    try:
        float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"--joint-stiffness must be none, mapped or a number [N m/rad] (got {text!r})"
        ) from None
    return finite_float("--joint-stiffness", 0.0, MAX_STIFFNESS, STIFFNESS_WHY)(text)


def _degrees(text: str):
    """START:STOP:NUM as NUM evenly spaced values [deg], by the rule of every range (``_validate.range_spec``)."""
    from .._validate import range_spec
    from ..model.params.bounds import MAX_CURVE_POINTS

    return range_spec(
        "--lordosis", text, MAX_CURVE_POINTS, "in degrees, e.g. -20:20:41", bounds=(-90.0, 90.0), unit="deg"
    )


def _curve_table(curve: dict) -> str:
    """The lordosis curve as rows: each criterion's least cost (or its status) per posture."""
    from ..anatomy.optimum import CURVE_AXIS, CURVE_AXIS_MEANING, CURVE_INACCURATE, CURVE_MEANING

    lines = [
        "",
        f"lordosis curve ({CURVE_MEANING})",
        f"{CURVE_AXIS}: {CURVE_AXIS_MEANING}; cost: the least sum of w_i a_i^2 [1] under each criterion",
        f"{CURVE_AXIS}  cost: classic  joint by joint  the chain (free)",
    ]
    inaccurate = 0
    for i, deg in enumerate(curve["lordosis_deg"]):
        cells = []
        for criterion in ("none", "joints", "chain"):
            row = curve[criterion]
            status = row["status"][i]
            inaccurate += status == "optimal_inaccurate"
            mark = INACCURATE_MARK if status == "optimal_inaccurate" else ""
            cells.append(f"{row['cost'][i]:.4g}{mark}" if status in ("optimal", "optimal_inaccurate") else status)
        lines.append(f"{deg:>{len(CURVE_AXIS)}.3g}  {cells[0]:>13}  {cells[1]:>14}  {cells[2]:>16}")
    if inaccurate:
        lines.append(CURVE_INACCURATE.format(count=inaccurate, mark=f"'{INACCURATE_MARK}' after the cost"))
    return "\n".join(lines)


def _contributions(args, anatomy, result):
    """--contributions: the result with each muscle's contribution."""
    from ..anatomy.contributions import with_contributions
    from ..anatomy.recordings import recorded_point

    if args.contributions is None:
        raise ParameterError("--group", "goes with --contributions (got --group alone)")
    optimum = (
        {"stability": args.stability, "margin": args.margin, "equilibrium": args.equilibrium} if args.optimise else None
    )
    return with_contributions(
        anatomy,
        result,
        plane=args.plane,
        posture=recorded_point(anatomy, args.posture, None, args.time).posture,  # the file's frame, as analysed
        joint_stiffness=args.joint_stiffness,
        loads=_loads(args.load) if args.load else (),
        count=args.contributions,
        groups=dict(args.group or ()),
        optimum=optimum,
    )


INACCURATE_MARK = "!"
"""What follows a cost in the lordosis table where its optimum is ``optimal_inaccurate``."""
