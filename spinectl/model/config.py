"""Reading and writing model parameters as TOML, and the built-in presets.

A configuration file may give any subset of the parameters; the rest come from
the preset it names with ``preset = "NAME"`` (default :data:`DEFAULT_PRESET`). Unknown
keys are rejected with a "did you mean" hint. ``[[muscles]]`` tables are merged with the
preset's pairs by name (:data:`MUSCLES_MODES`). :func:`dump_toml` writes the
fully resolved set with each field's unit and documentation as comments. Every model
loaded or changed here carries its :class:`~spinectl.model.source.ModelSource`.
"""

from __future__ import annotations

import dataclasses
import difflib
import hashlib
import textwrap
import tomllib
from importlib import resources
from pathlib import Path

from .._validate import show
from ..errors import ConfigError, ParameterError
from ..quoting import toml_comment
from ._toml import from_dict, locate, parse, read_text, table_lines, to_dict
from .params import Model, MusclePair
from .source import ModelSource, header, source_of, with_source

PRESET_PACKAGE = "spinectl.presets"

DEFAULT_PRESET = "wagner2012"
"""The preset of every command and API entry point when none is named: the calibrated one that
``spinectl reproduce`` runs, so that every answer belongs to the model whose landmarks
docs/reproduction.md checks (docs/model.md, "The default model"). ``"default"``, the
anatomical, uncalibrated estimate, stays selectable by name."""

PRESET_GUIDANCE = (
    "wagner2012 (used when none is named): 24 kg, its unstated parameters calibrated to the paper's landmarks, "
    "to compare with the paper; default: the anatomical, uncalibrated 40 kg estimate, the start for one's own subject "
    "(set its mass and attachments)"
)
"""Which preset to use, in one sentence: the ``--preset`` help, ``spinectl config show`` and the README."""

MUSCLES_MODES = ("merge", "replace")
"""How a file's ``[[muscles]]`` tables combine with the preset's pairs (its key ``muscles_mode``):
``"merge"`` (the default) updates the pair of the same ``name`` with the keys given and appends a
pair whose name is new; ``"replace"`` puts the file's pairs in place of the preset's. Replacing is only
ever the file author's written choice, so it is silent: the outputs name the file, and ``config show`` its pairs."""


def list_presets() -> list[str]:
    """Names of the built-in presets (TOML files shipped in :mod:`spinectl.presets`).

    Returns
    -------
    list of str
        Preset names without ``.toml``, sorted, e.g. ``["default", "wagner2012"]``.
    """
    files = resources.files(PRESET_PACKAGE).iterdir()
    return sorted(f.name.removesuffix(".toml") for f in files if f.name.endswith(".toml"))


def load_preset(name: str = DEFAULT_PRESET) -> Model:
    """The built-in preset ``name`` as a :class:`~spinectl.model.params.Model`.

    Parameters
    ----------
    name : str
        One of :func:`list_presets`; default :data:`DEFAULT_PRESET`.

    Returns
    -------
    Model
        The preset's parameters, validated, its source the preset.

    Raises
    ------
    ConfigError
        ``name`` is not a built-in preset.

    Examples
    --------
    >>> from spinectl import load_preset
    >>> model = load_preset("wagner2012")
    >>> model.geometry.cor_names
    ('L1L2', 'L2L3', 'L3L4', 'L4L5', 'L5S1')
    >>> model.reflex.delay  # tau [s]
    0.1
    """
    presets = list_presets()
    if not isinstance(name, str) or name not in presets:
        raise ConfigError("preset", f"must be one of {', '.join(map(repr, presets))} (got {show(name)})")
    text = resources.files(PRESET_PACKAGE).joinpath(f"{name}.toml").read_text(encoding="utf-8")
    model = from_dict(Model, parse(text, f"preset {name!r}"))
    return with_source(model, ModelSource(preset=name))


