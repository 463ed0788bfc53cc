"""Overrides (``--set``), muscle pairs merged by name, the model's source, and config diff (docs/model.md)."""

from __future__ import annotations

import copy
import dataclasses
import hashlib
import math
import pickle
import warnings

import numpy as np
import pytest

from spinectl.errors import ConfigError, ParameterError
from spinectl.model import config, laws, source
from spinectl.model._toml import to_dict
from spinectl.model.params import Model
from spinectl.model.stability import segment_stability
from spinectl.paper.grid import with_stiffness

BASE = config.load_preset(config.DEFAULT_PRESET)

ALTERNATIVES = {
    "natural": "clamped",
    "physical": "paper",
    "paper": "physical",
    "destabilising": "printed",
    "corrected": "printed",
    "paired": "independent",
    "rule": "explicit",
}
"""A second allowed value of each text parameter (their allowed values: docs/parameters.md)."""


@pytest.fixture(autouse=True)
def _second_law():
    """The paper's law registered again as ``wagner2012_b``: the second allowed value of ``fibre.law`` (only the
    paper's is built in), which :func:`_changed` gives it."""
    law = laws.register_law(dataclasses.replace(laws.LAWS["wagner2012"], name="wagner2012_b"))
    yield
    del laws.LAWS[law.name]


def _leaves(data, prefix=""):
    """(dotted name, value) of every parameter: lists of numbers and of names are one value, pairs by index."""
    for key, value in data.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            yield from _leaves(value, f"{name}.")
        elif isinstance(value, list) and value and isinstance(value[0], dict):
            for i, item in enumerate(value):
                yield from _leaves(item, f"{name}.{i}.")
        else:
            yield name, value


def _changed(name: str, value):
    """A valid value that differs from ``value``: 1 % more (a small step from 0 or inf), another word, renamed names."""
    if isinstance(value, str):
        return ALTERNATIVES.get(value, value + "_b")
    if isinstance(value, bool):
        return not value
    if isinstance(value, int):
        return value + 1
    if isinstance(value, list):
        return [_changed(name, x) for x in value]
    if math.isinf(value):
        return 1.0
    return value * 1.01 if value else 0.01


def _toml(value) -> str:
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, list):
        return "[" + ", ".join(_toml(x) for x in value) + "]"
    return repr(value)


PARAMETERS = list(_leaves(to_dict(BASE)))


def test_every_section_is_covered():
    """The list below is every field of every section: a new field is tested without editing this file."""
    sections = {name.split(".")[0] for name, _ in PARAMETERS}
    assert sections == set(to_dict(BASE))
    assert len(PARAMETERS) > 60


@pytest.mark.parametrize(("name", "value"), PARAMETERS, ids=[n for n, _ in PARAMETERS])
def test_set_changes_every_parameter(name, value):
    """``--set name=VALUE`` with a valid new value changes exactly that parameter and marks it overridden."""
    new = _changed(name, value)
    model = config.apply_overrides(BASE, [f"{name}={_toml(new)}"])
    changed = dict(_leaves(to_dict(model)))
    assert changed[name] == pytest.approx(new) if not isinstance(new, str) else changed[name] == new
    assert {k for k, v in changed.items() if v != dict(PARAMETERS)[k]} == {name}
    assert source.source_of(model).overridden == (name,)


def _file_for(name: str, value_text: str) -> str:
    """The TOML file that sets one dotted parameter; a pair's preceding pairs listed by name, so indices agree."""
    parts = name.split(".")
    if parts[0] != "muscles":
        return f"[{parts[0]}]\n{'.'.join(parts[1:])} = {value_text}\n"
    index = int(parts[1])
    tables = [f'[[muscles]]\nname = "{pair.name}"\n' for pair in BASE.muscles[: index + 1]]
    return "".join(tables) + f"{'.'.join(parts[2:])} = {value_text}\n"


@pytest.mark.parametrize(("name", "value"), PARAMETERS, ids=[n for n, _ in PARAMETERS])
def test_an_invalid_set_is_the_tomls_error(name, value, tmp_path):
    """A value of the wrong kind gives the same error, field and message, as the same line in a TOML file."""
    if name.endswith(".name"):
        pytest.skip("a pair's name is how a file's [[muscles]] finds its pair: the file would add a pair")
    bad = "[1, 2, 3]" if isinstance(value, str) else '"nonsense"'
    path = tmp_path / "bad.toml"
    path.write_text(f'preset = "{config.DEFAULT_PRESET}"\n' + _file_for(name, bad))
    with pytest.raises(ParameterError) as from_file:
        config.load_config(path)
    with pytest.raises(ParameterError) as from_set:
        config.apply_overrides(BASE, [f"{name}={bad}"])
    assert (from_set.value.field, str(from_set.value)) == (from_file.value.field, str(from_file.value))


