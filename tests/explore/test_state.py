"""The explorer's state: the parameters it sets, its TOML export read back, the sliders' grid."""

from __future__ import annotations

import dataclasses

import pytest

from spinectl.errors import ParameterError
from spinectl.explore import state as st
from spinectl.model.config import load_config, load_preset


@pytest.fixture
def state():
    return st.ExploreState(0.02, 0.05, mass=31.5, stiffness=15.0, delay=0.12, activation=0.75, activation_lag=0.07)


def test_initial_state_is_the_models_own(model):
    """Mass, K, delay, activation and lag are those of the model (params.py defaults); the point is the README's."""
    start = st.initial_state(model)
    assert (start.eccentricity, start.lordosis) == (0.03, 0.04)
    assert (start.mass, start.stiffness, start.delay, start.activation, start.activation_lag) == (
        40.0,
        0.0,
        0.1,
        0.5,
        0.05,
    )


def test_model_at_sets_each_parameter_by_its_dotted_name(model, state):
    """Each slider's field lands in the parameter the docs name (docs/explore.md), the rest untouched."""
    new = st.model_at(model, state)
    assert new.body.mass == 31.5 and new.passive.stiffness == 15.0
    assert (new.reflex.delay, new.reflex.activation, new.reflex.activation_time_constant) == (0.12, 0.75, 0.07)
    assert new.muscles == model.muscles and new.geometry == model.geometry
    with pytest.raises(ParameterError, match="mass"):
        st.model_at(model, dataclasses.replace(state, mass=-1.0))


def test_state_toml_reads_back_to_the_same_model(tmp_path, state):
    """The TOML export, read by --config, gives model_at(base, state); its first line gives the point."""
    base = load_preset("wagner2012")
    text = st.state_toml(base, state)
    path = tmp_path / "state.toml"
    path.write_text(text)
    assert load_config(path) == st.model_at(base, state)
    assert text.splitlines()[0] == "# spinectl explore: E = 0.02 m, Lambda = 0.05 m"


def test_from_shown_snaps_to_the_step_and_converts_to_si():
    """3.5999999999999996 cm (a browser's float) is 3.6 cm = 0.036 m; 105 ms is 0.105 s."""
    assert st.from_shown(st.slider_for("eccentricity"), 3.5999999999999996) == 36 * 0.1 / 100
    assert st.from_shown(st.slider_for("delay"), 105.0) == pytest.approx(0.105, abs=1e-15)
    assert [s.field for s in st.SLIDERS] == [f.name for f in dataclasses.fields(st.ExploreState)]


@pytest.mark.parametrize(
    ("sent", "message"),
    [
        ("3.6", "E [cm]: must be a number (got '3.6')"),
        (True, "E [cm]: must be a number (got True)"),
        (None, "E [cm]: must be a number (got None)"),
        (float("nan"), "E [cm]: must be finite (got nan)"),
        (8.05, "E [cm]: must be in [0, 8] (got 8.05)"),
    ],
)
def test_from_client_refuses_what_no_slider_sends(sent, message):
    """A browser's slider sends a number in its range; anything else is a ParameterError named by the label."""
    with pytest.raises(ParameterError) as raised:
        st.from_client(st.slider_for("eccentricity"), sent)
    assert str(raised.value) == message


def test_from_client_takes_the_range_shown():
    """A model whose own mass lies outside 10-80 kg widens its slider; that range is the one checked."""
    mass = st.slider_for("mass")
    assert st.from_client(mass, 90.0, 10.0, 90.0) == 90.0 and st.from_client(mass, 24.2) == 24.0
    with pytest.raises(ParameterError, match=r"must be in \[10, 80\]"):
        st.from_client(mass, 90.0)


def test_shown_text_has_the_decimals_of_the_step():
    """Steps 0.1 cm, 0.5 kg, 0.05 and 5 ms mean 1, 1, 2 and 0 decimals: 24.056578609556272 kg is '24.1'."""
    assert [st.decimals(st.slider_for(f)) for f in ("eccentricity", "mass", "activation", "delay")] == [1, 1, 2, 0]
    assert st.shown_text(st.slider_for("mass"), 24.056578609556272) == "24.1"
    assert (
        st.shown_text(st.slider_for("delay"), 0.105) == "105"
        and st.shown_text(st.slider_for("lordosis"), 0.04) == "4.0"
    )
