"""``spinectl config show``: print the fully resolved parameter set as TOML."""

from __future__ import annotations

import sys

from ..model.config import dump_toml, list_presets
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


def _show(args) -> int:
    sys.stdout.write(dump_toml(load_model(args)))
    return 0


def _presets(args) -> int:
    print("\n".join(list_presets()))
    return 0
