"""The schema engine for TOML files: reading, parsing, dotted keys, dataclasses from tables and back.

Model files (:mod:`spinectl.model.config`) and study files (:mod:`spinectl.landscape.study.spec`)
share it, so both report the same errors in the same words.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import tomllib
import typing
from pathlib import Path

from .._validate import escaped, show
from ..errors import ConfigError, ParameterError


def read_text(path: Path) -> str:
    """The text of a configuration file, or a :class:`ConfigError` saying why not.

    Parameters
    ----------
    path : Path
        A TOML file (UTF-8).

    Returns
    -------
    str
        Its text.

    Raises
    ------
    ConfigError
        Missing, not a regular file, unreadable or not UTF-8 (field ``config``).
    """
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


def parse(text: str, source: str) -> dict:
    """The tables of a TOML text.

    Parameters
    ----------
    text : str
        TOML.
    source : str
        Where the text came from, for the error message.

    Returns
    -------
    dict
        Nested tables as :func:`tomllib.loads` gives them.

    Raises
    ------
    ConfigError
        Not valid TOML, or nested too deeply (field ``config``).
    """
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError("config", f"{show(source)} is not valid TOML ({exc})") from None
    except RecursionError:  # tomllib recurses once per level of nested arrays
        raise ConfigError("config", f"{show(source)} nests arrays or tables too deeply") from None


def child(node, key: str, dotted: str):
    """The item ``key`` of a table or array met while following a dotted key.

    Parameters
    ----------
    node : dict or list
        A table, or an array indexed by decimal digits.
    key : str
        One part of ``dotted``.
    dotted : str
        The whole dotted key, named in errors.

    Returns
    -------
    object
        ``node[key]``.

    Raises
    ------
    ConfigError
        ``key`` unknown (with a "did you mean"), not an index below the array's length,
        or ``node`` not a table.
    """
    if isinstance(node, list):
        return node[_index(node, key, dotted)]
    if not isinstance(node, dict):
        raise ConfigError(dotted, f"{key!r} follows a value that is not a table")
    if key not in node:
        raise ConfigError(dotted, unknown_message(key, node))
    return node[key]


def _index(node: list, key: str, dotted: str) -> int:
    # isdecimal and isascii: int() accepts exactly these digits ('²'.isdigit() is true)
    if not (key.isascii() and key.isdecimal()) or int(key) >= len(node):
        raise ConfigError(dotted, f"index {show(key)} must be an integer below {len(node)}")
    return int(key)


def unknown_message(key: str, allowed) -> str:
    """The message for an unknown key: the allowed keys and the closest one.

    Parameters
    ----------
    key : str
        The key given.
    allowed : iterable of str
        The keys allowed at its place.

    Returns
    -------
    str
        E.g. ``unknown key 'mas' (allowed: mass, mass_height); did you mean 'mass'?``.
    """
    close = difflib.get_close_matches(key, list(allowed), n=1)
    hint = f"; did you mean {close[0]!r}?" if close else ""
    return f"unknown key {show(key)} (allowed: {', '.join(sorted(allowed))}){hint}"


def to_dict(obj) -> dict:
    """Nested plain dict (lists for tuples) of a parameter dataclass.

    Parameters
    ----------
    obj : dataclass instance
        A :class:`~spinectl.model.params.Model` or one of its sections.
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
        A parameter dataclass, e.g. :class:`~spinectl.model.params.Model`.
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
            raise ConfigError(f"{path}.{shown}" if path else shown, unknown_message(key, fields))
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
