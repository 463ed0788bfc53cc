"""Reading and writing model parameters as TOML, and the built-in presets.

A configuration file may give any subset of the parameters; the rest come from
the preset it names with ``preset = "NAME"`` (default ``"default"``). Unknown
keys are rejected with a "did you mean" hint. :func:`dump_toml` writes the
fully resolved set with each field's unit and documentation as comments.
"""

from __future__ import annotations

import dataclasses
from importlib import resources
from pathlib import Path

from .._validate import show
from ..errors import ConfigError
from ._toml import from_dict, locate, parse, read_text, table_lines, to_dict
from .params import Model

PRESET_PACKAGE = "spinectl.presets"


def list_presets() -> list[str]:
    """Names of the built-in presets (TOML files shipped in :mod:`spinectl.presets`).

    Returns
    -------
    list of str
        Preset names without ``.toml``, sorted, e.g. ``["default", "wagner2012"]``.
    """
    files = resources.files(PRESET_PACKAGE).iterdir()
    return sorted(f.name.removesuffix(".toml") for f in files if f.name.endswith(".toml"))


def load_preset(name: str = "default") -> Model:
    """The built-in preset ``name`` as a :class:`~spinectl.model.params.Model`.

    Parameters
    ----------
    name : str
        One of :func:`list_presets`.

    Returns
    -------
    Model
        The preset's parameters, validated.

    Raises
    ------
    ConfigError
        ``name`` is not a built-in preset.
    """
    presets = list_presets()
    if not isinstance(name, str) or name not in presets:
        raise ConfigError("preset", f"must be one of {', '.join(map(repr, presets))} (got {show(name)})")
    text = resources.files(PRESET_PACKAGE).joinpath(f"{name}.toml").read_text(encoding="utf-8")
    return _model_from_text(text, source=f"preset {name!r}", is_preset=True)


def load_config(path: str | Path | None = None, preset: str | None = None) -> Model:
    """Load a model: a preset, optionally overridden by the TOML file ``path``.

    Parameters
    ----------
    path : str or Path, optional
        A TOML file with any subset of the parameters. It may name its base
        preset with ``preset = "NAME"``.
    preset : str, optional
        Base preset; overrides the file's own ``preset`` key. Default ``"default"``.

    Returns
    -------
    Model
        The base preset with the file's values in place of its own, validated.
    """
    if path is None:
        return load_preset("default" if preset is None else preset)
    return _model_from_text(read_text(Path(path)), source=str(path), preset=preset)


def _model_from_text(text: str, source: str, preset: str | None = None, is_preset: bool = False) -> Model:
    data = parse(text, source)
    base_name = data.pop("preset", None)
    if is_preset:
        return from_dict(Model, data)
    if preset is None:
        preset = "default" if base_name is None else base_name
    return merge(load_preset(preset), data)


def merge(base: Model, data: dict) -> Model:
    """``base`` with the (partial, nested) parameters in ``data`` replacing its own.

    ``muscles``, a list, replaces the whole list when given.

    Parameters
    ----------
    base : Model
        The parameters to start from.
    data : dict
        Nested parameters as read from TOML, e.g. ``{"body": {"mass": 50.0}}`` (SI units).

    Returns
    -------
    Model
        A new, validated model; ``base`` is unchanged.
    """
    merged = _deep_merge(to_dict(base), data)
    return from_dict(Model, merged)


def _deep_merge(base: dict, new: dict) -> dict:
    out = dict(base)
    for key, value in new.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = _deep_merge(out[key], value)
        else:
            out[key] = value
    return out


def set_parameter(model: Model, dotted: str, value) -> Model:
    """Return ``model`` with one parameter replaced, e.g. ``"body.mass"`` or ``"muscles.0.spread"``.

    Parameters
    ----------
    model : Model
        The parameters to start from.
    dotted : str
        Dotted path of the parameter; list items by index.
    value : object
        The new value, in the parameter's unit (see ``docs/parameters.md``); validated.

    Returns
    -------
    Model
        A new, validated model; ``model`` is unchanged.
    """
    return set_parameters(model, {dotted: value})


def set_parameters(model: Model, values: dict) -> Model:
    """Return ``model`` with several parameters replaced at once, validated together.

    Together, because some parameters constrain each other (e.g. ``body.mass_height`` must
    lie above ``geometry.cor_heights``): one at a time, a valid pair could fail half-way.

    Parameters
    ----------
    model : Model
        The parameters to start from.
    values : dict
        New values by dotted path, as in :func:`set_parameter`.

    Returns
    -------
    Model
        A new, validated model; ``model`` is unchanged.
    """
    data = to_dict(model)
    for dotted, value in values.items():
        holder, key = locate(data, dotted)
        holder[key] = value
    return from_dict(Model, data)


def dump_toml(model: Model) -> str:
    """The fully resolved parameter set as TOML, with units and docs as comments.

    Parameters
    ----------
    model : Model
        The parameters to write.

    Returns
    -------
    str
        TOML text that :func:`load_config` reads back to ``model``; every field is
        preceded by a comment with its unit in brackets and its ``doc`` metadata.
    """
    lines = ["# spinectl model parameters (SI units unless a comment says otherwise)", ""]
    for f in dataclasses.fields(model):
        value = getattr(model, f.name)
        if isinstance(value, tuple):
            for item in value:
                lines += [f"[[{f.name}]]", *table_lines(item), ""]
        else:
            lines += [f"[{f.name}]", *table_lines(value), ""]
    return "\n".join(lines)


