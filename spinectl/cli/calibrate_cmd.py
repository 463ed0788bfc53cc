"""``spinectl calibrate``: fit the parameters the paper does not state to its landmarks.

Differential evolution on a coarse grid with both passive-stiffness
conventions (:func:`spinectl.paper.calibration.calibrate`), progress on stderr, the
residual of every landmark on stdout, and the calibrated model as a preset
TOML written atomically (``--out``). This is how ``spinectl/presets/wagner2012.toml``
was made; docs/reproduction.md describes the loss and the bounds.
"""

from __future__ import annotations

import shlex
import sys

from ..atomic import atomic_write_text, check_distinct, check_writable
from ..errors import ParameterError
from ._common import add_model_options, load_model, require


def register(sub) -> None:
    """Add the ``calibrate`` sub-command to the ``spinectl`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command action of :func:`spinectl.cli.build_parser`.
    """
    parser = sub.add_parser(
        "calibrate",
        help="fit the unstated parameters (mass, attachments, spread) to the paper's landmarks",
        description="Fit the upper-body mass, the muscle attachments and the fibre spread, within "
        "anatomical bounds, to the landmarks of Wagner et al. (2012) by differential evolution on a "
        "coarse grid, with both passive-stiffness conventions; verify on the paper's 81 x 81 grid and "
        "write the best model as a preset TOML (docs/reproduction.md).",
    )
    parser.defer(_options)
    parser.set_defaults(func=run)


def _options(parser) -> None:
    """The options, their defaults from :mod:`spinectl.paper.calibration` (imported when the command is used)."""
    from ..paper import calibration, grid

    parser.add_argument("--starts", type=int, default=1, help="independent optimiser runs, seeds SEED, SEED+1, ...")
    parser.add_argument("--seed", type=int, default=0, help="seed of the first run (default 0)")
    parser.add_argument(
        "--grid",
        type=int,
        default=calibration.FIT_POINTS,
        help=f"grid points per axis while fitting (default {calibration.FIT_POINTS})",
    )
    parser.add_argument(
        "--verify-grid",
        type=int,
        default=grid.PAPER_POINTS,
        help=f"grid points per axis of the final measurement (default {grid.PAPER_POINTS}: the paper's 1 mm)",
    )
    parser.add_argument("--generations", type=int, default=calibration.GENERATIONS, help="generations per run")
    parser.add_argument("--popsize", type=int, default=calibration.POPSIZE, help="population per free parameter")
    parser.add_argument(
        "--refine",
        type=int,
        default=calibration.REFINE_EVALUATIONS,
        help="loss evaluations of the local refinement per convention (0: none)",
    )
    parser.add_argument(
        "--activation",
        choices=("paired", "independent"),
        help="activation mode of the muscles (default: the preset's, 'paired')",
    )
    parser.add_argument(
        "--conventions",
        default=",".join(grid.CONVENTIONS),
        metavar="NAME,...",
        help="passive-stiffness conventions to fit (default: physical,paper)",
    )
    parser.add_argument(
        "--parameters",
        metavar="NAME,...",
        help="free parameters to fit (default: all of " + ", ".join(p.name for p in calibration.FREE_PARAMETERS) + ")",
    )
    parser.add_argument(
        "--bounds",
        action="append",
        default=[],
        metavar="NAME=LOW,HIGH",
        help="replace a free parameter's bounds, in its unit (repeatable), e.g. mass=10,55 for the "
        "mass-free preset wagner2012_mass_free",
    )
    parser.add_argument("--out", metavar="FILE.toml", help="write the calibrated model here as a preset (atomically)")
    parser.add_argument(
        "--history", metavar="FILE.csv", help="write every loss evaluation (vector, loss per convention) as CSV"
    )
    add_model_options(parser)


def run(args) -> int:
    """Run ``spinectl calibrate``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments (see :func:`register`).

    Returns
    -------
    int
        Exit code 0.
    """
    from ..paper import calibration

    require(3 <= args.grid <= 161, "--grid", f"must be 3 to 161 (got {args.grid})")
    require(3 <= args.verify_grid <= 161, "--verify-grid", f"must be 3 to 161 (got {args.verify_grid})")
    names = [n.strip() for n in args.parameters.split(",")] if args.parameters else None
    parameters = calibration.parameter_set(names)
    for text in args.bounds:
        parameters = calibration.with_bounds(parameters, *_bounds(text))
    conventions = [c.strip() for c in args.conventions.split(",") if c.strip()]
    check_distinct({"--out": args.out, "--history": args.history}, {"--config": args.config})
    base = load_model(args, {"optimisation.activation": ("--activation", args.activation)})
    for path in filter(None, (args.out, args.history)):
        check_writable(path)  # before minutes of fitting
    result = calibration.calibrate(
        base,
        parameters,
        conventions=conventions,
        points=args.grid,
        verify_points=args.verify_grid,
        seed=args.seed,
        starts=args.starts,
        popsize=args.popsize,
        generations=args.generations,
        refine=args.refine,
        progress=lambda line: print(line, file=sys.stderr, flush=True),
    )
    print(calibration.summary(result))
    if args.out:
        atomic_write_text(args.out, calibration.preset_toml(result, _command(args)))
        print(f"wrote {args.out}")
    if args.history:
        atomic_write_text(args.history, calibration.history_csv(result))
        print(f"wrote {args.history}")
    return 0


def _bounds(text: str) -> tuple[str, float, float]:
    """NAME=LOW,HIGH as (name, low, high); a one-line error (field --bounds) otherwise."""
    name, _, values = text.partition("=")
    parts = values.split(",")
    try:
        low, high = (float(part) for part in parts)
    except ValueError:
        raise ParameterError("--bounds", f"must be NAME=LOW,HIGH (got {text!r})") from None
    return name.strip(), low, high


def _command(args) -> str:
    """The command line that reproduces this run, for the preset's header."""
    words = ["spinectl", "calibrate"]
    for option in ("config", "preset", "activation", "parameters"):
        if getattr(args, option):
            words += [f"--{option}", getattr(args, option)]
    for assignment in args.assignments:
        words += ["--set", assignment]
    for text in args.bounds:
        words += ["--bounds", text]
    words += ["--seed", str(args.seed), "--starts", str(args.starts), "--grid", str(args.grid)]
    words += ["--verify-grid", str(args.verify_grid), "--generations", str(args.generations)]
    words += ["--popsize", str(args.popsize), "--refine", str(args.refine), "--conventions", args.conventions]
    if args.out:
        words += ["--out", args.out]
    return shlex.join(words)
