"""Small validators used by the parameter dataclasses.

Each raises :class:`~spinectl.errors.ParameterError` naming the field and what
is allowed; the configuration loader prefixes the section name.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from .errors import ParameterError


def real(name: str, value, *, allow_inf: bool = False) -> float:
    """Return ``value`` as a float; reject bools, strings, NaN and (by default) inf.

    Parameters
    ----------
    name : str
        Field name for the error message, e.g. ``"mass"``.
    value : object
        The value to check.
    allow_inf : bool
        Accept +-inf.
    """
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ParameterError(name, f"must be a number (got {value!r})")
    value = float(value)
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
    if value not in allowed:
        raise ParameterError(name, f"must be one of {', '.join(map(repr, allowed))} (got {value!r})")
    return value


def integer(name: str, value, low: int) -> int:
    """An int >= low.

    Parameters
    ----------
    name : str
        Field name for the error message, e.g. ``"mass"``.
    value : object
        The value to check; bools are rejected.
    low : int
        Smallest accepted value.
    """
    if isinstance(value, bool) or not isinstance(value, int):
        raise ParameterError(name, f"must be an integer (got {value!r})")
    if value < low:
        raise ParameterError(name, f"must be >= {low} (got {value})")
    return value


def real_vector(name: str, value, length: int | None = None) -> tuple[float, ...]:
    """A sequence of finite numbers, of ``length`` items if given.

    Parameters
    ----------
    name : str
        Field name for the error message, e.g. ``"mass"``.
    value : object
        The value to check: a list or tuple, not a string.
    length : int, optional
        Required number of items.
    """
    if isinstance(value, (str, bytes)) or not isinstance(value, Sequence):
        raise ParameterError(name, f"must be a list of numbers (got {value!r})")
    if length is not None and len(value) != length:
        raise ParameterError(name, f"must have {length} items (got {len(value)})")
    return tuple(real(f"{name}[{i}]", v) for i, v in enumerate(value))
