"""A study of motions: trials of (model, mapping, coordinates, activations or optimum), chunked by frames.

The file (docs/motion.md, "Many trials on Dask") has a ``[study]`` table and one ``[[trials]]`` table per trial;
:func:`load_motion_study` validates it into a :class:`MotionStudy` whose chunks are ranges of a trial's frames.
Keys are checked by the engine of the model and study files (:mod:`spinectl.model._toml`), values by the small
validators (:mod:`spinectl._validate`), each named as written (``trials[2].optimise``). Every coordinates and
activations file is read (OpenSim's reader, cheap) and its frame selection checked before any work; the models
are loaded by the workers, once each (:mod:`spinectl.landscape.study.motion_run`).
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from pathlib import Path

from ... import _validate as v
from ..._validate import show
from ...errors import ConfigError, ParameterError
from ...model._toml import check_keys, check_table, parse, read_text

MOTION_FORMAT = 1
"""The layout of a motion study's store; a resume needs the same."""

SECTIONS = ("study", "trials")
STUDY_KEYS = ("description", "chunk_frames")
TRIAL_KEYS = (
    "name",
    "model",
    "mapping",
    "coordinates",
    "activations",
    "optimise",
    "frames",
    "plane",
    "joint_stiffness",
    "least_stiffness",
)

NOT_IN_A_STUDY = ("removal", "group", "groups")
"""Options of ``spinectl motion`` that a trial does not take (the removal method per frame: run the command on
the trial), refused in one line rather than as an unknown key."""

DEFAULT_CHUNK_FRAMES = 50
"""Frames per chunk: a MyoTorso frame with given activations takes tens of ms, so a chunk is seconds of work,
long beside Dask's few ms per task, short enough that a killed run loses little."""

MAX_CHUNK_FRAMES = 100_000
MAX_TRIALS = 10_000
BUILTIN_MODELS = ("myotorso",)
"""Models named rather than given as a file (resolved by :func:`spinectl.anatomy.load`)."""


@dataclass(frozen=True)
class Trial:
    """One trial: a model and a motion, and how each frame's activations are found.

    Parameters
    ----------
    name : str
        Unique among the trials (the store's file of the trial).
    model : str
        ``"myotorso"``, or an MJCF or ``.osim`` file (an absolute path).
    mapping : str or None
        A mapping TOML file (absolute), or None for the model's built-in one.
    coordinates : str
        The OpenSim coordinates file (``.mot``; absolute).
    activations : str or None
        An activations file (``.sto``; absolute), read at each frame's time.
    optimise : str
        ``"none"``, ``"joints"`` or ``"chain"`` (:func:`spinectl.anatomy.motion.motion_response`).
    frames : tuple of int
        ``(first, last, step)``: the frames analysed, by index from 0, ``last`` included.
    plane : str
        One of the mapping's planes.
    joint_stiffness : str or float
        ``"none"``, ``"mapped"`` or a stiffness [N m/rad] added at each chain joint.
    least_stiffness : float or None
        Also the least added joint stiffness at this margin [N m/rad], or None.
    """

    name: str
    model: str
    mapping: str | None
    coordinates: str
    activations: str | None
    optimise: str
    frames: tuple
    plane: str = "sagittal"
    joint_stiffness: object = "none"
    least_stiffness: float | None = None

    def chunks(self, size: int) -> list[tuple]:
        """The trial's frames cut into runs of ``size`` analysed frames, as ``(first, last, step)`` each.

        Parameters
        ----------
        size : int
            Analysed frames per run (the study's ``chunk_frames``).

        Returns
        -------
        list of tuple
            ``(first, last, step)`` frame indices of each run, in order.
        """
        first, last, step = self.frames
        starts = range(first, last + 1, step * size)
        return [(a, min(a + step * (size - 1), last), step) for a in starts]


