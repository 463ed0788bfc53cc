"""Postures and activations from OpenSim's files (``.mot``, ``.sto``), matched to a model by name (docs/anatomy.md).

The operating point of an anatomical model is its posture and its muscles' activations. Both may come from
a file that a lab's pipeline wrote: OpenSim's inverse kinematics (a ``.mot`` of coordinates, in degrees or
radians as its header's ``inDegrees`` says), a states file (``/jointset/<joint>/<coordinate>/value`` columns
beside speeds, activations and fibre lengths), static optimisation, CMC or Moco (a ``.sto`` of activations),
an EMG pipeline (activations normalised to [0, 1]). Every file is read by OpenSim's own reader
(``opensim.TimeSeriesTable``, i.e. its ``STOFileAdapter``, which also refuses times that do not increase) and
converted from degrees by OpenSim's ``SimbodyEngine`` on an OpenSim model; on an MJCF model the hinge joints
are the rotational ones. This module only matches the columns to the model, picks the frame and checks it:

- a column names a coordinate (posture) or a muscle (activations) by its name or its path (an OpenSim
  model's ``/jointset/.../<coordinate>/value`` and ``/forceset/<muscle>/activation``); a column that is
  another state of the model (a speed, a fibre length) is skipped; any other column is refused, and so is a
  coordinate or muscle of the model that the file lacks, in one line naming them;
- the frame is the file's first, or the one at ``time`` (to :data:`TIME_TOLERANCE`); a NaN or infinite value
  in it is refused, naming the columns.

The same rules take a dict (name or path -> value [rad, m or 1]) from Python. The result is the operating
point in the engine's form, which :func:`spinectl.anatomy.analyses.analyse` and
:func:`spinectl.anatomy.optimum.optimised` take unchanged: the readers live here, at the I/O edge, and the
physics never sees a file.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._optional import require_module
from .._validate import file_fault, printable, show
from ..errors import ParameterError

TIME_TOLERANCE = 1e-6
"""How close [s] a requested time must be to a frame's: OpenSim writes times to 8 decimals (5e-9 s of
round-off), and a 1 kHz recording's frames are 1e-3 s apart, so 1e-6 s finds the frame meant and no other."""

MAX_RECORDING_BYTES = 1 << 30
"""The largest posture or activation file read [B]: a states file of 1,349 columns at 100 Hz for ten minutes
is about 1 GiB; a larger one is more likely /dev/zero or a mistake."""

SHOWN = 5
"""How many names a message lists before it says how many more there are."""


@dataclass(frozen=True)
class Columns:
    """How a model reads a file's columns (an engine's ``posture_columns`` or ``activation_columns``).

    Attributes
    ----------
    names : dict
        Column label -> the model's name it sets (a coordinate or a muscle); several labels may name one.
    required : tuple of str
        The model's names that a file must give (every coordinate, every muscle).
    skipped : frozenset of str
        Labels of the model's other states (speeds, fibre lengths...), read and left alone.
    rotational : frozenset of str
        The model's names converted from degrees where the file is in degrees (an OpenSim model's
        coordinates that OpenSim converts; an MJCF model's hinge joints).
    what : str
        ``"coordinate"`` or ``"muscle"``, for messages.
    """

    names: dict
    required: tuple
    skipped: frozenset = frozenset()
    rotational: frozenset = frozenset()
    what: str = "coordinate"


@dataclass(frozen=True)
class Frame:
    """One frame of a file (or a dict), matched to a model.

    Attributes
    ----------
    values : dict
        The model's name -> value: a coordinate's [rad or m], a muscle's activation [1].
    source : str
        Where it came from, as the table says it: ``"s01static.mot at t = 0.01 s (its first frame)"``.
    time : float
        The frame's time [s]; NaN for a dict.
    """

    values: dict
    source: str
    time: float = float("nan")


@dataclass(frozen=True)
class AnatomyPoint:
    """An anatomical model's operating point: the posture in the engine's form and the activations.

    Attributes
    ----------
    posture : object or None
        The engine's posture (MuJoCo: the full qpos; OpenSim: coordinate name -> value); None: the
        model's reference posture.
    activation : numpy.ndarray or None
        One activation per muscle, in the model's order; None: the model's own controls.
    posture_source, activation_source : str
        Where each came from (``""``: the model's own).
    """

    posture: object = None
    activation: object = None
    posture_source: str = ""
    activation_source: str = ""


