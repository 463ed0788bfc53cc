"""Parameters: presets, TOML round trip, validation, documentation."""

from __future__ import annotations

import dataclasses
import math

import pytest

from spinectl.errors import ConfigError, ParameterError
from spinectl.model import config
from spinectl.model.params import Model


def test_default_preset_equals_dataclass_defaults():
    """presets/default.toml must not drift from the documented dataclass defaults."""
    assert config.load_preset("default") == Model()


def test_dump_and_load_round_trip(tmp_path, model):
    path = tmp_path / "m.toml"
    path.write_text(config.dump_toml(model))
    assert config.load_config(path) == model


def test_partial_file_overrides_the_preset(tmp_path):
    path = tmp_path / "m.toml"
    path.write_text("[body]\nmass = 55.0\n[passive]\nstiffness = 15.0\n")
    m = config.load_config(path)
    assert m.body.mass == 55.0 and m.passive.stiffness == 15.0
    assert m.geometry == Model().geometry


def _error_for(tmp_path, text, exc=ParameterError):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(exc) as info:
        config.load_config(path)
    return info.value


def test_negative_mass_names_the_field(tmp_path):
    err = _error_for(tmp_path, "[body]\nmass = -3.0\n")
    assert err.field == "body.mass" and "> 0" in str(err)


def test_nan_is_rejected(tmp_path):
    err = _error_for(tmp_path, "[fibre]\nk1 = nan\n")
    assert err.field == "fibre.k1" and "finite" in str(err)


def test_unknown_key_suggests_the_right_one(tmp_path):
    err = _error_for(tmp_path, "[body]\nmas = 3.0\n", ConfigError)
    assert err.field == "body.mas" and "did you mean 'mass'" in str(err)


def test_unknown_section_is_rejected(tmp_path):
    err = _error_for(tmp_path, "[bodyy]\nmass = 3.0\n", ConfigError)
    assert "did you mean 'body'" in str(err)


def test_errors_inside_muscle_list_name_the_index(tmp_path):
    err = _error_for(tmp_path, '[[muscles]]\nname = "x"\nupper = [0.1, 0.0]\nlower = [0.1, 0.2]\n')
    assert err.field == "muscles.0.upper"


def test_missing_file_and_bad_toml(tmp_path):
    with pytest.raises(ConfigError, match="not found"):
        config.load_config(tmp_path / "nope.toml")
    err = _error_for(tmp_path, "[body\n", ConfigError)
    assert "not valid TOML" in str(err)


def test_unknown_preset():
    with pytest.raises(ConfigError, match="must be one of"):
        config.load_preset("nope")


def test_set_parameter(model):
    m = config.set_parameter(model, "muscles.1.spread", 0.05)
    assert m.muscles[1].spread == 0.05 and m.muscles[0] == model.muscles[0]
    with pytest.raises(ConfigError, match="did you mean 'mass'"):
        config.set_parameter(model, "body.masss", 1.0)
    with pytest.raises(ParameterError):
        config.set_parameter(model, "body.mass", math.nan)


def test_set_parameters_validates_once_at_the_end(model):
    """Moving a muscle wholly above its old upper attachment: one path at a time would pass through a
    muscle whose lower end lies above its upper end (invalid); all at once it is valid."""
    moved = {"muscles.0.lower.1": 0.30, "muscles.0.upper.1": 0.40}
    m = config.set_parameters(model, moved)
    assert m.muscles[0].lower == (0.12, 0.30) and m.muscles[0].upper == (0.12, 0.40)
    with pytest.raises(ParameterError, match="must lie above lower"):
        config.set_parameter(model, "muscles.0.lower.1", 0.30)
    assert config.set_parameters(model, {"body.mass": 30.0}) == config.set_parameter(model, "body.mass", 30.0)


def _parameter_fields():
    model = Model()
    for section in dataclasses.fields(Model):
        value = getattr(model, section.name)
        cls = type(value[0]) if isinstance(value, tuple) else type(value)
        for f in dataclasses.fields(cls):
            yield f"{section.name}.{f.name}", f


def test_every_parameter_has_a_unit_and_documentation():
    """Fails on an undocumented parameter (python-control's convention)."""
    undocumented = [name for name, f in _parameter_fields() if not f.metadata.get("doc") or "unit" not in f.metadata]
    assert undocumented == []