def load_config(path: str | Path | None = None, preset: str | None = None) -> Model:
    """Load a model: a preset, optionally overridden by the TOML file ``path``.

    Parameters
    ----------
    path : str or Path, optional
        A TOML file with any subset of the parameters. It may name its base
        preset with ``preset = "NAME"`` and how its ``[[muscles]]`` combine with the
        preset's with ``muscles_mode`` (:data:`MUSCLES_MODES`).
    preset : str, optional
        Base preset; overrides the file's own ``preset`` key. Default :data:`DEFAULT_PRESET`.

    Returns
    -------
    Model
        The base preset with the file's values in place of its own, validated; its source
        names the preset, the file and the file's SHA-256.

    Raises
    ------
    ConfigError
        The file cannot be read or parsed, or names an unknown key, preset or muscles mode.
    ParameterError
        A value is out of range.
    """
    if path is None:
        return load_preset(DEFAULT_PRESET if preset is None else preset)
    path = Path(path)
    data = parse(read_text(path), str(path))
    base_name = data.pop("preset", None)
    mode = data.pop("muscles_mode", "merge")
    if preset is None:  # an empty name is an error of load_preset, not the default
        preset = DEFAULT_PRESET if base_name is None else base_name
    model = merge(load_preset(preset), data, muscles_mode=mode)
    digest = hashlib.sha256(path.read_bytes()).hexdigest()
    return with_source(model, ModelSource(preset=preset, config=str(path), config_sha256=digest))


def merge(base: Model, data: dict, muscles_mode: str = "merge") -> Model:
    """``base`` with the (partial, nested) parameters in ``data`` replacing its own.

    Sections merge key by key; ``muscles`` merge by name or replace the set (``muscles_mode``).

    Parameters
    ----------
    base : Model
        The parameters to start from.
    data : dict
        Nested parameters as read from TOML, e.g. ``{"body": {"mass": 50.0}}`` (SI units).
    muscles_mode : {'merge', 'replace'}
        See :data:`MUSCLES_MODES`.

    Returns
    -------
    Model
        A new, validated model with ``base``'s source; ``base`` is unchanged.

    Raises
    ------
    ConfigError
        ``muscles_mode`` unknown, or a merged ``[[muscles]]`` table without a ``name``.
    """
    if muscles_mode not in MUSCLES_MODES:
        allowed = ", ".join(map(repr, MUSCLES_MODES))
        raise ConfigError("muscles_mode", f"must be one of {allowed} (got {show(muscles_mode)})")
    merged = _deep_merge(to_dict(base), {k: v for k, v in data.items() if k != "muscles"})
    if "muscles" in data:
        merged["muscles"] = _muscles(merged["muscles"], data["muscles"], muscles_mode)
    return with_source(from_dict(Model, merged), source_of(base))


def _muscles(base: list, given, mode: str) -> list:
    """The muscle pairs of ``base`` combined with a file's ``[[muscles]]`` (:data:`MUSCLES_MODES`)."""
    if not isinstance(given, list) or not given:
        return given  # from_dict names the error: must be an array of tables, with at least one pair
    if mode == "replace":  # the file says so in words: no warning for a choice its author wrote
        return given
    out = [dict(pair) for pair in base]
    names = [pair["name"] for pair in out]
    for i, pair in enumerate(given):
        if not isinstance(pair, dict):
            return given  # from_dict names the error
        if "name" not in pair:
            raise ConfigError(
                f"muscles.{i}.name",
                "is required: pairs merge with the preset's by name (or set muscles_mode = 'replace')",
            )
        if pair["name"] in [p.get("name") for p in given[:i]]:
            repeated = show(pair["name"])
            raise ParameterError(f"muscles.{i}.name", f"must be unique among the pairs (repeated: {repeated})")
        if pair["name"] in names:
            out[names.index(pair["name"])].update(pair)
        else:
            _check_new_pair(pair, i, names)
            out.append(dict(pair))
            names.append(pair["name"])
        from_dict(MusclePair, out[names.index(pair["name"])], f"muscles.{i}")  # errors name the file's table
    return out


NEW_PAIR_REQUIRED = ("upper", "lower")
"""Keys that a ``[[muscles]]`` table must give when its name is new: the attachments that no default
can supply (MusclePair's defaults are one pair's; a misspelt name would silently copy them)."""