def anatomy_point(anatomy, posture=None, activations=None, time=None) -> AnatomyPoint:
    """The operating point of a model from files or dicts: its posture and its muscles' activations.

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model (:func:`spinectl.anatomy.load`).
    posture : str, pathlib.Path, dict or None
        An OpenSim coordinates or states file (``.mot``, ``.sto``; degrees or radians as its header's
        ``inDegrees`` says), or a dict of coordinate (MJCF: joint) name or path -> value [rad or m];
        every coordinate of the model given. None: the model's reference posture.
    activations : str, pathlib.Path, dict or None
        A ``.sto`` with one column per muscle (MJCF: per muscle actuator), by name or by path ending
        ``/activation``, values in [0, 1]; or such a dict. Every muscle given. None: the model's own.
    time : float, optional
        The frame read from each file [s]; default each file's first.

    Returns
    -------
    AnatomyPoint

    Raises
    ------
    ParameterError
        One line naming the file (field ``posture`` or ``activations``) and what is wrong: not readable by
        OpenSim, no ``inDegrees`` in a posture's header, times that do not increase, ``time`` not a frame,
        unknown columns, the model's coordinates or muscles missing, NaN values, activations outside the bounds.
    """
    point = AnatomyPoint()
    if posture is not None:
        frame = read_frame(posture, anatomy.posture_columns(), "posture", time)
        point = AnatomyPoint(anatomy.named_posture(frame.values), None, frame.source)
    if activations is not None:
        frame = read_frame(activations, anatomy.activation_columns(), "activations", time)
        a = np.array([frame.values[name] for name in anatomy.muscles])
        _check_bounds(anatomy, a, frame)
        point = AnatomyPoint(point.posture, a, point.posture_source, frame.source)
    return point


def recorded_point(anatomy, posture=None, activation=None, time=None) -> AnatomyPoint:
    """The operating point that :func:`~spinectl.anatomy.analyses.analyse` analyses: files read, the rest as given.

    A posture or activation given as a file name (``str`` or path) is read by :func:`anatomy_point`; any
    other value (the engine's posture, an activation vector or dict, None) passes through unchanged.

    Parameters
    ----------
    anatomy : AnatomyEngine
        The model.
    posture, activation : optional
        A file, or the engine's form.
    time : float, optional
        The frame read from the files [s]; refused without a file.

    Returns
    -------
    AnatomyPoint
        ``posture_source`` ``"given"`` for a posture given in the engine's form, ``""`` for none;
        ``activation_source`` ``""`` unless read from a file.
    """
    posture_file, activation_file = _is_file(posture), _is_file(activation)
    if time is not None and not (posture_file or activation_file):
        raise ParameterError(
            "time", f"selects a frame of a posture or activation file; none was given (got {show(time)})"
        )
    point = anatomy_point(anatomy, posture if posture_file else None, activation if activation_file else None, time)
    return AnatomyPoint(
        point.posture if posture_file else posture,
        point.activation if activation_file else activation,
        point.posture_source or ("" if posture is None else "given"),
        point.activation_source,
    )


def _is_file(value) -> bool:
    return isinstance(value, (str, os.PathLike))


def read_frame(source, columns: Columns, field: str, time=None) -> Frame:
    """One frame of a file (read by OpenSim) or a dict, its columns matched to a model.

    Parameters
    ----------
    source : str, pathlib.Path or dict
        The file, or label -> value (no degrees: [rad], [m], [1]).
    columns : Columns
        How the model reads the labels.
    field : str
        ``"posture"`` or ``"activations"``: the field of every message.
    time : float, optional
        The frame's time [s]; default the first (a file only).

    Returns
    -------
    Frame
    """
    if isinstance(source, dict):
        if time is not None:
            raise ParameterError("time", "selects a frame of a file; a dict is one frame (got a time with a dict)")
        labels, row = [str(k) for k in source], np.array([_number(field, k, v) for k, v in source.items()])
        return Frame(_matched(columns, labels, row, field, "the dict"), "given")
    return read_recording(source, field).frame(columns, time)


