"""Options and helpers shared by the sub-commands."""

from __future__ import annotations

import argparse
import json
import math
import sys

from ..atomic import atomic_write_text
from ..errors import ParameterError
from ..model.config import load_config
from ..model.params import Model


def add_model_options(parser: argparse.ArgumentParser, default_preset: str = "default") -> None:
    """``--config FILE`` and ``--preset NAME``, on every command.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The (sub-)command's parser; the options go into a group named "model".
    default_preset : str
        The preset used when neither option is given (named in the help).
    """
    group = parser.add_argument_group("model")
    group.add_argument("--config", metavar="FILE", help="TOML file overriding the preset's parameters")
    group.add_argument("--preset", metavar="NAME", help=f"built-in parameter preset (default: {default_preset!r})")


def add_position_options(parser: argparse.ArgumentParser) -> None:
    """``--E`` and ``--Lambda`` in metres.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The sub-command's parser.
    """
    parser.add_argument("--E", type=finite_float("--E"), default=0.0, help="eccentricity E [m] (default 0)")
    parser.add_argument("--Lambda", type=finite_float("--Lambda"), default=0.0, help="lordosis Lambda [m] (default 0)")


def add_dpi_option(parser: argparse.ArgumentParser) -> None:
    """``--dpi``, the resolution of PNG figures, on the commands that draw (:data:`spinectl.paper.figures.DPI`).

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The sub-command's parser.
    """
    from ..paper.figures import DPI

    parser.add_argument("--dpi", type=finite_float("--dpi"), default=DPI, help=f"PNG resolution (default {DPI})")


def load_model(args: argparse.Namespace, default_preset: str = "default") -> Model:
    """The model named by ``--preset`` and ``--config``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments with ``config`` and ``preset`` (see :func:`add_model_options`).
    default_preset : str
        The preset when neither option is given; a ``--config`` file without
        ``--preset`` keeps its own base preset (its ``preset`` key, else 'default').
    """
    preset = args.preset or (None if args.config else default_preset)
    return load_config(args.config, preset=preset)


def finite_float(name: str):
    """An argparse ``type`` accepting finite floats only, naming the option on error.

    Parameters
    ----------
    name : str
        The option, e.g. ``"--E"``, as named in the error message.
    """

    def convert(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be a number (got {text!r})") from None
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"{name} must be finite (got {text!r})")
        return value + 0.0  # -0 becomes 0

    convert.__name__ = name
    return convert


def float_list(name: str):
    """An argparse ``type`` for comma-separated finite floats, e.g. ``10,5,3``.

    Parameters
    ----------
    name : str
        The option, e.g. ``"--pcsa"``, as named in the error message.
    """
    one = finite_float(name)

    def convert(text: str) -> list[float]:
        return [one(part) for part in text.split(",") if part.strip()]

    convert.__name__ = name
    return convert


def emit_json(payload: dict, out: str | None = None) -> None:
    """Print ``payload`` as JSON, or write it atomically to ``out``.

    Parameters
    ----------
    payload : dict
        JSON-serialisable document; NaN is written as ``NaN``.
    out : str, optional
        Output file; default standard output.
    """
    text = json.dumps(payload, indent=2, allow_nan=True) + "\n"
    if out:
        atomic_write_text(out, text)
    else:
        sys.stdout.write(text)


def require(condition: bool, field: str, message: str) -> None:
    """Raise :class:`ParameterError` for ``field`` unless ``condition``.

    Parameters
    ----------
    condition : bool
        What must hold.
    field : str
        The option or parameter named in the error, e.g. ``"--pcsa"``.
    message : str
        What is allowed, e.g. ``"must be >= 0"``.
    """
    if not condition:
        raise ParameterError(field, message)