def test_an_unknown_field_says_did_you_mean_as_in_a_file(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text("[body]\nmas = 3.0\n")
    with pytest.raises(ConfigError) as from_file:
        config.load_config(path)
    with pytest.raises(ConfigError) as from_set:
        config.apply_overrides(BASE, ["body.mas=3.0"])
    assert str(from_set.value) == str(from_file.value)
    assert "did you mean 'mass'" in str(from_set.value)


def test_set_reads_words_and_pairs_by_name():
    """A bare word is a string; a pair is found by its name as well as its index."""
    model = config.apply_overrides(BASE, ["passive.convention=physical", "muscles.straight.spread=0.02"])
    assert model.passive.convention == "physical" and model.muscles[0].spread == 0.02


@pytest.mark.parametrize("text", ["passive.stiffness", "=3", ""])
def test_set_without_field_and_value_is_refused(text):
    with pytest.raises(ParameterError, match="must be SECTION.FIELD=VALUE"):
        config.apply_overrides(BASE, [text])


def test_a_file_pair_merges_by_name_and_a_new_name_adds_one(tmp_path):
    path = tmp_path / "m.toml"
    path.write_text(
        '[[muscles]]\nname = "straight"\nspread = 0.02\n'
        '[[muscles]]\nname = "extra"\nupper = [0.05, 0.2]\nlower = [0.05, 0.0]\n'
    )
    model = config.load_config(path)
    assert model.pair_names == (*BASE.pair_names, "extra")
    assert model.muscles[3].upper == (0.05, 0.2) and model.muscles[3].lower == (0.05, 0.0)
    assert model.muscles[0].spread == 0.02 and model.muscles[0].upper == BASE.muscles[0].upper
    assert model.muscles[1:3] == BASE.muscles[1:3]


@pytest.mark.parametrize(
    ("tables", "message"),
    [
        # the newcomer's typo: before, a fourth pair with straight's default attachments, silently
        (
            'name = "straigth"\nspread = 0.02\n',
            "muscles.0.upper: is required for the new pair 'straigth': a pair that is not the preset's gives its "
            "attachments upper and lower [m]; did you mean 'straight'?",
        ),
        (
            'name = "psoas"\nupper = [0.03, 0.2]\n',
            "muscles.0.lower: is required for the new pair 'psoas': a pair that is not the preset's gives its "
            "attachments upper and lower [m] (the pairs are 'straight', 'oblique_outer', 'oblique_inner')",
        ),
    ],
)
def test_a_new_pair_must_give_its_attachments(tmp_path, tables, message):
    path = tmp_path / "m.toml"
    path.write_text("[[muscles]]\n" + tables)
    with pytest.raises(ConfigError) as err:
        config.load_config(path)
    assert str(err.value) == message


def test_a_nameless_pair_in_merge_mode_is_an_error(tmp_path):
    path = tmp_path / "m.toml"
    path.write_text("[[muscles]]\nspread = 0.02\n")
    with pytest.raises(ConfigError, match="muscles.0.name: is required"):
        config.load_config(path)


def test_replace_mode_replaces_the_set_silently(tmp_path):
    path = tmp_path / "m.toml"
    path.write_text('muscles_mode = "replace"\n[[muscles]]\nname = "only"\n')
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the author chose it: no warning
        model = config.load_config(path)
    assert model.pair_names == ("only",)


def test_replacing_with_every_name_does_not_warn(tmp_path):
    """config show's output names every pair: loading it back in replace mode drops none, so no warning."""
    path = tmp_path / "m.toml"
    path.write_text('muscles_mode = "replace"\n' + config.dump_toml(BASE))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert config.load_config(path) == BASE


def test_unknown_muscles_mode_is_refused(tmp_path):
    path = tmp_path / "m.toml"
    path.write_text('muscles_mode = "append"\n')
    with pytest.raises(ConfigError, match="muscles_mode: must be one of 'merge', 'replace'"):
        config.load_config(path)


def test_the_source_names_preset_file_hash_and_overrides(tmp_path):
    """The SHA-256 is that of the file's bytes (hashlib, independently); overrides accumulate in order."""
    path = tmp_path / "m.toml"
    path.write_bytes(b'preset = "default"\r\n[body]\r\nmass = 50.0\r\n')
    model = config.set_parameter(config.load_config(path), "reflex.delay", 0.05)
    origin = source.source_of(model)
    assert origin.preset == "default" and origin.config == str(path)
    assert origin.config_sha256 == hashlib.sha256(path.read_bytes()).hexdigest()
    assert origin.overridden == ("reflex.delay",)
    line = source.header(model)
    assert line.startswith("preset default, K = 0 N m/rad, convention physical; config ")
    assert line.endswith(f"(sha256 {origin.config_sha256[:12]}); overridden: reflex.delay")
    assert source.provenance(model)["config_sha256"] == origin.config_sha256


def _first_line_and_keys(model: Model) -> tuple[str, str | None, list]:
    """What ``spinectl stability`` prints first, and its JSON's ``preset`` and ``overridden``, for ``model``."""
    result = segment_stability(model, 0.0, 0.0, np.full(len(model.muscle_names), 1e-4))
    document = result.to_dict(model)
    return result.table(model).splitlines()[0], document["preset"], document["overridden"]


def test_replace_keeps_the_preset_and_lists_the_fields_it_changed():
    """``load_preset('wagner2012').replace(body=...)``: the outputs name the preset and the field, as
    ``--set body.mass=60`` would (before: ``preset none (a Model built in Python)``, no field)."""
    model = config.load_preset("wagner2012")
    heavier = model.replace(body=dataclasses.replace(model.body, mass=60.0))
    line, preset, overridden = _first_line_and_keys(heavier)
    assert line == "preset wagner2012, K = 0 N m/rad, convention physical; overridden: body.mass"
    assert (preset, overridden) == ("wagner2012", ["body.mass"])
    assert source.source_of(heavier) == source.source_of(config.set_parameter(model, "body.mass", 60.0))


def test_the_source_survives_every_transformation_in_turn(tmp_path):
    """A file's model through replace (two fields of one section, a pair by its name), set_parameters,
    with_stiffness, a copy and a pickle (a Dask worker's model): the file and its SHA-256 stay, and each
    changed field is listed once, in order; a section replaced by an equal one lists nothing."""
    path = tmp_path / "m.toml"
    path.write_text('preset = "default"\n[body]\nmass = 50.0\n', encoding="utf-8")
    model = config.load_config(path)
    pair = model.muscles[1]
    model = model.replace(reflex=dataclasses.replace(model.reflex, delay=0.05, kp=2.0), body=model.body)
    model = model.replace(muscles=model.muscles[:1] + (dataclasses.replace(pair, spread=0.02),) + model.muscles[2:])
    model = with_stiffness(config.set_parameters(model, {"reflex.delay": 0.06, "body.mass": 55.0}), 15.0)
    model = pickle.loads(pickle.dumps(copy.deepcopy(model)))
    expected = ["reflex.delay", "reflex.kp", f"muscles.{pair.name}.spread", "body.mass", "passive.stiffness"]
    line, preset, overridden = _first_line_and_keys(model)
    assert (preset, overridden) == ("default", expected)
    digest = hashlib.sha256(path.read_bytes()).hexdigest()[:12]
    assert line.startswith(f"preset default, K = 15 N m/rad, convention physical; config {path} (sha256 {digest})")
    fewer = model.replace(muscles=model.muscles[:1])  # the pairs themselves differ
    assert source.source_of(fewer).overridden[-1] == "muscles"


def test_a_model_built_in_python_stays_one_when_replaced():
    """No preset to keep: ``Model().replace(...)`` still says so, and lists no override of a preset."""
    model = Model().replace(body=dataclasses.replace(Model().body, mass=60.0))
    assert _first_line_and_keys(model)[1:] == (None, [])


def test_the_source_is_no_parameter():
    """Two equal parameter sets compare equal however they were made."""
    assert config.load_preset("default") == Model()
    assert config.set_parameter(BASE, "body.mass", BASE.body.mass) == BASE


def test_the_default_preset_is_the_calibrated_one():
    """Every entry point starts from wagner2012 (docs/model.md, "The default model")."""
    assert config.DEFAULT_PRESET == "wagner2012"
    assert source.source_of(config.load_preset()).preset == "wagner2012"
    assert source.source_of(config.load_config()).preset == "wagner2012"


def test_diff_lists_every_differing_parameter_with_its_unit():
    """wagner2012 against default: the calibrated mass, attachments and spreads (the calibration's free
    parameters, docs/reproduction.md); both use the physical K convention, which wagner2012_mass_free does not."""
    differences = {d.name: d for d in config.diff_models(BASE, config.load_preset("default"))}
    assert differences["body.mass"].unit == "kg" and differences["body.mass"].second == 40.0
    assert set(differences) == {"body.mass"} | {
        f"muscles.{pair}.{field}" for pair in BASE.pair_names for field in ("upper", "lower", "spread")
    }
    assert config.diff_models(BASE, BASE) == []
    free = {d.name: d for d in config.diff_models(config.load_preset("wagner2012_mass_free"), BASE)}
    assert free["passive.convention"].line() == "passive.convention: paper -> physical"  # the presets' files


def test_diff_matches_pairs_by_name():
    extra = config.merge(BASE, {"muscles": [{"name": "extra", "upper": [0.12, 0.24], "lower": [0.12, 0.0]}]})
    lines = [d.line() for d in config.diff_models(BASE, extra)]
    assert "muscles.extra.spread [m]: (absent) -> 0.03" in lines and len(lines) == 5