@dataclass(frozen=True)
class Recording:
    """A file of frames as OpenSim read it, before its columns are matched to a model (:func:`read_recording`).

    Read once, a recording gives any of its frames (:meth:`frame`), as a motion's analysis asks for each.

    Attributes
    ----------
    path : pathlib.Path
        The file.
    field : str
        ``"posture"`` or ``"activations"``: the field of every message.
    labels : tuple of str
        The column labels, as in the file.
    times : numpy.ndarray, shape (t,)
        The frames' times [s], strictly increasing (OpenSim's check).
    values : numpy.ndarray, shape (t, len(labels))
        As in the file (degrees where ``in_degrees``).
    in_degrees : bool
        The header's ``inDegrees`` (a posture's; False for activations).
    """

    path: Path
    field: str
    labels: tuple
    times: np.ndarray
    values: np.ndarray
    in_degrees: bool = False

    def frame(self, columns: Columns, time=None) -> Frame:
        """The frame at ``time`` (default the first), matched to a model and in radians.

        Parameters
        ----------
        columns : Columns
            How the model reads the labels.
        time : float, optional
            A time of the file's frames [s] (to :data:`TIME_TOLERANCE`).

        Returns
        -------
        Frame
        """
        index, chosen = _frame_index(self.times, time, self.path, self.field)
        where = f"{printable(self.path.name)} at t = {self.times[index]:g} s ({chosen})"
        values = _matched(columns, self.labels, self.values[index], self.field, where)
        if self.in_degrees:
            values = {k: float(np.radians(v)) if k in columns.rotational else v for k, v in values.items()}
        return Frame(values, where, float(self.times[index]))


def read_recording(source, field: str) -> Recording:
    """A ``.mot`` or ``.sto`` file read by OpenSim's ``TimeSeriesTable`` (its ``STOFileAdapter``).

    Parameters
    ----------
    source : str or pathlib.Path
        The file.
    field : str
        ``"posture"`` (its header must say ``inDegrees``) or ``"activations"``.

    Returns
    -------
    Recording

    Raises
    ------
    ParameterError
        One line: OpenSim missing (:class:`~spinectl.anatomy.export_osim.OpenSimUnavailable`), no regular file,
        no ``endheader`` and labels, OpenSim's own refusal (times not increasing), no ``inDegrees`` in a posture.
    """
    osim = _opensim(field)  # first: without it no file can be read
    path = _readable(source, field)
    _check_header(path, field)
    table = _table(osim, path, field)
    degrees = _in_degrees(osim, table, path, field) if field == "posture" else False
    times = np.asarray(table.getIndependentColumn(), float)
    values = table.getMatrix().to_numpy() if times.size else np.zeros((0, table.getNumColumns()))
    return Recording(path, field, tuple(table.getColumnLabels()), times, values, degrees)


def _number(field: str, key, value) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        raise ParameterError(field, f"{show(str(key))}: must be a number (got {show(value)})") from None


def _readable(source, field: str) -> Path:
    """The file's path, if it is a regular file within :data:`MAX_RECORDING_BYTES`; else one line."""
    path = Path(source)
    fault = file_fault(path, MAX_RECORDING_BYTES)
    if fault:
        raise ParameterError(field, f"{show(str(path))} {fault}")
    if not path.is_file():
        raise ParameterError(field, f"must be an OpenSim .mot or .sto file (no such file: {show(str(path))})")
    return path


def _check_header(path: Path, field: str) -> None:
    """A line ``endheader`` and, after it, a line of column labels: else one line, before OpenSim reads the file.

    OpenSim 4.6's STOFileAdapter never returns on a file that ends before those two lines (a text file that is
    no table, a header cut short): the guard reads lines up to the labels, no further, and parses nothing.
    """
    ended = False
    with open(path, "rb") as lines:  # bytes: the encoding is OpenSim's to read
        for line in lines:
            text = line.strip()
            if ended and text:
                return
            ended = ended or text == b"endheader"
    raise ParameterError(
        field,
        f"{show(str(path))} is no OpenSim .mot or .sto file: it needs a header ending in a line 'endheader', then "
        f"a line of column labels ({'no labels after it' if ended else 'no endheader line'})",
    )


def _opensim(field: str):
    """OpenSim, or one line: the option needs it to read its file."""
    from .export_osim import INSTALL_HINT, OpenSimUnavailable, require_opensim

    require_module(
        "opensim", OpenSimUnavailable, f"--{field} reads the file with OpenSim's STOFileAdapter: {INSTALL_HINT}"
    )
    return require_opensim()


def _table(osim, path: Path, field: str):
    """The file as OpenSim's ``TimeSeriesTable`` (its STOFileAdapter; times strictly increasing)."""
    from .engine import engine_output_to_stderr, opensim_message

    try:
        with engine_output_to_stderr():
            return osim.TimeSeriesTable(str(path))
    except Exception as exc:  # OpenSim's own exception types: one line each, its words kept
        text = opensim_message(exc)
        raise ParameterError(field, f"OpenSim cannot read {show(str(path))} as a time series: {text}") from None


