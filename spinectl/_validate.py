"""Small validators used by the parameter dataclasses.

Each raises :class:`~spinectl.errors.ParameterError` naming the field and what
is allowed; the configuration loader prefixes the section name. Messages are
one line: offending values are shown by a shortened ``repr``.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence

from .errors import ParameterError

SHOWN_CHARS = 60
"""Longest ``repr`` of an offending value quoted in a message [characters]."""


def show(value) -> str:
    """``repr(value)``, shortened to :data:`SHOWN_CHARS` so that a message stays one readable line.

    Parameters
    ----------
    value : object
        The offending value.
    """
    try:
        text = repr(value)
    except RecursionError:  # a list nested deeper than repr can follow
        text = f"<deeply nested {type(value).__name__}>"
    return _shorten(text)


def escaped(text: str) -> str:
    """``text`` without quotes but with line breaks and control characters escaped, shortened like :func:`show`.

    Parameters
    ----------
    text : str
        E.g. a key as written in a TOML file.
    """
    return _shorten(printable(text))


def printable(text: str) -> str:
    """``text`` with every non-printable character (line breaks included) escaped as in ``repr``.

    Parameters
    ----------
    text : str
        E.g. an error message that must print as one line.
    """
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


def _shorten(text: str) -> str:
    return text if len(text) <= SHOWN_CHARS else text[: SHOWN_CHARS - 3] + "..."


def real(name: str, value, *, allow_inf: bool = False) -> float:
    """Return ``value`` as a float; reject bools, strings, NaN and (by default) inf.

    Integers too large for a float are rejected; -0.0 becomes 0.0 (so outputs
    never show a signed zero the user did not mean).

    Parameters
    ----------
    name : str
        Field name for the error message, e.g. ``"mass"``.
    value : object
        The value to check; any real number type (int, float, numpy scalars).
    allow_inf : bool
        Accept +-inf.
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ParameterError(name, f"must be a number (got {show(value)})")
    try:
        value = float(value) + 0.0
    except OverflowError:
        raise ParameterError(name, f"must be finite (got an integer of {len(str(value))} digits)") from None
    if math.isnan(value) or (math.isinf(value) and not allow_inf):
        raise ParameterError(name, f"must be finite (got {value})")
    return value


def positive(name: str, value) -> float:
    """A finite number > 0.

    Parameters
    ----------
    name : str
        Field name for the error message, e.g. ``"mass"``.
    value : object
        The value to check.
    """
    value = real(name, value)
    if value <= 0:
        raise ParameterError(name, f"must be > 0 (got {value:g})")
    return value


def non_negative(name: str, value, *, allow_inf: bool = False) -> float:
    """A number >= 0 (finite unless ``allow_inf``).

    Parameters
    ----------
    name : str
        Field name for the error message, e.g. ``"mass"``.
    value : object
        The value to check.
    allow_inf : bool
        Accept +inf.
    """
    value = real(name, value, allow_inf=allow_inf)
    if value < 0:
        raise ParameterError(name, f"must be >= 0 (got {value:g})")
    return value


def in_range(name: str, value, low: float, high: float) -> float:
    """A finite number in the closed interval [low, high].

    Parameters
    ----------
    name : str
        Field name for the error message, e.g. ``"mass"``.
    value : object
        The value to check.
    low, high : float
        Bounds of the interval, in the field's unit.
    """
    value = real(name, value)
    if not low <= value <= high:
        raise ParameterError(name, f"must be in [{low:g}, {high:g}] (got {value:g})")
    return value


def choice(name: str, value, allowed: Sequence[str]) -> str:
    """One of the strings in ``allowed``.

    Parameters
    ----------
    name : str
        Field name for the error message, e.g. ``"mass"``.
    value : object
        The value to check.
    allowed : sequence of str
        The accepted values.
    """
    if not isinstance(value, str) or value not in allowed:
        raise ParameterError(name, f"must be one of {', '.join(map(repr, allowed))} (got {show(value)})")
    return value


def integer(name: str, value, low: int, high: int | None = None) -> int:
    """An int in [low, high].

    Parameters
    ----------
    name : str
        Field name for the error message, e.g. ``"mass"``.
    value : object
        The value to check; bools and floats (even 5.0) are rejected.
    low : int
        Smallest accepted value.
    high : int, optional
        Largest accepted value; no bound if None.
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ParameterError(name, f"must be an integer (got {show(value)})")
    value = int(value)
    if value < low or (high is not None and value > high):
        allowed = f">= {low}" if high is None else f"in [{low}, {high}]"
        raise ParameterError(name, f"must be an integer {allowed} (got {show(value)})")
    return value


def label(field: str, value) -> str:
    """A non-empty, printable string (it ends up in tables, file names and one-line messages).

    Parameters
    ----------
    field : str
        Field name for the error message, e.g. ``"name"``.
    value : object
        The value to check.
    """
    if not isinstance(value, str) or not value.strip() or not value.isprintable():
        raise ParameterError(field, f"must be a non-empty printable string (got {show(value)})")
    return value


def labels(field: str, value) -> tuple[str, ...]:
    """Distinct labels, see :func:`label`.

    Parameters
    ----------
    field : str
        Field name for the error message, e.g. ``"cor_names"``.
    value : object
        The value to check: a list or tuple of strings.
    """
    items = _sequence(field, value, "a list of strings")
    out = tuple(label(f"{field}[{i}]", item) for i, item in enumerate(items))
    duplicates = sorted({n for n in out if out.count(n) > 1})
    if duplicates:
        raise ParameterError(field, f"must be unique (repeated: {', '.join(map(repr, duplicates))})")
    return out


def real_vector(name: str, value, length: int | None = None) -> tuple[float, ...]:
    """A sequence of finite numbers, of ``length`` items if given.

    Parameters
    ----------
    name : str
        Field name for the error message, e.g. ``"mass"``.
    value : object
        The value to check: a list, tuple or 1-d numpy array, not a string.
    length : int, optional
        Required number of items.
    """
    items = _sequence(name, value, "a list of numbers")
    if length is not None and len(items) != length:
        raise ParameterError(name, f"must have {length} items (got {len(items)})")
    return tuple(real(f"{name}[{i}]", v) for i, v in enumerate(items))


def _sequence(name: str, value, what: str) -> Sequence:
    if hasattr(value, "tolist") and not isinstance(value, (str, bytes)):
        value = value.tolist()  # a numpy array from the Python API
    if isinstance(value, (str, bytes)) or not isinstance(value, Sequence):
        raise ParameterError(name, f"must be {what} (got {show(value)})")
    return value