def _check_new_pair(pair: dict, index: int, names: list) -> None:
    """Raise unless a pair that is not the preset's gives its attachments; suggest the name meant."""
    missing = [key for key in NEW_PAIR_REQUIRED if key not in pair]
    if not missing:
        return
    name = pair["name"]
    from_dict(MusclePair, {"name": name}, f"muscles.{index}")  # a name that is no name: that error first
    close = difflib.get_close_matches(name, names, n=1)
    hint = f"; did you mean {close[0]!r}?" if close else f" (the pairs are {', '.join(map(repr, names))})"
    raise ConfigError(
        f"muscles.{index}.{missing[0]}",
        f"is required for the new pair {show(name)}: a pair that is not the preset's gives its attachments "
        f"{' and '.join(NEW_PAIR_REQUIRED)} [m]{hint}",
    )


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

    Returns
    -------
    Model
        A new, validated model; ``model`` is unchanged.
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

    Returns
    -------
    Model
        A new, validated model whose source lists these fields as overridden; ``model`` is unchanged.

    Raises
    ------
    ConfigError
        A dotted path that names no parameter (with a "did you mean"), as in a TOML file.
    ParameterError
        A value out of range.
    """
    data = to_dict(model)
    for dotted, value in values.items():
        holder, key = locate(data, _pair_index(data, dotted))
        holder[key] = value
    return with_source(from_dict(Model, data), source_of(model).with_overridden(values))


def _pair_index(data: dict, dotted: str) -> str:
    """``muscles.straight.spread`` as ``muscles.0.spread``: a pair by its name as well as its index."""
    parts = dotted.split(".")
    names = [pair.get("name") for pair in data.get("muscles", [])]
    if len(parts) > 1 and parts[0] == "muscles" and parts[1] in names:
        parts[1] = str(names.index(parts[1]))
    return ".".join(parts)


def apply_overrides(model: Model, assignments) -> Model:
    """``model`` with ``SECTION.FIELD=VALUE`` assignments applied and validated together, as ``--set`` does.

    VALUE is read as a TOML value (``15``, ``1e-3``, ``inf``, ``[0.04, 0.26]``, ``"paper"``); text
    that is no TOML value is a string, so ``passive.convention=paper`` needs no quotes. A pair is
    named by index or by name (``muscles.straight.spread=0.02``).

    Parameters
    ----------
    model : Model
        The parameters to start from.
    assignments : iterable of str
        E.g. ``["passive.stiffness=15", "reflex.delay=0.05"]``.

    Returns
    -------
    Model
        A new model whose source lists the fields as overridden (:func:`set_parameters`).

    Raises
    ------
    ParameterError
        An assignment without ``=`` (field ``set``), or a value out of range.
    ConfigError
        A field that does not exist, with the same message as in a TOML file.
    """
    values = {}
    for text in assignments:
        dotted, sep, value = text.partition("=")
        if not sep or not dotted.strip():
            raise ParameterError("set", f"must be SECTION.FIELD=VALUE, e.g. passive.stiffness=15 (got {show(text)})")
        values[dotted.strip()] = _toml_value(value.strip())
    return set_parameters(model, values) if values else model


def _toml_value(text: str):
    """``text`` read as one TOML value, or as a string if it is none."""
    try:
        data = tomllib.loads(f"value = {text}")
    except tomllib.TOMLDecodeError:
        return text
    return data["value"] if list(data) == ["value"] else text


def dump_toml(model: Model, origins: dict | None = None) -> str:
    """The fully resolved parameter set as TOML, with units and docs as comments.

    Parameters
    ----------
    model : Model
        The parameters to write.
    origins : dict, optional
        Where each value comes from, by dotted field (``"body.mass"``, ``"muscles.straight.upper"``), e.g.
        ``"calibrated (spinectl calibrate)"``. A field given here whose value differs from the ``default``
        preset's gets a comment saying so (:func:`value_notes`): a field's doc describes the default, and
        its comment must not stand above another value unremarked.

    Returns
    -------
    str
        TOML text that :func:`~spinectl.model._toml.from_dict` reads back to ``model`` (and
        :func:`load_config` when its pairs include the preset's); every field is preceded by a
        comment with its unit in brackets and its ``doc`` metadata. Without ``origins`` it names no
        source, so that what it identifies (a study's digest) depends on the parameters alone.
    """
    notes = value_notes(model, origins) if origins else {}
    lines = ["# spinectl model parameters (SI units unless a comment says otherwise)", ""]
    for f in dataclasses.fields(model):
        value = getattr(model, f.name)
        if isinstance(value, tuple):
            for item in value:
                lines += [f"[[{f.name}]]", *table_lines(item, _section(notes, f"{f.name}.{item.name}")), ""]
        else:
            lines += [f"[{f.name}]", *table_lines(value, _section(notes, f.name)), ""]
    return "\n".join(lines)


def _section(notes: dict, prefix: str) -> dict:
    """The notes of one table (``body``, ``muscles.straight``) by field name."""
    start = f"{prefix}."
    return {dotted.removeprefix(start): note for dotted, note in notes.items() if dotted.startswith(start)}


def value_notes(model: Model, origins: dict) -> dict:
    """A comment for each field of ``origins`` whose value differs from the ``default`` preset's.

    The docs of the fields describe the anatomical default (``mass``: "spinectl's default, 40 kg, ...");
    beside another value the comment says what this one is, where it comes from, and the default's
    value, each to 6 significant digits (what a fitted or typed value means; the value line keeps
    every digit, so that the file reads back to the same model).

    Parameters
    ----------
    model : Model
    origins : dict
        Where the value comes from by dotted field, e.g. ``{"body.mass": "calibrated (preset wagner2012)"}``.

    Returns
    -------
    dict
        ``"This value: 24.0566 kg (calibrated ...); the default preset's: 40 kg."`` by dotted field.
    """
    ours, default = _parameters(model), _parameters(load_preset("default"))
    notes = {}
    for dotted, origin in origins.items():
        if dotted in ours and dotted in default and ours[dotted][1] != default[dotted][1]:
            unit = ours[dotted][0]
            unit = f" {unit}" if unit and unit != "1" else ""
            here, there = _shown(ours[dotted][1]), _shown(default[dotted][1])
            notes[dotted] = f"This value: {here}{unit} ({origin}); the default preset's: {there}{unit}."
    return notes


def model_origins(model: Model) -> dict:
    """Where each parameter of a loaded model comes from: ``--set``, its file, or its preset.

    Parameters
    ----------
    model : Model
        A model of :func:`load_config` or :func:`apply_overrides` (its source names them).

    Returns
    -------
    dict
        By dotted field: ``"set on the command line"``, ``"from FILE"`` or ``"preset NAME: <what the preset
        file's first line says it is>"`` (e.g. calibrated against the paper's landmarks).
    """
    source = source_of(model)
    ours = _parameters(model)
    preset = _parameters(load_preset(source.preset)) if source.preset in list_presets() else {}
    about = preset_description(source.preset) if preset else ""
    origins = {}
    for dotted, (_, value) in ours.items():
        if dotted in source.overridden:
            origins[dotted] = "set on the command line"
        elif dotted not in preset or preset[dotted][1] != value:
            origins[dotted] = f"from {source.config}" if source.config else "set in Python"
        elif preset:
            origins[dotted] = f"preset {source.preset}" + (f": {about}" if about else "")
    return origins


def preset_description(name: str) -> str:
    """What the preset file says it is, from its first comment line (``"calibrated against ..."``), or ``""``.

    Parameters
    ----------
    name : str
        One of :func:`list_presets`.

    Returns
    -------
    str
        The line without ``# spinectl preset`` and its final full stop.
    """
    text = resources.files(PRESET_PACKAGE).joinpath(f"{name}.toml").read_text(encoding="utf-8")
    first = text.splitlines()[0] if text else ""
    if not first.startswith("# spinectl preset "):
        return ""
    return first.removeprefix("# spinectl preset ").rstrip(".")


@dataclasses.dataclass(frozen=True)
class Difference:
    """One parameter in which two models differ (:func:`diff_models`).

    Attributes
    ----------
    name : str
        Dotted parameter; a muscle pair by its name (``muscles.straight.spread``).
    unit : str
        Its unit as in ``docs/parameters.md`` (``"1"`` a ratio, ``""`` text).
    first, second : object
        Its value in each model; None where the model has no such pair.
    """

    name: str
    unit: str
    first: object
    second: object

    def line(self) -> str:
        """The difference as one line: ``body.mass [kg]: 24.06 -> 40``.

        Returns
        -------
        str
        """
        unit = f" [{self.unit}]" if self.unit and self.unit != "1" else ""
        return f"{self.name}{unit}: {_shown(self.first)} -> {_shown(self.second)}"


def _shown(value) -> str:
    if value is None:
        return "(absent)"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_shown(x) for x in value) + "]"
    return f"{value:.6g}" if isinstance(value, float) else str(value)


def diff_models(first: Model, second: Model) -> list[Difference]:
    """Every parameter whose value differs between two models, with its unit.

    Muscle pairs are matched by name, so a pair missing from one model is listed field by field
    with None on that side.

    Parameters
    ----------
    first, second : Model

    Returns
    -------
    list of Difference
        In the order of the model's sections and fields; empty if the models are equal.
    """
    a, b = _parameters(first), _parameters(second)
    out = []
    for name in list(a) + [n for n in b if n not in a]:
        unit = (a.get(name) or b[name])[0]
        x, y = (a[name][1] if name in a else None), (b[name][1] if name in b else None)
        if x != y:
            out.append(Difference(name, unit, x, y))
    return out


def _parameters(model: Model) -> dict:
    """(unit, value) of every parameter by dotted name; muscle pairs by their names."""
    out = {}
    for section in dataclasses.fields(model):
        value = getattr(model, section.name)
        pairs = section.name == "muscles"
        for prefix, obj in [(f"muscles.{p.name}", p) for p in value] if pairs else [(section.name, value)]:
            for f in dataclasses.fields(obj):
                out[f"{prefix}.{f.name}"] = (f.metadata.get("unit", ""), getattr(obj, f.name))
    return out


def load_model_spec(spec: str) -> Model:
    """A preset by name, or a model file by path: the argument of ``spinectl config diff``.

    Parameters
    ----------
    spec : str
        A name of :func:`list_presets`, else a path to a TOML model file.

    Returns
    -------
    Model

    Raises
    ------
    ConfigError
        Neither a preset nor a readable model file (the message names both).
    """
    if spec in list_presets():
        return load_preset(spec)
    if not Path(spec).exists():
        presets = ", ".join(map(repr, list_presets()))
        raise ConfigError("config", f"{show(spec)} is neither a preset ({presets}) nor an existing file")
    return load_config(spec)


def show_toml(model: Model) -> str:
    """``spinectl config show``: :func:`dump_toml` under comments naming the model and how files combine.

    Parameters
    ----------
    model : Model
        The parameters to show.

    Returns
    -------
    str
        A complete model file: the :func:`~spinectl.model.source.header` line and the rules of
        ``[[muscles]]`` as comments, ``muscles_mode = "replace"`` (its pairs are the whole set, so
        :func:`load_config` reads it back to ``model``), then :func:`dump_toml`.
    """
    return "\n".join(
        [
            toml_comment(f"model: {header(model)}"),  # the header names the --config path
            *textwrap.wrap(f"Presets: {PRESET_GUIDANCE}.", 110, initial_indent="# ", subsequent_indent="# "),
            '# A --config file gives any subset of these parameters, over its preset (preset = "NAME").',
            "# Its [[muscles]] tables merge with the preset's pairs by name: a known name changes the keys",
            '# given, a new name adds a pair. muscles_mode = "replace" (as here, where every pair is listed)',
            "# puts the file's pairs in place of the preset's; spinectl warns if that drops a preset's pair.",
            'muscles_mode = "replace"',
            "",
            dump_toml(model, model_origins(model)),
        ]
    )