@dataclass(frozen=True)
class MotionChunk:
    """One unit of work: a trial's range of frames.

    Attributes
    ----------
    index : int
        Position in the study's order (trials in order, frames in order).
    trial : int
        The trial's position in :attr:`MotionStudy.trials`.
    frames : tuple of int
        ``(first, last, step)`` of the file's frames.
    """

    index: int
    trial: int
    frames: tuple


@dataclass(frozen=True)
class MotionStudy:
    """A validated study of motions: its trials and its chunks of frames.

    Parameters
    ----------
    trials : tuple of Trial
        At least one, names unique.
    chunk_frames : int
        Analysed frames per chunk, in [1, :data:`MAX_CHUNK_FRAMES`].
    description : str
        Free text, stored with the results.
    text : str
        The study file as written, stored with the results.
    recordings : dict
        ``(path, field)`` -> the :class:`~spinectl.anatomy.recordings.Recording` read when the file was
        checked (:func:`parse_motion_study`), for the workers, which then need neither the file nor OpenSim;
        empty: each worker reads the files.
    """

    trials: tuple
    chunk_frames: int = DEFAULT_CHUNK_FRAMES
    description: str = ""
    text: str = field(default="", compare=False)
    recordings: dict = field(default_factory=dict, compare=False, repr=False)

    def __post_init__(self):
        object.__setattr__(
            self, "chunk_frames", v.integer("study.chunk_frames", self.chunk_frames, 1, MAX_CHUNK_FRAMES)
        )
        if not isinstance(self.description, str):
            raise ParameterError("study.description", f"must be a string (got {show(self.description)})")
        chunks = [(t, f) for t, trial in enumerate(self.trials) for f in trial.chunks(self.chunk_frames)]
        object.__setattr__(self, "_chunks", tuple(MotionChunk(i, t, f) for i, (t, f) in enumerate(chunks)))

    @property
    def n_chunks(self) -> int:
        """Number of chunks of the study."""
        return len(self._chunks)

    def chunk(self, index: int) -> MotionChunk:
        """The chunk at position ``index``.

        Parameters
        ----------
        index : int
            0 <= index < :attr:`n_chunks`.

        Returns
        -------
        MotionChunk
        """
        return self._chunks[int(index)]

    def chunks_of(self, trial: int) -> list[MotionChunk]:
        """The chunks of one trial, in the order of its frames.

        Parameters
        ----------
        trial : int
            The trial's position in :attr:`trials`.

        Returns
        -------
        list of MotionChunk
        """
        return [c for c in self._chunks if c.trial == trial]

    def digest(self) -> str:
        """SHA-256 of what fixes the numbers and the layout: every trial's settings and its files' bytes, the chunking.

        A file edited between a run and its resume changes it (the chunks done would be of the old file);
        the study file's comments and spacing do not.

        Returns
        -------
        str
            64 hexadecimal digits.
        """
        trials = []
        for t in self.trials:
            files = {k: _file_digest(getattr(t, k)) for k in ("model", "mapping", "coordinates", "activations")}
            trials.append(
                [t.name, t.optimise, list(t.frames), t.plane, str(t.joint_stiffness), t.least_stiffness, files]
            )
        content = {"format": MOTION_FORMAT, "trials": trials, "chunk_frames": self.chunk_frames}
        return hashlib.sha256(json.dumps(content, sort_keys=True).encode()).hexdigest()


