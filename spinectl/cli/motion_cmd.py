"""``spinectl motion``: the Cholewicki-McGill stability index along a recorded motion (docs/motion.md)."""

from __future__ import annotations

import argparse
import sys

from ..anatomy.mapping import MAX_STIFFNESS
from ..errors import ParameterError
from ._common import finite_float, input_name, named_pattern
from .anatomy_cmd import STIFFNESS_WHY, _joint_stiffness, _loads, add_load_option, add_reflex_options

MAX_FRAME_RATE = 1e6
"""Largest --rate [Hz]: far above any motion capture's; the file's own rate is the real bound (checked later)."""


def register(sub) -> None:
    """Add the ``motion`` sub-command to the ``spinectl`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command action of :func:`spinectl.cli.build_parser`.
    """
    parser = sub.add_parser(
        "motion",
        help="the Cholewicki-McGill stability index at every frame of a recorded motion (.mot)",
        description="For every frame of an OpenSim coordinates file (or a --frames selection, or --rate), the "
        "operating point (posture from the file; activations from --activations at the same time, the anatomy "
        "optimum per frame with --optimise, or the model's own controls), the net torque, the least eigenvalue "
        "of -K of the free chain and of the chain constrained by the model's rhythm (the index, Cholewicki & "
        "McGill 1996) with its mode shape and the number of unstable modes; written as one NetCDF file. Needs "
        "pip install 'spinectl[anatomy]' and 'spinectl[opensim]' (OpenSim reads the files). See docs/motion.md.",
    )
    parser.add_argument("model", help="'myotorso', an MJCF file or an OpenSim .osim file")
    parser.add_argument(
        "--coordinates",
        required=True,
        type=input_name,
        metavar="FILE.mot",
        help="OpenSim coordinates (inverse kinematics .mot, or a states .sto), every coordinate of the model by "
        "name or path; degrees or radians as its header's inDegrees says",
    )
    parser.add_argument("--mapping", metavar="FILE", help="mapping TOML (default: the built-in one of the model)")
    parser.add_argument(
        "--activations",
        type=input_name,
        metavar="FILE.sto",
        help="activations per muscle (static optimisation, CMC, EMG normalised to [0, 1]), read at each frame's "
        "time (default: the model's own controls)",
    )
    parser.add_argument(
        "--optimise",
        choices=("none", "joints", "chain"),
        default="none",
        help="the activations per frame: none (--activations, else the model's own controls; default), or the "
        "least-effort optimum holding the frame's posture with the stability criterion joint by joint or of "
        "the free chain (margin 1 N m/rad)",
    )
    parser.add_argument(
        "--frames",
        type=_frames,
        metavar="A:B[:STEP]",
        help="the frames analysed, by index from 0, A to B included, every STEP-th (default: all)",
    )
    parser.add_argument(
        "--rate",
        type=finite_float("--rate", 0.0, MAX_FRAME_RATE, " Hz"),
        metavar="HZ",
        help="one frame every 1/HZ s (the nearest), HZ > 0 and at most the file's own rate (e.g. 3: "
        "Cholewicki & McGill's three times per second)",
    )
    parser.add_argument("--plane", default="sagittal", help="sagittal, coronal or 3d (default: sagittal)")
    parser.add_argument(
        "--joint-stiffness",
        type=_joint_stiffness,
        default="none",
        metavar="K",
        help="intervertebral stiffness added at each chain joint: none (default), mapped or a number [N m/rad]",
    )
    parser.add_argument(
        "--least-stiffness",
        type=finite_float("--least-stiffness", 0.0, MAX_STIFFNESS, STIFFNESS_WHY),
        metavar="MU",
        help="also the least joint stiffness added that makes the free chain's -K >= MU [N m/rad] at each frame "
        "(an SDP per frame)",
    )
    add_load_option(parser, ", the same at every frame, and in the optimum")
    parser.add_argument(
        "--contributions",
        action="store_true",
        help="also each muscle's and each class's d lambda_min / d a_i at every frame, on the free and the "
        "constrained chain (docs/contributions.md)",
    )
    parser.add_argument(
        "--removal",
        nargs="?",
        const="groups",
        choices=("groups", "muscles"),
        help="also the removal method at every frame (Cholewicki & VanVliet 2002): the index of both chains with "
        "each muscle class and each --group removed, the others' activations kept (the equilibrium not "
        "re-solved), or with --optimise the optimum re-solved without them (one re-solve per group per frame); "
        "'muscles': each muscle too (not with --optimise); removal.png with --plot (docs/motion.md)",
    )
    parser.add_argument(
        "--group",
        action="append",
        type=named_pattern("--group"),
        metavar="NAME=REGEX",
        help="with --removal: a named group of muscles, those whose names match REGEX at their start "
        "(a prefix is one: back=IL|LTp); repeatable",
    )
    add_reflex_options(parser, " at every frame")
    parser.add_argument("--out", required=True, metavar="FILE.nc", help="the NetCDF file written")
    parser.add_argument("--plot", metavar="DIR", help="write motion.png into DIR")
    parser.add_argument(
        "--no-cache",
        action="store_true",
        help="compile the model anew, neither reading nor writing the cache",
    )
    parser.set_defaults(func=run)


