"""``spinectl config show``: the resolved parameters as TOML; ``config presets``; ``config diff A B``."""

from __future__ import annotations

import sys

from ..model.config import diff_models, list_presets, load_model_spec, show_toml
from ..model.source import header
from ._common import add_model_options, load_model


def register(sub) -> None:
    """Add the ``config`` sub-command to the ``spinectl`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The sub-command action of :func:`spinectl.cli.build_parser`.
    """
    parser = sub.add_parser("config", help="show model parameters or list presets")
    actions = parser.add_subparsers(dest="action", metavar="ACTION")
    actions.required = True
    show = actions.add_parser("show", help="print the resolved parameters as TOML")
    add_model_options(show)
    show.set_defaults(func=_show)
    presets = actions.add_parser("presets", help="list the built-in presets")
    presets.set_defaults(func=_presets)
    diff = actions.add_parser(
        "diff",
        help="every parameter in which two presets or model files differ, with its unit",
        description="Compare two models, each a preset name or a TOML model file (on its own preset): one line "
        "per differing parameter, 'name [unit]: first -> second'; muscle pairs matched by name.",
    )
    diff.add_argument("first", metavar="FIRST", help="a preset name or a model file (TOML)")
    diff.add_argument("second", metavar="SECOND", help="a preset name or a model file (TOML)")
    diff.set_defaults(func=_diff)


def _show(args) -> int:
    sys.stdout.write(show_toml(load_model(args)))
    return 0


def _presets(args) -> int:
    print("\n".join(list_presets()))
    return 0


def _diff(args) -> int:
    first, second = load_model_spec(args.first), load_model_spec(args.second)
    differences = diff_models(first, second)
    print(f"--- {header(first)}\n+++ {header(second)}")
    print("\n".join(d.line() for d in differences) if differences else "no parameter differs")
    return 0
