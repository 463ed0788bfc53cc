"""The study file: TOML read, checked against its schema and turned into a :class:`~.spec.Study`.

The format is that of ``docs/studies.md``. Keys are checked by the engine of the model files
(:mod:`spinectl.model._toml`), so a study file and a model file report the same mistakes in the same
words; the values are validated by the dataclasses of :mod:`spinectl.landscape.study.spec`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ... import _validate as v
from ..._validate import escaped, show
from ...errors import ConfigError, ParameterError
from ...model import config
from ...model._toml import check_keys, check_table, flatten, parse, quoted_key, read_text
from ...model.checks import check_axis_range
from ...model.params import Model
from ...units import CM_PER_M
from .. import sweep
from .spec import GRID, Axis, Sampled, Samples, Study, grid_axis, sample_count

SECTIONS = ("study", "model", "axes", "samples")
ANGLE_AXIS = "lordosis_angle_deg"
"""The lordosis grid axis as an angle [deg], instead of ``axes.Lambda`` [m] (docs/atlas.md)."""
"""The sections of a study file."""

STUDY_KEYS = ("preset", "config", "outputs", "chunk_size", "description")
"""The keys of ``[study]``."""

SAMPLE_KEYS = ("count", "seed", "parameters")
"""The keys of ``[samples]``."""

RANGE_KEYS = ("start", "stop", "num")
"""The keys of a range of values, ``{ start, stop, num }``."""


def load_study(path: str | Path, overrides=()) -> Study:
    """Read and validate a study file (TOML; ``docs/studies.md``).

    Parameters
    ----------
    path : str or Path
        The study file; a ``config`` it names is relative to its folder.
    overrides : sequence of str
        ``SECTION.FIELD=VALUE`` assignments on the study's base model, after its ``[model]``
        (``spinectl study --set``; :func:`spinectl.model.config.apply_overrides`).

    Returns
    -------
    Study
        The validated study, with the file's text.

    Raises
    ------
    ConfigError
        The file cannot be read, is not TOML, or has an unknown key ("did you mean").
    ParameterError
        A value is invalid; the field is named as in the file, e.g. ``axes."body.mass"[2]``.
    """
    path = Path(path)
    text = read_text(path, "study")
    return parse_study(text, base_dir=path.parent, source=str(path), overrides=overrides)


def parse_study(text: str, base_dir: str | Path = ".", source: str = "study", overrides=()) -> Study:
    """A :class:`~.spec.Study` from the text of a study file.

    Parameters
    ----------
    text : str
        TOML with the sections ``[study]``, ``[model]``, ``[axes]``, ``[samples]``.
    base_dir : str or Path
        Folder against which ``study.config`` is resolved.
    source : str
        Where the text came from, for messages.
    overrides : sequence of str
        ``SECTION.FIELD=VALUE`` assignments on the base model, after its ``[model]``
        (:func:`spinectl.model.config.apply_overrides`).

    Returns
    -------
    Study
        The validated study, with ``text``.

    Raises
    ------
    ConfigError
        Not TOML, an unknown section or key ("did you mean"), a section that is not a table,
        or a base model that cannot be loaded.
    ParameterError
        A value is invalid, or ``axes.E`` or ``axes.Lambda`` is missing or beyond the model's range
        (named as written, with the value in metres where cm were likely meant).
    """
    try:
        data = parse(text, source)
    except ConfigError as exc:
        raise ConfigError("study", exc.message) from None
    for key, value in data.items():  # key by key: the first section that is wrong is the one named
        check_keys((key,), SECTIONS)
        check_table(value, escaped(key))
    head = data.get("study", {})
    check_keys(head, STUDY_KEYS, "study")
    axes = flatten(data.get("axes", {}), "axes", lambda x: any(k in x for k in RANGE_KEYS))
    for name in GRID:
        if name not in axes and not (name == "Lambda" and ANGLE_AXIS in axes):
            raise ParameterError(f"axes.{name}", "is required: a list of values or { start, stop, num } [m]")
    options = {k: head[k] for k in ("outputs", "chunk_size", "description") if k in head}
    model = config.apply_overrides(_base_model(head, data.get("model"), Path(base_dir)), overrides)
    return Study(
        model=model,
        eccentricity=_grid_axis("E", axes.pop("E"), model.geometry.eccentricity_range),
        lordosis=_lordosis_axis(axes, model),
        axes=tuple(Axis(name, _axis_values(quoted_key("axes", name), value)) for name, value in axes.items()),
        samples=_samples(data["samples"]) if "samples" in data else None,
        text=text,
        **options,
    )


def _axis_values(where: str, value) -> tuple:
    """An axis: ``{ start, stop, num }`` (inclusive, evenly spaced), a list, or one value."""
    if not isinstance(value, dict):
        return tuple(value) if isinstance(value, list) else (value,)
    check_keys(value, RANGE_KEYS, where)
    missing = [k for k in RANGE_KEYS if k not in value]
    if missing:
        raise ParameterError(where, f"a range needs start, stop and num (missing {', '.join(missing)})")
    start, stop = v.real(f"{where}.start", value["start"]), v.real(f"{where}.stop", value["stop"])
    num = v.integer(f"{where}.num", value["num"], 1, sweep.MAX_GRID_POINTS)
    return tuple(v.linear_range(where, start, stop, num, _toml_axis(value), sweep.MAX_GRID_POINTS, table=True).tolist())


def _grid_axis(name: str, written, bounds) -> tuple[float, ...]:
    """A grid axis, refused beyond ``bounds`` [m] as written in the file: its range or its values, not a point."""
    values = grid_axis(name, _axis_values(f"axes.{name}", written))
    check_axis_range(f"axes.{name}", values, bounds, _toml_axis(written), _toml_axis(written, CM_PER_M))
    return values


def _lordosis_axis(axes: dict, model) -> tuple[float, ...]:
    """``axes.Lambda`` [m], or ``axes.lordosis_angle_deg`` [deg] converted to Lambda (popped from ``axes``).

    The angle is the one between the spine line's end tangents, Lambda = L tan(theta / 2) / (2 phi'(0))
    (:func:`spinectl.model.clinical.lordosis_from_angle`; docs/atlas.md): evenly spaced in degrees, so not in Lambda.
    """
    from ...model.clinical import lordosis_angle, lordosis_from_angle

    bounds = model.geometry.lordosis_range
    if ANGLE_AXIS not in axes:
        return _grid_axis("Lambda", axes.pop("Lambda"), bounds)
    where = f"axes.{ANGLE_AXIS}"
    if "Lambda" in axes:
        raise ParameterError(where, "and axes.Lambda both give the lordosis: give one of them")
    written = axes.pop(ANGLE_AXIS)
    angles = np.array(grid_axis(ANGLE_AXIS, _axis_values(where, written)))
    try:
        values = tuple(lordosis_from_angle(angles, model).tolist())
    except ParameterError as exc:
        raise ParameterError(where, exc.message) from None
    low, high = bounds
    if min(values) < low or max(values) > high:
        a_low, a_high = lordosis_angle([low, high], model)
        raise ParameterError(
            where,
            f"must be within [{a_low:.6g}, {a_high:.6g}] deg, the modelled range of Lambda (got {_toml_axis(written)})",
        )
    return values


def _toml_axis(written, scale: float = 1.0) -> str:
    """An axis as the file writes it, its lengths divided by ``scale``; a long list shortened with ``...``."""
    if isinstance(written, dict):
        return f"{{ start = {written['start'] / scale:g}, stop = {written['stop'] / scale:g}, num = {written['num']} }}"
    if not isinstance(written, list):
        return f"{written / scale:g}"
    shown = [f"{x / scale:g}" for x in written]
    return "[" + ", ".join(shown if len(shown) <= 6 else [*shown[:3], "...", shown[-1]]) + "]"


def _base_model(head: dict, overrides, base_dir: Path) -> Model:
    """The preset or configuration named in ``[study]``, with the ``[model]`` section on top."""
    preset = head.get("preset")
    try:
        if "config" in head:
            if not isinstance(head["config"], str):
                raise ParameterError("config", f"must be a file name (got {show(head['config'])})")
            model = config.load_config(base_dir / head["config"], preset=preset)
        else:
            model = config.load_preset(config.DEFAULT_PRESET if preset is None else preset)
    except ConfigError as exc:
        if exc.field not in ("config", "preset"):
            raise
        raise ConfigError(f"study.{exc.field}", exc.message) from None
    if overrides is None:
        return model
    try:
        return config.merge(model, overrides)
    except ParameterError as exc:
        raise exc.under("model") from None


def _samples(table: dict) -> Samples:
    """The ``[samples]`` section: its count, seed and one distribution per (dotted) parameter."""
    check_keys(table, SAMPLE_KEYS, "samples")
    if "count" in table:  # a bad count is the fault named, even when the parameters are missing too
        sample_count(table["count"])
    for key in ("count", "parameters"):
        if key not in table:
            raise ParameterError(f"samples.{key}", "is required")
    drawn = table["parameters"]
    if not isinstance(drawn, dict):
        raise ParameterError("samples.parameters", f"must be a table of distributions (got {show(drawn)})")
    parameters = []
    for name, spec in flatten(drawn, "samples.parameters", lambda x: "distribution" in x).items():
        where = quoted_key("samples.parameters", name)
        if not isinstance(spec, dict) or "distribution" not in spec:
            raise ParameterError(where, "must be { distribution = ..., <its arguments> }, see docs/studies.md")
        arguments = tuple((k, x) for k, x in spec.items() if k != "distribution")
        parameters.append(Sampled(name, spec["distribution"], arguments))
    return Samples(table["count"], table.get("seed", 0), tuple(parameters))