def run(args) -> int:
    """Run ``spinectl motion``: compute, write the NetCDF file (and the figure), print a short summary.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments.

    Returns
    -------
    int
        0 (an unstable frame is an answer).
    """
    from ..anatomy import load
    from ..anatomy.engine import engine_output_to_stderr
    from ..anatomy.motion import motion_response, select_frames
    from ..anatomy.motion_removal import check_removal
    from ..anatomy.recordings import read_recording
    from ..atomic import check_distinct, check_folder, check_writable

    if args.optimise != "none" and args.activations is not None:
        raise ParameterError("--activations", "cannot go with --optimise, which finds the activations itself")
    check_removal(args.removal, args.group, args.optimise, ("--removal", "--group"))  # before any file is read
    inputs = {"--coordinates": args.coordinates, "--activations": args.activations}
    check_distinct({"--out": args.out}, {k: v for k, v in inputs.items() if v is not None})
    check_writable(args.out)  # a typo in --out costs a second, not the run
    if args.plot:
        # and --plot's folder: never the file written without its figures
        check_folder(args.plot, ["motion.png"] + (["removal.png"] if args.removal else []))
    with engine_output_to_stderr():
        coordinates = read_recording(args.coordinates, "posture")
        select_frames(coordinates.times, args.frames, args.rate, ("--frames", "--rate"))  # before the model loads
        anatomy = load(args.model, args.mapping, cache=not args.no_cache)
        activations = None if args.activations is None else read_recording(args.activations, "activations")
        result = motion_response(
            anatomy,
            coordinates,
            activations,
            args.optimise,
            args.frames,
            args.rate,
            args.plane,
            args.joint_stiffness,
            args.least_stiffness,
            loads=_loads(args.load),
            contributions=args.contributions,
            reflex=None if args.kp is None else (args.kp, args.kd, args.activation_lag),
            removal=args.removal,
            groups=dict(args.group or ()),
        )
    _write(result, args)
    print(result.summary())
    return 0


def _write(result, args) -> None:
    """The NetCDF file (with its checksums, as a landscape's) and, with --plot, the figure: each atomic."""
    from ..landscape.netcdf import save

    figures = {}
    if args.plot:
        from ..anatomy.motion import motion_plot, removal_plot

        figures["motion.png"] = motion_plot(result)  # drawn before anything is written: a failure leaves nothing
        if args.removal:
            figures["removal.png"] = removal_plot(result)
    save(result.dataset, args.out)
    print(f"wrote {args.out}", file=sys.stderr)
    if figures:
        from ..canvas import save_figures

        save_figures(figures, args.plot, 150.0)
        for name in figures:
            print(f"wrote {args.plot}/{name}", file=sys.stderr)


def _frames(text: str) -> tuple:
    """--frames A:B[:STEP]: integers; their range against the file is checked when it is read."""
    parts = text.split(":")
    try:
        if len(parts) not in (2, 3):
            raise ValueError
        first, last, step = (int(p) for p in (parts + ["1"])[:3])
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"--frames must be FIRST:LAST or FIRST:LAST:STEP, frame indices from 0 (got {text!r})"
        ) from None
    return first, last, step