def _file_digest(path) -> str | None:
    """SHA-256 of a file's bytes; a built-in model's name or None as itself."""
    if path is None or path in BUILTIN_MODELS:
        return path
    digest = hashlib.sha256()
    with open(path, "rb") as file:
        for block in iter(lambda: file.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def is_motion_study(text: str, source: str = "study") -> bool:
    """Whether a study file's text is a study of motions (it has ``[[trials]]``) rather than a parameter study.

    Parameters
    ----------
    text : str
        The file's TOML.
    source : str
        Where it came from, for a TOML error's message.

    Returns
    -------
    bool
    """
    try:
        return "trials" in parse(text, source)
    except ConfigError:
        return False  # the parameter study's reader says what is wrong, in its words


def load_motion_study(path: str | Path) -> MotionStudy:
    """Read and validate a study of motions (TOML; docs/motion.md, "Many trials on Dask").

    Parameters
    ----------
    path : str or Path
        The study file; the files it names are relative to its folder.

    Returns
    -------
    MotionStudy

    Raises
    ------
    ConfigError
        Not readable, not TOML, an unknown section or key ("did you mean").
    ParameterError
        A value is invalid, a file is missing or unreadable, a frame selection outside its file; the field
        named as written (``trials[1].frames``).
    """
    path = Path(path)
    text = read_text(path, "study")
    return parse_motion_study(text, path.parent, str(path))


def parse_motion_study(text: str, base_dir: str | Path = ".", source: str = "study") -> MotionStudy:
    """A :class:`MotionStudy` from the text of its file (see :func:`load_motion_study`).

    Parameters
    ----------
    text : str
        The study file's TOML text.
    base_dir : str or pathlib.Path
        The folder the file's relative paths are read from (the study file's).
    source : str
        The name errors give the file.

    Returns
    -------
    MotionStudy

    Raises
    ------
    spinectl.errors.ConfigError
        One line naming the key as written and what is allowed.
    """
    try:
        data = parse(text, source)
    except ConfigError as exc:
        raise ConfigError("study", exc.message) from None
    check_keys(data, SECTIONS)
    head = data.get("study", {})
    check_table(head, "study")
    check_keys(head, STUDY_KEYS, "study")
    rows = data.get("trials")
    if not isinstance(rows, list) or not rows or not all(isinstance(r, dict) for r in rows):
        raise ParameterError("trials", "must be one or more [[trials]] tables")
    if len(rows) > MAX_TRIALS:
        raise ParameterError("trials", f"at most {MAX_TRIALS:,} trials (got {len(rows):,})")
    kept = {}  # trials of one motion file read (and check) it once: OpenSim's reader takes 0.1-0.5 s a file
    trials = tuple(_trial(f"trials[{i}]", row, Path(base_dir), _reader(kept)) for i, row in enumerate(rows))
    names = [t.name for t in trials]
    for i, name in enumerate(names):
        if name in names[:i]:
            raise ParameterError(f"trials[{i}].name", f"must be unique among the trials (repeated: {show(name)})")
    chunk_frames, description = head.get("chunk_frames", DEFAULT_CHUNK_FRAMES), head.get("description", "")
    return MotionStudy(trials, chunk_frames, description, text, kept)


def _trial(where: str, row: dict, base: Path, read=None) -> Trial:
    """One ``[[trials]]`` table: keys, values, files; its frames checked against its coordinates file.

    ``read(where, path, field)`` reads a recording (default :func:`_read`): the caller's may keep those read.
    """
    from ...anatomy.motion import OPTIMISE, select_frames

    for key in NOT_IN_A_STUDY:
        if key in row:
            raise ParameterError(
                f"{where}.{key}",
                "is not supported in a study of motions: run spinectl motion --removal [--group] on the trial",
            )
    check_keys(row, TRIAL_KEYS, where)
    for key in ("name", "model", "coordinates"):
        if key not in row:
            raise ParameterError(f"{where}.{key}", "is required")
    name = v.label(f"{where}.name", row["name"])
    if "/" in name or name in (".", ".."):
        raise ParameterError(f"{where}.name", f"must not contain '/' (it names the trial's file; got {show(name)})")
    model = _string(f"{where}.model", row["model"])
    model = model if model in BUILTIN_MODELS else _file(f"{where}.model", model, base)
    files = {
        k: _file(f"{where}.{k}", _string(f"{where}.{k}", row[k]), base) if k in row else None
        for k in ("mapping", "coordinates", "activations")
    }
    optimise = v.choice(f"{where}.optimise", row.get("optimise", "none"), OPTIMISE)
    if optimise != "none" and files["activations"] is not None:
        raise ParameterError(f"{where}.activations", "cannot go with optimise, which finds the activations itself")
    read = read or _read
    recording = read(f"{where}.coordinates", files["coordinates"], "posture")  # OpenSim's reader, once here
    if files["activations"] is not None:
        read(f"{where}.activations", files["activations"], "activations")
    n = recording.times.size
    frames = _frames(f"{where}.frames", row.get("frames"), n)
    select_frames(recording.times, frames, None, (f"{where}.frames", "rate"))
    return Trial(
        name=name,
        model=model,
        mapping=files["mapping"],
        coordinates=files["coordinates"],
        activations=files["activations"],
        optimise=optimise,
        frames=frames,
        plane=_string(f"{where}.plane", row.get("plane", "sagittal")),
        joint_stiffness=_stiffness(f"{where}.joint_stiffness", row.get("joint_stiffness", "none")),
        least_stiffness=None
        if "least_stiffness" not in row
        else _bounded(f"{where}.least_stiffness", row["least_stiffness"]),
    )


KEPT_BYTES = 256 * 2**20
"""The most bytes of recordings a study keeps for its workers (:attr:`MotionStudy.recordings`); the files
past it are read by the workers, so that a study of many long trials does not hold them all in memory."""


def _reader(kept: dict):
    """:func:`_read`, keeping each file's recording in ``kept`` (by path and field) up to :data:`KEPT_BYTES`:
    a file named by many trials is read once."""

    held = [0]  # bytes kept so far

    def read(where: str, path: str, field: str):
        if (path, field) in kept:
            return kept[path, field]
        recording = _read(where, path, field)
        size = recording.values.nbytes + recording.times.nbytes
        if held[0] + size <= KEPT_BYTES:
            kept[path, field], held[0] = recording, held[0] + size
        return recording

    return read


def _read(where: str, path: str, field: str):
    """A recording read by OpenSim's reader; its one-line refusal named by the trial's key."""
    from ...anatomy.recordings import read_recording

    try:
        return read_recording(path, field)
    except ParameterError as exc:
        raise ParameterError(where, exc.message) from None


def _string(where: str, value) -> str:
    if not isinstance(value, str) or not value:
        raise ParameterError(where, f"must be a non-empty string (got {show(value)})")
    return value


def _file(where: str, name: str, base: Path) -> str:
    """A file named relative to the study file's folder, as an absolute path; refused if it is not a readable file."""
    path = (base / name).resolve()
    if not path.is_file():
        raise ParameterError(where, f"must be a file (relative to the study file's folder; got {show(str(path))})")
    return str(path)


def _frames(where: str, value, n: int) -> tuple:
    """``"FIRST:LAST[:STEP]"`` or ``[first, last, step]``; default every frame of the file."""
    if value is None:
        return (0, n - 1, 1)
    parts = value.split(":") if isinstance(value, str) else value
    try:
        if not isinstance(parts, list) or len(parts) not in (2, 3):
            raise ValueError
        numbers = [int(p) if isinstance(p, str) else p for p in parts]
        if not all(isinstance(x, int) and not isinstance(x, bool) for x in numbers):
            raise ValueError
    except ValueError:
        raise ParameterError(
            where, f'must be "FIRST:LAST" or "FIRST:LAST:STEP", frame indices from 0 (got {show(value)})'
        ) from None
    return tuple((numbers + [1])[:3])


def _stiffness(where: str, value):
    """``joint_stiffness``: ``"none"``, ``"mapped"`` or a number in [0, MAX_STIFFNESS] N m/rad."""
    if isinstance(value, str):
        return v.choice(where, value, ("none", "mapped"))
    return _bounded(where, value)


def _bounded(where: str, value) -> float:
    from ...anatomy.mapping import MAX_STIFFNESS

    return v.in_range(where, value, 0.0, MAX_STIFFNESS)
