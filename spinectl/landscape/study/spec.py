"""The study: a validated :class:`Study` and its plan of chunks (docs/studies.md).

The work is cut into chunks: one combination of the parameter axes (and sample) times a tile of the
grid, each solved as one stacked problem by the fast path
(:func:`spinectl.landscape.columns.point_columns`). The chunks are fixed by the study alone, never by
the workers, so every worker count gives the same bits.
"""

from __future__ import annotations

import hashlib
import json
import math
import numbers
from dataclasses import dataclass, field

import numpy as np

from ... import _validate as v
from ..._validate import show
from ...errors import ConfigError, ParameterError, SpinectlError
from ...model import config
from ...model._toml import check_keys, locate, quoted_key, unknown_message
from ...model.checks import validate_grid
from ...model.params import Model
from .. import schema, sweep

ALIASES = {"K": "passive.stiffness", "delay": "reflex.delay"}
"""Short axis names: the dimension keeps the short name (``K``, as in ``spinectl sweep --K``)."""

GRID = ("E", "Lambda")
"""The grid axes, always the last two dimensions before ``segment`` and ``muscle``."""

SAMPLE = "sample"
"""The dimension of the Monte-Carlo draws."""

DISTRIBUTIONS = {"normal": ("mean", "std"), "uniform": ("low", "high"), "lognormal": ("median", "sigma")}
"""Distributions of ``[samples.parameters]`` and their arguments, in the parameter's unit
(``sigma``: of the logarithm). A draw is mean + std z, low + (high - low) u, median exp(sigma z)
with z standard normal, u uniform on [0, 1)."""

DEFAULT_CHUNK_POINTS = 4096
"""Grid points per chunk: one stacked problem of this size takes about 1.5 s and 65 MB of working
memory, so Python and scheduling overheads vanish and a killed study loses little."""

MAX_CHUNK_POINTS = 65536
"""Largest chunk: the stacked problem's working memory grows linearly, about 16 kB a point
(tracemalloc peak of ``columns.point_columns``), so about 1 GB at this size."""

MAX_COMBINATIONS = 10_000
"""Most combinations of the parameter axes and samples: each is validated before any work
starts (a few ms each: half a minute at most), and each needs at least one chunk."""

MAX_CHUNKS = 1_000_000
"""Most chunks of a study: each chunk is a file of every output plus its count and CRC-32 (23 million
files here with every output), and the client keeps three integers a chunk; a study of more is one of
tiny chunks (raise ``chunk_size``) or beyond what a store on one machine holds."""

STORE_FORMAT = 1
"""Version of the store layout (:mod:`spinectl.landscape.study.store`); part of :meth:`Study.digest`."""


def _scalars(where: str, values) -> tuple:
    """Coordinate values: all finite numbers (ints stay ints) or all strings, distinct, at least one."""
    items = v._sequence(where, values, "a list of numbers or strings")
    if not items:
        raise ParameterError(where, "must have at least one value")
    if any(isinstance(x, str) for x in items) and not all(isinstance(x, str) for x in items):
        raise ParameterError(where, f"must be all numbers or all strings (got {show(list(items))})")
    out = tuple(_scalar(f"{where}[{i}]", x) for i, x in enumerate(items))
    if len(set(out)) != len(out):
        raise ParameterError(where, f"must not repeat a value (got {show(list(out))})")
    return out


def _scalar(where: str, value):
    if isinstance(value, str):
        return v.label(where, value)
    number = v.real(where, value)  # rejects bools, NaN, inf and ints too large for a float
    return int(value) if isinstance(value, numbers.Integral) else number


def grid_axis(name: str, values) -> tuple[float, ...]:
    """A grid axis of a study, validated; errors name it as the study file does (``axes.E[2]``).

    Parameters
    ----------
    name : str
        ``"E"`` or ``"Lambda"``.
    values : sequence of float
        The axis [m]: distinct finite numbers, at least one.

    Returns
    -------
    tuple of float
        The values [m].

    Raises
    ------
    ParameterError
        Not numbers, not finite, repeated or empty.
    """
    values = _scalars(f"axes.{name}", values)
    return tuple(v.real(f"axes.{name}[{i}]", x) for i, x in enumerate(values))


