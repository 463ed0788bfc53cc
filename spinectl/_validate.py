"""Small validators used by the parameter dataclasses.

Each raises :class:`~spinectl.errors.ParameterError` naming the field and what
is allowed; the configuration loader prefixes the section name. Messages are
one line: offending values are shown by a shortened ``repr``.
"""

from __future__ import annotations

import difflib
import math
import numbers
import os
import stat
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


def show_path(path) -> str:
    """A path quoted as :func:`show` quotes it, shortened at the start so that the file's own name stays.

    Parameters
    ----------
    path : str or os.PathLike
        The path.

    Returns
    -------
    str
        E.g. ``"'.../run-3/model.xml'"``.
    """
    text = repr(str(path))
    return text if len(text) <= SHOWN_CHARS else "'..." + text[-(SHOWN_CHARS - 4) :]


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


def choice(name: str, value, allowed: Sequence[str], *, suggest: bool = False) -> str:
    """One of the strings in ``allowed``.

    Parameters
    ----------
    name : str
        Field name for the error message, e.g. ``"mass"``.
    value : object
        The value to check.
    allowed : sequence of str
        The accepted values.
    suggest : bool
        Add the closest allowed value to the message (``"; did you mean 'x'?"``), if one is close.
    """
    if not isinstance(value, str) or value not in allowed:
        close = difflib.get_close_matches(value, list(allowed), n=1) if suggest and isinstance(value, str) else []
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise ParameterError(name, f"must be one of {', '.join(map(repr, allowed))} (got {show(value)}){hint}")
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
    allowed = f">= {low}" if high is None else f"in [{low}, {high}]"
    # the range in both messages: a float such as 1e9 is refused for its size as much as for its type
    integral = isinstance(value, numbers.Integral) and not isinstance(value, bool)
    if not integral or value < low or (high is not None and value > high):
        raise ParameterError(name, f"must be an integer {allowed} (got {show(value)})")
    return int(value)


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


def linear_range(name: str, start: float, stop: float, num: int, typed: str, limit: int, *, table: bool = False):
    """``num`` evenly spaced values from ``start`` to ``stop``, inclusive: every range of an axis or a curve.

    One rule for every such range (``sweep --E``, ``design --delays`` and ``--passive``, ``anatomy
    --lordosis``, a study file's ``{ start, stop, num }``): ``start <= stop``, ``1 <= num <= limit``,
    and one value exactly when ``start = stop``. numpy's ``linspace`` would keep START alone for
    ``num = 1`` (silently dropping STOP), and repeat one value ``num`` times for ``start = stop``.

    Parameters
    ----------
    name : str
        The option or field, e.g. ``"--E"`` or ``"axes.E"``, as named in errors.
    start, stop : float
        The ends, finite, in the axis's unit.
    num : int
        The number of values.
    typed : str
        The range as the user wrote it, quoted in errors (``"'0:0.08:81'"``).
    limit : int
        The most values allowed (the caller's bound, with its reason).
    table : bool, optional
        Name the parts as a study file does (``start``, ``stop``, ``num``) rather than the command
        line (``START:STOP:NUM``).

    Returns
    -------
    numpy.ndarray, shape (num,)
        The values, ``numpy.linspace(start, stop, num)``.

    Raises
    ------
    ParameterError
        Naming ``name``, the rule broken and ``typed``.
    """
    import numpy as np

    s, t, n = ("start", "stop", "num") if table else ("START", "STOP", "NUM")
    form = "{ start, stop, num }" if table else "START:STOP:NUM"
    if not (math.isfinite(start) and math.isfinite(stop) and start <= stop and 1 <= num <= limit):
        raise ParameterError(name, f"must be {form} with {s} <= {t} and 1 <= {n} <= {limit:,} (got {typed})")
    if num == 1 and start != stop:
        raise ParameterError(
            name, f"with {n} = 1 must have {s} = {t}, or give the single value alone, e.g. {start:g} (got {typed})"
        )
    if num > 1 and start == stop:
        raise ParameterError(
            name, f"with {s} = {t} must have {n} = 1: {num} values would all be {start:g} (got {typed})"
        )
    return np.linspace(start, stop, num)


def range_spec(name: str, spec: str, limit: int, example: str, bounds=None, unit: str = ""):
    """A range typed on the command line, ``START:STOP:NUM`` or a single value, by :func:`linear_range`'s rule.

    Parameters
    ----------
    name : str
        The option, e.g. ``"--delays"``, as named in errors.
    spec : str
        As typed, e.g. ``"0:0.2:41"`` or ``"0.1"``.
    limit : int
        The most values allowed.
    example : str
        The unit in words and an example, for the malformed spec: ``"in metres, e.g. 0:0.08:81"``.
    bounds : (float, float), optional
        The allowed interval, in ``unit``; a range beyond it is refused naming the spec as typed.
    unit : str, optional
        The unit of ``bounds``, e.g. ``"s"``.

    Returns
    -------
    numpy.ndarray, shape (num,)
        The values.

    Raises
    ------
    ParameterError
        Naming ``name``: a malformed spec, a range that breaks :func:`linear_range`'s rule, or one beyond ``bounds``.
    """
    import numpy as np

    parts = spec.split(":")
    try:
        if len(parts) == 1:
            axis = np.array([float(parts[0])])
            start = stop = float(axis[0])
            num = 1
        elif len(parts) == 3:
            start, stop, num = float(parts[0]), float(parts[1]), int(parts[2])
        else:
            raise ValueError(spec)
    except ValueError:
        raise ParameterError(name, f"must be START:STOP:NUM {example} (got {spec!r})") from None
    axis = linear_range(name, start, stop, num, repr(spec), limit)
    if bounds is not None and not (bounds[0] <= start and stop <= bounds[1]):
        low, high = bounds
        raise ParameterError(
            name, f"must be in [{low:g}, {high:g}] {unit} (got {spec!r}: {start:g} to {stop:g} {unit})"
        )
    return axis


def file_fault(path, limit: int) -> str:
    """Why a file cannot be read as a small regular file, or ``""``: not one (a FIFO, a device such as /dev/zero,
    a folder, also behind a symbolic link), or larger than ``limit`` bytes.

    A reader that opens such a file blocks for ever (a FIFO) or reads until memory runs out (/dev/zero, a
    huge file): check before opening.

    Parameters
    ----------
    path : os.PathLike
        The file.
    limit : int
        The most bytes it may hold [B].

    Returns
    -------
    str
        E.g. ``"is not a regular file"``, ``"is larger than 16 MiB"``; ``""`` for a regular file within the
        limit, or one that does not exist (the reader says that).
    """
    try:
        status = os.stat(path)  # follows links: a link to /dev/zero is /dev/zero
    except FileNotFoundError:
        return ""
    except OSError as exc:
        return f"cannot be read ({exc.strerror or exc.__class__.__name__})"
    if not stat.S_ISREG(status.st_mode):
        return "is not a regular file"
    if status.st_size > limit:
        return f"is larger than {limit / 2**20:g} MiB"
    return ""
