"""The schema engine for TOML files: reading, parsing, dotted keys, dataclasses from tables and back.

Model files (:mod:`spinectl.model.config`) and study files (:mod:`spinectl.landscape.study.files`)
share it, so both report the same errors in the same words: an unknown key with the allowed
ones and a "did you mean" (:func:`check_keys`), a value that should be a table
(:func:`check_table`), a dotted key that leads nowhere (:func:`locate`) or is given twice
(:func:`flatten`), each field named as it is written in the file (:func:`quoted_key`).
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
from ..quoting import toml_comment, toml_string

MAX_TEXT_BYTES = 16 * 1024 * 1024
"""The largest parameter, study, atlas or mapping file read [B]: such files are kilobytes (a model with every
field, 20 pairs and 24 CoRs is under 20 kB); an 8 GB file was read whole (17 GB of memory, a minute) before
its TOML was found invalid."""


def read_text(path: Path, field: str = "config") -> str:
    """The text of a configuration file, or a :class:`ConfigError` saying why not.

    Parameters
    ----------
    path : Path
        A TOML file (UTF-8).
    field : str, optional
        What the error names: the option or kind of file (``config``, ``mapping``, ``atlas``, ``study``).

    Returns
    -------
    str
        Its text.

    Raises
    ------
    ConfigError
        Missing, not a regular file, larger than :data:`MAX_TEXT_BYTES`, unreadable or not UTF-8.
    """
    shown = show(str(path))
    try:
        if not path.exists():
            raise ConfigError(field, f"file not found: {shown}")
        if not path.is_file():  # a folder, or a device such as /dev/zero that never ends
            raise ConfigError(field, f"not a regular file: {shown}")
        with path.open(mode="rb") as stream:  # at most the bound: a file that grows meanwhile is still refused
            data = stream.read(MAX_TEXT_BYTES + 1)
        if len(data) > MAX_TEXT_BYTES:
            raise ConfigError(field, f"{shown} is larger than {MAX_TEXT_BYTES // 2**20} MiB: not a spinectl TOML file")
        # TOML is UTF-8 whatever the locale; a byte-order mark (as some Windows editors write) is not content
        return data.decode("utf-8-sig")
    except ConfigError:
        raise
    except UnicodeDecodeError:
        raise ConfigError(field, f"{shown} is not UTF-8 text") from None
    except (OSError, ValueError) as exc:  # permissions, name too long, a NUL byte in the name
        reason = getattr(exc, "strerror", None) or exc.__class__.__name__
        raise ConfigError(field, f"cannot read {shown}: {reason}") from None


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


def locate(data, dotted: str) -> tuple:
    """The table or array that holds the value at a dotted key, and the value's key in it.

    Parameters
    ----------
    data : dict
        Nested tables and arrays, as :func:`parse` or :func:`to_dict` give them.
    dotted : str
        A dotted key such as ``"body.mass"`` or ``"muscles.0.spread"`` (array items by index).

    Returns
    -------
    tuple of (dict or list, str or int)
        The holder and the key (an int in an array): ``holder[key]`` is the value.

    Raises
    ------
    ConfigError
        A part of ``dotted`` is unknown (with a "did you mean"), not an index of its array,
        or follows a value that is not a table (field ``dotted``), as :func:`child` says.
    """
    node = data
    *parents, last = dotted.split(".")
    for key in parents:
        node = child(node, key, dotted)
    child(node, last, dotted)  # the last key must exist too: same checks, same messages
    return node, int(last) if isinstance(node, list) else last


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


def check_keys(keys, allowed, where: str = "") -> None:
    """Reject the first key that is not allowed, with :func:`unknown_message`.

    Parameters
    ----------
    keys : iterable of str
        The keys given, e.g. a table (its keys).
    allowed : iterable of str
        The keys allowed there.
    where : str
        The field of the table, as written in the file (``"samples"``, ``'axes."body.mass"'``);
        empty at the top of the file.

    Raises
    ------
    ConfigError
        For the first unknown key; the field is ``where.key`` (the key escaped, since a quoted
        TOML key may hold a line break).
    """
    allowed = list(allowed)
    for key in keys:
        if key not in allowed:
            shown = escaped(key)
            raise ConfigError(f"{where}.{shown}" if where else shown, unknown_message(key, allowed))


def check_table(value, where: str) -> None:
    """Reject a value that should be a table.

    Parameters
    ----------
    value : object
        The value given.
    where : str
        Its field, as written in the file.

    Raises
    ------
    ConfigError
        ``value`` is not a table (a dict).
    """
    if not isinstance(value, dict):
        raise ConfigError(where, f"must be a table (got {show(value)})")


def quoted_key(section: str, name: str) -> str:
    """A key of ``section`` as written in TOML: ``axes."body.mass"`` (a dotted key is quoted).

    Parameters
    ----------
    section : str
        The field of the table that holds the key, e.g. ``"axes"``.
    name : str
        The key, possibly dotted.

    Returns
    -------
    str
        ``section.name``, with ``name`` quoted if it holds a dot, escaped either way.
    """
    return f'{section}."{escaped(name)}"' if "." in name else f"{section}.{escaped(name)}"


def flatten(table: dict, section: str, is_leaf) -> dict:
    """The dotted keys of nested tables: ``body.mass = 1`` unquoted is ``{"body": {"mass": 1}}`` in TOML.

    Parameters
    ----------
    table : dict
        A table whose keys may be dotted, quoted or not.
    section : str
        The field of the table, for messages.
    is_leaf : callable
        ``is_leaf(value)`` for a non-empty table: true if it is a value (e.g. ``{ start, stop,
        num }``) rather than the next level of a dotted key. Other values are leaves anyway.

    Returns
    -------
    dict
        Each leaf by its dotted key, in the order of the file.

    Raises
    ------
    ParameterError
        A key is given twice: ``"body.mass"`` quoted and ``body.mass`` unquoted are two keys to TOML.
    """
    return _flatten(table, section, is_leaf, "")


def _flatten(table: dict, section: str, is_leaf, prefix: str) -> dict:
    out: dict = {}
    for key, value in table.items():
        name = f"{prefix}{key}"
        nested = isinstance(value, dict) and bool(value) and not is_leaf(value)
        parts = _flatten(value, section, is_leaf, f"{name}.") if nested else {name: value}
        for dotted in parts:
            if dotted in out:
                raise ParameterError(quoted_key(section, dotted), "is given twice")
        out |= parts
    return out


def field_metadata(obj, dotted: str) -> dict:
    """The metadata (``unit``, ``doc``) of the dataclass field that holds a dotted parameter.

    Parameters
    ----------
    obj : dataclass instance
        E.g. a :class:`~spinectl.model.params.Model` (only its structure is read).
    dotted : str
        A dotted parameter, e.g. ``"body.mass"``; items of a tuple by index
        (``"muscles.0.upper.1"`` is a coordinate of the field ``upper``).

    Returns
    -------
    dict
        The metadata of the last field on the way (empty if it has none).

    Raises
    ------
    KeyError
        A part of ``dotted`` names no field (check names first, e.g. with :func:`locate`).
    IndexError
        An index beyond its tuple.
    """
    node, meta = obj, {}
    for key in dotted.split("."):
        if isinstance(node, tuple):
            node = node[int(key)]
            continue
        meta = {f.name: f.metadata for f in dataclasses.fields(node)}[key]
        node = getattr(node, key)
    return dict(meta)


def to_dict(obj) -> dict:
    """Nested plain dict (lists for tuples) of a parameter dataclass.

    Parameters
    ----------
    obj : dataclass instance
        A :class:`~spinectl.model.params.Model` or one of its sections.

    Returns
    -------
    dict
        Its fields by name; nested dataclasses as dicts, tuples of them as lists of dicts.
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

    Returns
    -------
    object
        An instance of ``cls``.

    Raises
    ------
    ConfigError
        For an unknown key or a section of the wrong shape.
    ParameterError
        For a value that fails validation; the field is named with its full path.
    """
    check_table(data, path or "config")
    check_keys(data, [f.name for f in dataclasses.fields(cls)], path)
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


def table_lines(obj, notes: dict | None = None) -> list[str]:
    """The fields of a dataclass as the lines of a TOML table, each after a comment with its unit and doc.

    Parameters
    ----------
    obj : dataclass instance
        One section of a model, e.g. its ``body``.
    notes : dict, optional
        A comment line by field name, put after the doc and before the value (what this value is, where the
        doc describes the default).

    Returns
    -------
    list of str
        ``# [unit] doc`` and ``name = value`` for each field (without the table's header).

    Raises
    ------
    TypeError
        A value that TOML cannot hold (a ``None``, an object).
    """
    lines = []
    for f in dataclasses.fields(obj):
        unit = f.metadata.get("unit", "")
        doc = f.metadata.get("doc", "")
        comment = f"[{unit}] {doc}" if unit else doc
        lines.append(toml_comment(comment))
        if notes and f.name in notes:  # a note may name a file: one comment line whatever the path holds
            lines.append(toml_comment(notes[f.name]))
        lines.append(f"{f.name} = {_toml_value(getattr(obj, f.name))}")
    return lines


def _toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return toml_string(value)
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in value) + "]"
    raise TypeError(f"cannot write {value!r} as TOML")