def _in_degrees(osim, table, path: Path, field: str) -> bool:
    """The header's ``inDegrees`` (OpenSim's ``TableUtilities.isInDegrees``); a posture without it is refused."""
    if not table.hasTableMetaDataKey("inDegrees"):
        raise ParameterError(
            field, f"{show(str(path))}: its header must say inDegrees=yes or inDegrees=no (it says neither)"
        )
    return bool(osim.TableUtilities.isInDegrees(table))


def _frame_index(times: np.ndarray, time, path: Path, field: str) -> tuple:
    """The row of the first frame, or of ``time``; with the phrase that says which."""
    if times.size == 0:
        raise ParameterError(field, f"{show(str(path))} has no frame (no row of values)")
    if time is None:
        return 0, "its first frame" if times.size > 1 else "its one frame"
    try:
        t = float(time)
    except (TypeError, ValueError):
        t = float("nan")
    near = np.flatnonzero(np.abs(times - t) <= TIME_TOLERANCE) if np.isfinite(t) else np.zeros(0, int)
    if near.size == 0:
        raise ParameterError(
            "time",
            f"must be a time of {printable(path.name)}'s frames, to {TIME_TOLERANCE:g} s: {times.size} frame(s) from "
            f"{times[0]:g} to {times[-1]:g} s (got {show(time)})",
        )
    return int(near[0]), "the time asked"


def _matched(columns: Columns, labels, row: np.ndarray, field: str, where: str) -> dict:
    """Label -> value matched to the model's names: unknown labels, missing names, duplicates, NaN refused."""
    unknown = [lab for lab in labels if lab not in columns.names and lab not in columns.skipped]
    if unknown:
        raise ParameterError(field, f"{where}: column(s) that name no {columns.what} of the model: {_listed(unknown)}")
    values, seen = {}, {}
    for lab, value in zip(labels, row, strict=True):
        name = columns.names.get(lab)
        if name is None:
            continue
        if name in seen:
            raise ParameterError(
                field, f"{where}: columns {seen[name]!r} and {lab!r} both give {columns.what} {name!r}"
            )
        seen[name], values[name] = lab, float(value)
    missing = [name for name in columns.required if name not in values]
    if missing:
        raise ParameterError(
            field, f"{where}: every {columns.what} of the model must be given; missing {_listed(missing)}"
        )
    bad = [seen[name] for name, v in values.items() if not np.isfinite(v)]
    if bad:
        raise ParameterError(field, f"{where}: values must be finite (NaN or infinite in {_listed(bad)})")
    return values


def _listed(names) -> str:
    """Names as a message lists them: the first :data:`SHOWN`, then how many more."""
    shown = ", ".join(repr(printable(n)) for n in names[:SHOWN])
    more = len(names) - SHOWN
    return f"{shown} and {more} more ({len(names)} in all)" if more > 0 else shown


def _check_bounds(anatomy, a: np.ndarray, frame: Frame) -> None:
    """Activations within the model's control bounds ([0, 1]: EMG normalised), the first offender named."""
    lower, upper = anatomy.control_bounds()
    out = np.flatnonzero((a < lower) | (a > upper))
    if out.size:
        i = int(out[0])
        more = f"; {out.size - 1} more outside" if out.size > 1 else ""
        raise ParameterError(
            "activations",
            f"{frame.source}: must be in [{lower[i]:g}, {upper[i]:g}] (EMG normalised to its maximum) "
            f"(got {a[i]:g} for {anatomy.muscles[i]!r}{more})",
        )


def posture_columns_of(labels: dict, required, skipped=(), rotational=()) -> Columns:
    """A :class:`Columns` of coordinates (the engines' ``posture_columns`` build theirs with it).

    Parameters
    ----------
    labels : dict
        Label -> coordinate name.
    required : iterable of str
        Every coordinate a file must give.
    skipped : iterable of str
        The model's other state labels.
    rotational : iterable of str
        The coordinates in radians.

    Returns
    -------
    Columns
    """
    return Columns(dict(labels), tuple(required), frozenset(skipped), frozenset(rotational), "coordinate")


def activation_columns_of(labels: dict, required, skipped=()) -> Columns:
    """A :class:`Columns` of muscles (the engines' ``activation_columns`` build theirs with it).

    Parameters
    ----------
    labels : dict
        Label -> muscle name.
    required : iterable of str
        Every muscle a file must give.
    skipped : iterable of str
        The model's other state labels.

    Returns
    -------
    Columns
    """
    return Columns(dict(labels), tuple(required), frozenset(skipped), frozenset(), "muscle")
