"""``spinectl study``: a parameter study from a study file, chunk by chunk on Dask, into a Zarr store."""

from __future__ import annotations

import argparse

from ._common import add_scheduler_options, add_set_option, scheduler_options


def register(sub) -> None:
    """Add the ``study`` sub-command to the ``spinectl`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command action of :func:`spinectl.cli.build_parser`.
    """
    parser = sub.add_parser(
        "study",
        help="a parameter study (axes, samples) on Dask into a resumable Zarr store",
        description="Solve the sweep's problems over the E x Lambda grid and every parameter axis and "
        "Monte-Carlo draw of STUDY.toml (docs/studies.md), chunk by chunk, on a local Dask cluster or an "
        "existing one, writing each chunk to a Zarr store as it finishes. A STUDY.toml of [[trials]] is a study "
        "of motions instead: spinectl motion on every trial, chunked by frames (docs/motion.md).",
    )
    parser.add_argument("study", metavar="STUDY.toml", help="the study file")
    parser.add_argument("--out", required=True, metavar="STORE.zarr", help="the Zarr store (a folder)")
    add_scheduler_options(parser)
    parser.add_argument("--resume", action="store_true", help="continue the study in --out, skipping chunks done")
    parser.add_argument(
        "--max-chunks", type=_count, metavar="N", help="stop after N chunks (continue later with --resume)"
    )
    add_set_option(parser.add_argument_group("model (the study file names its preset or config)"))
    parser.set_defaults(func=run)


def _integer(text: str, low: int, name: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{name} must be an integer (got {text!r})") from None
    if value < low:
        raise argparse.ArgumentTypeError(f"{name} must be >= {low} (got {text!r})")
    return value


def _count(text: str) -> int:
    return _integer(text, 0, "--max-chunks")


def run(args) -> int:
    """Run ``spinectl study``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments (see :func:`register`).

    Returns
    -------
    int
        Exit code 0 (also when ``--max-chunks`` stopped the study early).
    """
    from ..landscape import study  # dask and zarr only for this command

    options = scheduler_options(args)
    if _motions(args):
        return _run_motions(args, options)
    spec = study.load_study(args.study, overrides=args.assignments)
    result = study.run_study(spec, args.out, resume=args.resume, max_chunks=args.max_chunks, **options)
    print(study.describe(result))
    return 0


def _motions(args) -> bool:
    """Whether STUDY.toml is a study of motions (``[[trials]]``); its own reader says what else is wrong."""
    from pathlib import Path

    from ..errors import ConfigError
    from ..landscape.study.motion_spec import is_motion_study
    from ..model._toml import read_text

    try:
        return is_motion_study(read_text(Path(args.study), "study"), args.study)
    except ConfigError:
        return False


def _run_motions(args, options) -> int:
    """A study of motions: every trial's frames, chunk by chunk, into the store (docs/motion.md)."""
    from ..anatomy.engine import engine_output_to_stderr
    from ..errors import ParameterError
    from ..landscape.study import describe
    from ..landscape.study.motion_run import run_motion_study
    from ..landscape.study.motion_spec import load_motion_study

    if args.assignments:
        raise ParameterError("--set", "sets the paper's model of a parameter study, not a study of motions")
    spec = load_motion_study(args.study)
    with engine_output_to_stderr():
        result = run_motion_study(spec, args.out, resume=args.resume, max_chunks=args.max_chunks, **options)
    print(describe(result))
    return 0