@pytest.mark.parametrize(
    ("text", "field", "needle"),
    [
        ("[reflex]\ndelay = -0.1\n", "reflex.delay", "in [0, 10]"),
        ("[reflex]\ndelay = 11.0\n", "reflex.delay", "in [0, 10]"),
        ("[reflex]\npade_order = 0\n", "reflex.pade_order", "in [1, 10]"),
        ("[reflex]\npade_order = 11\n", "reflex.pade_order", "in [1, 10]"),
        ("[reflex]\nsim_divergence = 2.0\n", "reflex.sim_divergence", "<= pi/2"),
        ("[reflex]\npade_order = 5.0\n", "reflex.pade_order", "must be an integer"),
        ("[reflex]\nactivation = -0.5\n", "reflex.activation", "in [0, 10]"),
        ("[reflex]\ngain_factor = 1.0\n", "reflex.gain_factor", "> 1"),
        ("[reflex]\ngains = 'auto'\n", "reflex.gains", "one of"),
        ("[reflex]\nsim_perturbation = 0.3\n", "reflex.sim_perturbation", "< sim_divergence"),
        ("[reflex]\nsim_time_step = 20.0\n", "reflex.sim_time_step", "< sim_duration"),
    ],
)
def test_reflex_section_is_validated(tmp_path, text, field, needle):
    err = _error_for(tmp_path, text)
    assert err.field == field and needle in str(err)


def test_a_file_with_a_byte_order_mark_reads_as_without(tmp_path):
    """A UTF-8 byte-order mark, as some Windows editors save it: before, "not valid TOML (Invalid statement
    (at line 1, column 1))" for a file that is valid TOML; the mark is not content. Study files too."""
    from spinectl.landscape.study import load_study

    path = tmp_path / "bom.toml"
    path.write_bytes(b"\xef\xbb\xbf[body]\nmass = 42.0\n")
    assert config.load_config(path).body.mass == 42.0
    study = tmp_path / "study.toml"
    grid = "E = { start = 0.0, stop = 0.08, num = 3 }\nLambda = { start = 0.0, stop = 0.08, num = 3 }\n"
    study.write_bytes(b"\xef\xbb\xbf[axes]\n" + grid.encode())
    assert load_study(study).grid_shape == (3, 3)


@pytest.mark.parametrize("preset", config.list_presets())
def test_show_says_what_each_value_is_where_it_is_not_the_defaults(preset):
    """``config show``: a field's doc describes the default preset's value (mass: "spinectl's default, 40 kg");
    above every value that differs from it, a comment gives this value to 6 significant digits, where it
    comes from (the preset file's own first line: calibrated) and the default's. The differing fields are
    found by comparing the two presets' parameters here; nothing else gets such a comment."""
    model = config.load_preset(preset)
    lines = config.show_toml(model).splitlines()
    ours, default = config._parameters(model), config._parameters(config.load_preset("default"))
    differing = {d for d in ours if d in default and ours[d][1] != default[d][1]}
    assert len([line for line in lines if line.startswith("# This value: ")]) == len(differing)
    assert (preset == "default") == (not differing)
    if "body.mass" in differing:
        row = lines.index(f"mass = {model.body.mass!r}")
        assert lines[row - 1] == (
            f"# This value: {model.body.mass:.6g} kg (preset {preset}: calibrated against the landmarks of "
            "Wagner et al. (2012); docs/reproduction.md); the default preset's: 40 kg."
        )


def test_show_names_a_value_set_on_the_command_line_and_the_presets_to_choose_from():
    model = config.apply_overrides(config.load_preset("wagner2012"), ["body.mass=35"])
    text = config.show_toml(model)
    assert "# This value: 35 kg (set on the command line); the default preset's: 40 kg.\nmass = 35.0" in text
    assert "Presets: wagner2012" in text and "one's own" in text


def test_dump_toml_without_origins_names_no_source(model):
    """What a study's digest hashes depends on the parameters alone: no value notes without ``origins``."""
    assert "This value" not in config.dump_toml(config.apply_overrides(model, ["body.mass=35"]))


@pytest.mark.parametrize(
    "folder",
    [
        "runs/a\n[body]\nmass = 1.0\n#",  # a line break ends a comment: the rest would be parameters
        "runs/a\r\nmuscles_mode = 'merge'",  # CR LF, and a key of the file's top level
    ],
)
def test_shown_toml_names_a_hostile_config_path_only_in_comments(tmp_path, folder):
    """``config show`` of a model from a file under a hostile path: the path is in the header's comment and in the
    comment of every value that the file changed ("from FILE"), and nowhere else: the text reads back (tomllib,
    then load_config) to exactly the model shown, whose mass is the file's 30 kg, not the path's 1 kg. Before, the
    line break in the header and in the notes made the path's next lines TOML."""
    from spinectl._validate import printable

    path = tmp_path / folder / "model.toml"
    path.parent.mkdir(parents=True)
    path.write_text('preset = "wagner2012"\n[body]\nmass = 30.0\n', encoding="utf-8")
    model = config.load_config(str(path))
    text = config.show_toml(model)
    data = __import__("tomllib").loads(text)
    assert data["body"]["mass"] == 30.0 and set(data) == {"muscles_mode", *config.to_dict(model)}
    shown = tmp_path / "shown.toml"
    shown.write_text(text, encoding="utf-8")
    assert config.load_config(str(shown)) == model
    assert sum(printable(str(path)) in line for line in text.splitlines()) >= 2  # the header and the note
