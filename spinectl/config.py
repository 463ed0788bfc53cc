"""Reading and writing model parameters as TOML, and the built-in presets.

A configuration file may give any subset of the parameters; the rest come from
the preset it names with ``preset = "NAME"`` (default ``"default"``). Unknown
keys are rejected with a "did you mean" hint. :func:`dump_toml` writes the
fully resolved set with each field's unit and documentation as comments.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import tomllib
import typing
from importlib import resources
from pathlib import Path

from ._validate import escaped, show
from .errors import ConfigError, ParameterError
from .params import Model

PRESET_PACKAGE = "spinectl.presets"


def list_presets() -> list[str]:
    """Names of the built-in presets (TOML files shipped in :mod:`spinectl.presets`)."""
    files = resources.files(PRESET_PACKAGE).iterdir()
    return sorted(f.name.removesuffix(".toml") for f in files if f.name.endswith(".toml"))


def load_preset(name: str = "default") -> Model:
    """The built-in preset ``name`` as a :class:`~spinectl.params.Model`.

    Parameters
    ----------
    name : str
        One of :func:`list_presets`.
    """
    presets = list_presets()
    if not isinstance(name, str) or name not in presets:
        raise ConfigError("preset", f"must be one of {', '.join(map(repr, presets))} (got {show(name)})")
    text = resources.files(PRESET_PACKAGE).joinpath(f"{name}.toml").read_text()
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
    """
    if path is None:
        return load_preset("default" if preset is None else preset)
    return _model_from_text(_read(Path(path)), source=str(path), preset=preset)


def _read(path: Path) -> str:
    """The text of a configuration file, or a :class:`ConfigError` saying why not."""
    shown = show(str(path))
    try:
        if not path.exists():
            raise ConfigError("config", f"file not found: {shown}")
        if not path.is_file():  # a folder, or a device such as /dev/zero that never ends
            raise ConfigError("config", f"not a regular file: {shown}")
        return path.read_text(encoding="utf-8")  # TOML is UTF-8 whatever the locale
    except ConfigError:
        raise
    except UnicodeDecodeError:
        raise ConfigError("config", f"{shown} is not UTF-8 text") from None
    except (OSError, ValueError) as exc:  # permissions, name too long, a NUL byte in the name
        reason = getattr(exc, "strerror", None) or exc.__class__.__name__
        raise ConfigError("config", f"cannot read {shown}: {reason}") from None


def _parse(text: str, source: str) -> dict:
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError("config", f"{show(source)} is not valid TOML ({exc})") from None
    except RecursionError:  # tomllib recurses once per level of nested arrays
        raise ConfigError("config", f"{show(source)} nests arrays or tables too deeply") from None