def _check_name(where: str, parameter: str, model: Model) -> None:
    """``parameter`` must name one value of the model: a ConfigError ("did you mean") otherwise."""
    try:
        holder, key = locate(config.to_dict(model), parameter)
    except ConfigError as exc:
        raise ConfigError(where, exc.message) from None
    node = holder[key]
    if isinstance(node, (dict, list)) and node:
        example = f"{parameter}.{next(iter(node)) if isinstance(node, dict) else 0}"
        raise ParameterError(where, f"{parameter} is a table or a list: name one of its values, e.g. {example}")


@dataclass(frozen=True)
class Axis:
    """One parameter axis of a study: a dimension of the results.

    Parameters
    ----------
    name : str
        Dotted parameter (``"body.mass"``, ``"muscles.0.spread"``) or an alias of :data:`ALIASES`;
        the name of the dimension.
    values : tuple
        The parameter's values (numbers or strings), in its unit; distinct.
    """

    name: str
    values: tuple

    def __post_init__(self):
        object.__setattr__(self, "values", _scalars(quoted_key("axes", self.name), self.values))

    @property
    def parameter(self) -> str:
        """The dotted parameter that this axis sets."""
        return ALIASES.get(self.name, self.name)


@dataclass(frozen=True)
class Sampled:
    """Monte-Carlo draws of one parameter, fixed by the seed of :class:`Samples`.

    Parameters
    ----------
    parameter : str
        Dotted parameter, e.g. ``"body.mass"``.
    distribution : str
        A key of :data:`DISTRIBUTIONS`.
    arguments : tuple of (str, float)
        The distribution's arguments by name, e.g. ``(("mean", 40.0), ("std", 4.0))``.
    """

    parameter: str
    distribution: str
    arguments: tuple

    def __post_init__(self):
        where = quoted_key("samples.parameters", self.parameter)
        v.choice(f"{where}.distribution", self.distribution, tuple(DISTRIBUTIONS))
        names = DISTRIBUTIONS[self.distribution]
        given = dict(self.arguments)
        check_keys(given, names, where)
        missing = [n for n in names if n not in given]
        if missing:
            raise ParameterError(where, f"a {self.distribution} distribution needs {', '.join(missing)}")
        args = {n: v.real(f"{where}.{n}", given[n]) for n in names}
        if self.distribution == "uniform" and not args["low"] < args["high"]:
            raise ParameterError(f"{where}.high", f"must be > low = {args['low']:g} (got {args['high']:g})")
        if self.distribution == "lognormal":
            v.positive(f"{where}.median", args["median"])
        if self.distribution != "uniform":
            v.non_negative(f"{where}.{names[1]}", args[names[1]])
        object.__setattr__(self, "arguments", tuple(args.items()))

    def draw(self, count: int, seed: int) -> np.ndarray:
        """``count`` draws [the parameter's unit], from a stream of their own.

        Each parameter's stream is seeded by ``seed`` and its name, so adding or
        removing another sampled parameter leaves these draws unchanged.

        Parameters
        ----------
        count : int
            Number of draws.
        seed : int
            Seed of the study's samples.

        Returns
        -------
        numpy.ndarray, shape (count,)
            The draws, in the unit of the parameter.
        """
        rng = np.random.default_rng([seed, *self.parameter.encode()])
        a, b = (value for _, value in self.arguments)
        if self.distribution == "uniform":
            return a + (b - a) * rng.random(count)
        z = rng.standard_normal(count)
        return a + b * z if self.distribution == "normal" else a * np.exp(b * z)


def sample_count(count) -> int:
    """``samples.count``, validated: each draw is a combination, so at most :data:`MAX_COMBINATIONS`.

    Parameters
    ----------
    count : object
        As written in the study file.

    Returns
    -------
    int
        The number of draws.

    Raises
    ------
    ParameterError
        Not an integer, or not in [1, :data:`MAX_COMBINATIONS`]; the message gives the bound and its reason.
    """
    try:
        return v.integer("samples.count", count, 1, MAX_COMBINATIONS)
    except ParameterError as exc:
        raise ParameterError(
            "samples.count",
            exc.message.replace(" (got", ": each draw is a combination, all checked before any work (got"),
        ) from None


@dataclass(frozen=True)
class Samples:
    """Monte-Carlo draws: one ``sample`` dimension of ``count`` draws of several parameters.

    Parameters
    ----------
    count : int
        Number of draws (the length of the ``sample`` dimension).
    seed : int
        Seed (>= 0): the same seed gives the same draws, so a resumed study sees the same ones.
    parameters : tuple of Sampled
        The parameters drawn, each independently.
    """

    count: int
    seed: int
    parameters: tuple[Sampled, ...]

    def __post_init__(self):
        object.__setattr__(self, "count", sample_count(self.count))
        object.__setattr__(self, "seed", v.integer("samples.seed", self.seed, 0))
        if not self.parameters:
            raise ParameterError("samples.parameters", "must name at least one parameter to draw")
        names = [p.parameter for p in self.parameters]
        for name in {n for n in names if names.count(n) > 1}:
            raise ParameterError(quoted_key("samples.parameters", name), "is given twice")
        draws = {p.parameter: p.draw(self.count, self.seed) for p in self.parameters}
        for values in draws.values():
            values.flags.writeable = False
        object.__setattr__(self, "_draws", draws)  # drawn once: every combination reads them

    def values(self) -> dict[str, np.ndarray]:
        """The draws of every parameter by name, shape (count,) each (read-only).

        Returns
        -------
        dict of str to numpy.ndarray
            ``{dotted parameter: draws}``, each of shape (count,) in the parameter's unit;
            a new dict, the arrays read-only.
        """
        return dict(self._draws)


@dataclass(frozen=True)
class Chunk:
    """One unit of work: a combination of the parameter axes times a tile of the grid.

    Attributes
    ----------
    index : int
        Position in the study's chunk order (combinations outer, tiles inner, C order).
    combination : tuple of int
        Index along each parameter dimension (:attr:`Study.dims`).
    eccentricity, lordosis : slice
        The tile: indices into the E and Lambda axes.
    """

    index: int
    combination: tuple[int, ...]
    eccentricity: slice
    lordosis: slice