def _model_from_text(text: str, source: str, preset: str | None = None, is_preset: bool = False) -> Model:
    data = _parse(text, source)
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
    """
    data = to_dict(model)
    for dotted, value in values.items():
        node = data
        *parents, last = dotted.split(".")
        for key in parents:
            node = _child(node, key, dotted)
        _child(node, last, dotted)  # the last key must exist too: same checks, same messages
        node[int(last) if isinstance(node, list) else last] = value
    return from_dict(Model, data)


def _child(node, key: str, dotted: str):
    if isinstance(node, list):
        return node[_index(node, key, dotted)]
    if not isinstance(node, dict):
        raise ConfigError(dotted, f"{key!r} follows a value that is not a table")
    if key not in node:
        raise ConfigError(dotted, _unknown_message(key, node))
    return node[key]


def _index(node: list, key: str, dotted: str) -> int:
    # isdecimal and isascii: int() accepts exactly these digits ('²'.isdigit() is true)
    if not (key.isascii() and key.isdecimal()) or int(key) >= len(node):
        raise ConfigError(dotted, f"index {show(key)} must be an integer below {len(node)}")
    return int(key)


def _unknown_message(key: str, allowed) -> str:
    close = difflib.get_close_matches(key, list(allowed), n=1)
    hint = f"; did you mean {close[0]!r}?" if close else ""
    return f"unknown key {show(key)} (allowed: {', '.join(sorted(allowed))}){hint}"


def to_dict(obj) -> dict:
    """Nested plain dict (lists for tuples) of a parameter dataclass.

    Parameters
    ----------
    obj : dataclass instance
        A :class:`~spinectl.params.Model` or one of its sections.
    """
    out = {}
    for f in dataclasses.fields(obj):
        value = getattr(obj, f.name)
        if dataclasses.is_dataclass(value):
            value = to_dict(value)
        elif isinstance(value, tuple) and value and dataclasses.is_dataclass(value[0]):
            value = [to_dict(x) for x in value]
        elif isinstance(value, tuple):
            value = list(value)
        out[f.name] = value
    return out


def from_dict(cls, data: dict, path: str = ""):
    """Build the dataclass ``cls`` from a nested dict, validating every field.

    Parameters
    ----------
    cls : type
        A parameter dataclass, e.g. :class:`~spinectl.params.Model`.
    data : dict
        Its fields, nested as in TOML (SI units).
    path : str
        Dotted path of ``cls`` inside the model, prefixed to error field names.

    Raises
    ------
    ConfigError
        For an unknown key or a section of the wrong shape.
    ParameterError
        For a value that fails validation; the field is named with its full path.
    """
    if not isinstance(data, dict):
        raise ConfigError(path or "config", f"must be a table (got {show(data)})")
    fields = {f.name: f for f in dataclasses.fields(cls)}
    for key in data:
        if key not in fields:
            shown = escaped(key)  # a quoted TOML key may hold a newline
            raise ConfigError(f"{path}.{shown}" if path else shown, _unknown_message(key, fields))
    hints = typing.get_type_hints(cls)
    kwargs = {}
    for name, value in data.items():
        sub = f"{path}.{name}" if path else name
        kwargs[name] = _convert(hints[name], value, sub)
    try:
        return cls(**kwargs)
    except ParameterError as exc:
        raise exc.under(path) from None


def _convert(hint, value, path: str):
    if dataclasses.is_dataclass(hint):
        return from_dict(hint, value, path)
    args = typing.get_args(hint)
    if typing.get_origin(hint) is tuple and args and dataclasses.is_dataclass(args[0]):
        if not isinstance(value, list):
            raise ConfigError(path, f"must be an array of tables (got {show(value)})")
        return tuple(from_dict(args[0], item, f"{path}.{i}") for i, item in enumerate(value))
    if typing.get_origin(hint) is tuple:
        if not isinstance(value, (list, tuple)):
            raise ParameterError(path, f"must be a list (got {show(value)})")
        return tuple(value)
    return value


def dump_toml(model: Model) -> str:
    """The fully resolved parameter set as TOML, with units and docs as comments.

    Parameters
    ----------
    model : Model
        The parameters to write.
    """
    lines = ["# spinectl model parameters (SI units unless a comment says otherwise)", ""]
    for f in dataclasses.fields(model):
        value = getattr(model, f.name)
        if isinstance(value, tuple):
            for item in value:
                lines += [f"[[{f.name}]]", *_fields_toml(item), ""]
        else:
            lines += [f"[{f.name}]", *_fields_toml(value), ""]
    return "\n".join(lines)


def _fields_toml(obj) -> list[str]:
    lines = []
    for f in dataclasses.fields(obj):
        unit = f.metadata.get("unit", "")
        doc = f.metadata.get("doc", "")
        comment = f"[{unit}] {doc}" if unit else doc
        lines.append(f"# {comment}")
        lines.append(f"{f.name} = {_toml_value(getattr(obj, f.name))}")
    return lines


def _toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in value) + "]"
    raise TypeError(f"cannot write {value!r} as TOML")