@dataclass(frozen=True)
class Study:
    """A validated parameter study: base model, grid, parameter axes, samples, outputs, chunking.

    Construction validates everything a worker will need, so that a bad value
    stops the study before any work: every axis value and every draw through
    :func:`spinectl.model.config.set_parameters`, then every combination together,
    on the whole grid (:func:`spinectl.model.checks.validate_grid`).
    Field names in errors are those of the study file (``axes."body.mass"[2]``).

    Parameters
    ----------
    model : Model
        The base model; axes and samples replace some of its parameters.
    eccentricity, lordosis : tuple of float
        The grid axes E and Lambda [m].
    axes : tuple of Axis
        Parameter axes, one dimension each, in this order.
    samples : Samples or None
        Monte-Carlo draws (a ``sample`` dimension after the axes), or none.
    outputs : tuple of str
        Variables of :data:`spinectl.landscape.schema.VARIABLES` to keep (default: all but
        :data:`~spinectl.landscape.schema.ON_REQUEST`, the coupled chain's SDPs).
    chunk_size : int
        Grid points per chunk: tiles of whole rows (every Lambda of some E) where a row fits.
    description : str
        Free text, stored with the results.
    text : str
        The study file as written, stored with the results.

    Raises
    ------
    ConfigError
        An axis or draw names no parameter of the model ("did you mean"), or an unknown output.
    ParameterError
        A value is invalid alone, or with the others of its combination; too many points,
        combinations or chunks (:data:`MAX_CHUNKS`).
    ModelError
        A combination cannot be evaluated at a point of the grid.
    """

    model: Model
    eccentricity: tuple
    lordosis: tuple
    axes: tuple[Axis, ...] = ()
    samples: Samples | None = None
    outputs: tuple[str, ...] = tuple(name for name in schema.VARIABLES if name not in schema.ON_REQUEST)
    chunk_size: int = DEFAULT_CHUNK_POINTS
    description: str = ""
    text: str = field(default="", compare=False)

    def __post_init__(self):
        if not isinstance(self.model, Model):
            raise ParameterError("study.model", f"must be a Model (got {show(self.model)})")
        if self.samples is not None and not isinstance(self.samples, Samples):
            raise ParameterError("study.samples", f"must be Samples or None (got {show(self.samples)})")
        if not all(isinstance(a, Axis) for a in self.axes):
            raise ParameterError("study.axes", f"must be a sequence of Axis (got {show(self.axes)})")
        object.__setattr__(self, "axes", tuple(self.axes))
        for name, axis in zip(GRID, (self.eccentricity, self.lordosis), strict=True):
            object.__setattr__(self, "eccentricity" if name == "E" else "lordosis", grid_axis(name, axis))
        if len(self.eccentricity) * len(self.lordosis) > sweep.MAX_GRID_POINTS:
            raise ParameterError("axes", f"the E x Lambda grid must have at most {sweep.MAX_GRID_POINTS:,} points")
        object.__setattr__(self, "outputs", self._outputs(self.outputs))
        chunk = v.integer("study.chunk_size", self.chunk_size, 1, MAX_CHUNK_POINTS)
        object.__setattr__(self, "chunk_size", chunk)
        if not isinstance(self.description, str):
            raise ParameterError("study.description", f"must be a string (got {show(self.description)})")
        self._check_parameters()
        if math.prod(self.shape) > MAX_COMBINATIONS:
            raise ParameterError("axes", f"at most {MAX_COMBINATIONS:,} combinations of axes and samples")
        if self.n_chunks > MAX_CHUNKS:  # before the combinations' checks, which take a few ms each
            raise ParameterError(
                "study.chunk_size",
                f"gives {self.n_chunks:,} chunks, more than the {MAX_CHUNKS:,} a store can hold (a file of every "
                f"output each): raise chunk_size (at most {MAX_CHUNK_POINTS:,}) or use fewer points",
            )
        checked_shapes: set = set()  # geometry and muscles whose attachments passed on the whole grid
        for combination in np.ndindex(*self.shape):
            self._check_combination(combination, checked_shapes)

    @staticmethod
    def _outputs(outputs) -> tuple[str, ...]:
        names = v._sequence("study.outputs", outputs, "a list of variable names")
        if not names:
            raise ParameterError("study.outputs", "must name at least one variable")
        for i, name in enumerate(names):
            if isinstance(name, str) and name in schema.DRAW_VARIABLES:  # not "did you mean" another quantity
                raise ConfigError(
                    f"study.outputs[{i}]",
                    f"must be a landscape variable; {show(name)} is an output of the atlas's draws (spinectl atlas)",
                )
            if not isinstance(name, str) or name not in schema.VARIABLES:
                raise ConfigError(f"study.outputs[{i}]", unknown_message(str(name), schema.VARIABLES))
            if name in names[:i]:  # a typo for another output, most likely: not silently one array
                raise ParameterError(f"study.outputs[{i}]", f"must name each output once (repeated: {show(name)})")
        return tuple(names)

    def _check_parameters(self) -> None:
        """Each axis value and draw alone; no parameter twice; no change of the outputs' shape."""
        seen: dict[str, str] = {}
        drawn = self.samples.values() if self.samples else {}
        named = [(quoted_key("axes", a.name), a.parameter, a.values) for a in self.axes]
        named += [(quoted_key("samples.parameters", p), p, d.tolist()) for p, d in drawn.items()]
        shape = (self.model.geometry.cor_names, self.model.muscle_names)
        for where, parameter, values in named:
            _check_name(where, parameter, self.model)
            if parameter in seen:
                raise ParameterError(where, f"sets {parameter}, which {seen[parameter]} sets already")
            seen[parameter] = where
            for i, value in enumerate(values):
                try:
                    model = config.set_parameters(self.model, {parameter: value})
                except ParameterError as exc:
                    raise type(exc)(f"{where}[{i}]", f"{exc.field}: {exc.message}") from None
                if (model.geometry.cor_names, model.muscle_names) != shape:
                    raise ParameterError(where, "must not rename the segments or muscles: outputs need one shape")

    def _check_combination(self, combination, checked_shapes: set) -> None:
        """One combination of values together, on the whole grid (:func:`validate_grid`); errors name the combination.

        ``checked_shapes`` holds the (geometry, muscles) whose attachments passed already:
        they alone decide that check, so it runs once per distinct pair, not per combination.
        """
        overrides = self.overrides(combination)
        values = ", ".join(f"{k} = {show(x)}" for k, x in overrides.items())
        where = f" (study combination {values})" if values else ""
        try:
            model = config.set_parameters(self.model, overrides)
            shape = (model.geometry, model.muscles)
            validate_grid(
                model, self.eccentricity, self.lordosis, self.chunk_size, attachments=shape not in checked_shapes
            )
            checked_shapes.add(shape)
        except ParameterError as exc:
            raise type(exc)(exc.field, exc.message + where) from None
        except SpinectlError as exc:
            raise type(exc)(str(exc) + where) from None

    @property
    def dims(self) -> tuple[str, ...]:
        """The parameter dimensions: the axes in order, then ``sample`` if there are samples."""
        return tuple(a.name for a in self.axes) + ((SAMPLE,) if self.samples else ())

    @property
    def shape(self) -> tuple[int, ...]:
        """Length of each of :attr:`dims`."""
        return tuple(len(a.values) for a in self.axes) + ((self.samples.count,) if self.samples else ())

    def overrides(self, combination) -> dict:
        """The parameters that one combination sets, by dotted name, as plain Python values.

        Parameters
        ----------
        combination : tuple of int
            Index along each of :attr:`dims`.

        Returns
        -------
        dict
            ``{dotted parameter: value}`` in each parameter's unit, ready for
            :func:`spinectl.model.config.set_parameters`; empty without axes or samples.
        """
        out = {a.parameter: a.values[i] for a, i in zip(self.axes, combination, strict=False)}
        if self.samples:
            k = combination[len(self.axes)]
            out |= {name: values[k].item() for name, values in self.samples.values().items()}
        return out

    @property
    def tile(self) -> tuple[int, int]:
        """Grid points of a chunk along E and Lambda: whole rows of Lambda while ``chunk_size`` allows."""
        n_lambda = min(len(self.lordosis), self.chunk_size)
        return max(1, min(len(self.eccentricity), self.chunk_size // n_lambda)), n_lambda

    @property
    def tiles(self) -> tuple[int, int]:
        """Number of tiles along E and Lambda."""
        return tuple(-(-n // t) for n, t in zip(self.grid_shape, self.tile, strict=True))

    @property
    def grid_shape(self) -> tuple[int, int]:
        """Points along E and Lambda."""
        return len(self.eccentricity), len(self.lordosis)

    @property
    def n_chunks(self) -> int:
        """Number of chunks of the study."""
        return math.prod(self.shape) * math.prod(self.tiles)

    def chunk(self, index: int) -> Chunk:
        """The chunk at position ``index`` of the study's order.

        Parameters
        ----------
        index : int
            0 <= index < :attr:`n_chunks`.

        Returns
        -------
        Chunk
            Its index, the combination of the parameter axes and the slices of the E and
            Lambda axes that make its tile.
        """
        combination, tile = divmod(int(index), math.prod(self.tiles))
        i_e, i_l = divmod(tile, self.tiles[1])
        (b_e, b_l), (n_e, n_l) = self.tile, self.grid_shape
        return Chunk(
            index=int(index),
            combination=tuple(int(i) for i in np.unravel_index(combination, self.shape)) if self.shape else (),
            eccentricity=slice(i_e * b_e, min((i_e + 1) * b_e, n_e)),
            lordosis=slice(i_l * b_l, min((i_l + 1) * b_l, n_l)),
        )

    def digest(self) -> str:
        """SHA-256 of everything that fixes the numbers and the layout of the results.

        The resolved base model, the grid, the axes, the drawn values, the
        outputs and the tiling, not the file's text: comments and spacing may
        change between a run and its resume, a value may not.

        Returns
        -------
        str
            64 hexadecimal digits.
        """
        content = {
            "format": STORE_FORMAT,
            "model": config.dump_toml(self.model),
            "grid": [list(self.eccentricity), list(self.lordosis)],
            "axes": [[a.name, a.parameter, list(a.values)] for a in self.axes],
            "samples": {k: d.tolist() for k, d in self.samples.values().items()} if self.samples else None,
            "outputs": list(self.outputs),
            "tile": list(self.tile),
        }
        return hashlib.sha256(json.dumps(content, sort_keys=True).encode()).hexdigest()
