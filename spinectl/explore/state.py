"""The explorer's state: the point (E, Lambda) and the parameters its sliders move.

A state is a frozen value; :func:`model_at` applies it to the model the explorer
started from (the preset or ``--config``), validated by
:func:`spinectl.model.config.set_parameters`, and :func:`state_toml` writes that
model as a TOML file that ``--config`` reads back (docs/explore.md).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from .._validate import in_range
from ..model.config import dump_toml, set_parameters
from ..model.params import Model
from ..paper import grid
from ..quoting import toml_comment
from ..units import CM_PER_M

MS_PER_S = 1000.0
"""Milliseconds per second: the delays are shown in ms."""
START_POINT = (0.03, 0.04)
"""(E, Lambda) [m] where the explorer starts: the README's example point."""


@dataclass(frozen=True)
class ExploreState:
    """Everything the explorer's sliders set.

    Attributes
    ----------
    eccentricity, lordosis : float
        E and Lambda [m] of the point shown.
    mass : float
        Point mass of the upper body [kg] (``body.mass``).
    stiffness : float
        Passive stiffness K [N m/rad] (``passive.stiffness``).
    delay : float
        Reflex delay tau [s] (``reflex.delay``).
    activation : float
        Fraction of the minimum stabilising PCSA [1] (``reflex.activation``).
    activation_lag : float
        Force-generation time constant T_a [s] (``reflex.activation_time_constant``).
    """

    eccentricity: float
    lordosis: float
    mass: float
    stiffness: float
    delay: float
    activation: float
    activation_lag: float


@dataclass(frozen=True)
class Slider:
    """One slider: the state's field it sets, its label and its range in the unit shown.

    Attributes
    ----------
    field : str
        Field of :class:`ExploreState`.
    label : str
        Label, with the unit shown in brackets.
    start, end, step : float
        Range and step in the unit shown.
    scale : float
        Unit shown per SI unit (100 for cm, 1000 for ms).
    parameter : str or None
        Dotted model parameter it sets (:func:`model_at`); None for E and Lambda, the point.
    """

    field: str
    label: str
    start: float
    end: float
    step: float
    scale: float = 1.0
    parameter: str | None = None


_LOW, _HIGH = (x * CM_PER_M for x in grid.PAPER_RANGE)
SLIDERS = (
    Slider("eccentricity", "E [cm]", _LOW, _HIGH, 0.1, CM_PER_M),
    Slider("lordosis", "Λ [cm]", _LOW, _HIGH, 0.1, CM_PER_M),
    Slider("mass", "mass [kg]", 10.0, 80.0, 0.5, 1.0, "body.mass"),
    Slider("stiffness", "K [N m/rad]", 0.0, 30.0, 0.5, 1.0, "passive.stiffness"),
    Slider("delay", "reflex delay τ [ms]", 0.0, 250.0, 5.0, MS_PER_S, "reflex.delay"),
    Slider("activation", "activation [× minimum PCSA]", 0.0, 1.5, 0.05, 1.0, "reflex.activation"),
    Slider("activation_lag", "activation lag T_a [ms]", 0.0, 150.0, 5.0, MS_PER_S, "reflex.activation_time_constant"),
)
"""The sliders, in the order shown; the paper's grid bounds E and Lambda (0 to 8 cm)."""

LANDSCAPE_PARAMETERS = ("mass", "stiffness")
"""Fields whose change moves the landscapes (minimum PCSA and ||CT|| do not depend on the reflex)."""
REFLEX_ONLY = ("delay", "activation_lag")
"""Fields that move the delay margins only: the PCSA, and so the drawing, eigenvalues and counter torques, stay."""


def pictures_key(state: ExploreState) -> tuple[float, ...]:
    """The fields that the drawing, the eigenvalues and the counter torques depend on (all but :data:`REFLEX_ONLY`).

    Parameters
    ----------
    state : ExploreState

    Returns
    -------
    tuple of float
        Equal for two states whose pictures of the point are the same (for one model).
    """
    return tuple(getattr(state, f.name) for f in dataclasses.fields(state) if f.name not in REFLEX_ONLY)


def initial_state(model: Model) -> ExploreState:
    """The state the explorer opens with: :data:`START_POINT` and the model's own parameters.

    Parameters
    ----------
    model : Model
        The preset or configuration given.

    Returns
    -------
    ExploreState
        E, Lambda [m] from :data:`START_POINT`; mass [kg], K [N m/rad], delay [s], activation [1]
        and its lag [s] from ``model``.
    """
    return ExploreState(
        eccentricity=START_POINT[0],
        lordosis=START_POINT[1],
        mass=model.body.mass,
        stiffness=model.passive.stiffness,
        delay=model.reflex.delay,
        activation=model.reflex.activation,
        activation_lag=model.reflex.activation_time_constant,
    )


def model_at(base: Model, state: ExploreState) -> Model:
    """``base`` with the parameters of ``state`` (everything but the point), validated together.

    Parameters
    ----------
    base : Model
        The preset or configuration the explorer started from.
    state : ExploreState

    Returns
    -------
    Model
        A new model; ``base`` is unchanged. Its source lists as overridden only the sliders moved off
        ``base``'s own values (every output's header names them, :func:`spinectl.model.source.header`): before,
        it listed all five at the opening state, as if the user had changed them.

    Raises
    ------
    ParameterError
        A value outside its parameter's allowed range.
    """
    own = initial_state(base)  # the base's values: set again, they would be listed as overridden
    moved = [s for s in SLIDERS if s.parameter and getattr(state, s.field) != getattr(own, s.field)]
    return set_parameters(base, {s.parameter: getattr(state, s.field) for s in moved})


def state_toml(base: Model, state: ExploreState) -> str:
    """The state as a configuration file: the model of :func:`model_at`, and the point as a comment.

    Parameters
    ----------
    base : Model
    state : ExploreState

    Returns
    -------
    str
        TOML text that ``spinectl ... --config`` reads back to ``model_at(base, state)``; its first
        line gives E and Lambda [m], which are no model parameters but the point shown.
    """
    point = toml_comment(f"spinectl explore: E = {state.eccentricity!r} m, Lambda = {state.lordosis!r} m")
    return point + "\n" + dump_toml(model_at(base, state))


def from_shown(slider: Slider, shown: float) -> float:
    """A slider's value in SI units, on its grid of steps (a browser's slider may be off by an ulp).

    Parameters
    ----------
    slider : Slider
    shown : float
        The value in the unit shown.

    Returns
    -------
    float
        The nearest step in the unit shown, rounded to 10 decimals (5.1, not 5.1000000000000005),
        over ``scale``: in SI units.
    """
    return round(round(shown / slider.step) * slider.step, 10) / slider.scale


def from_client(slider: Slider, shown, start: float | None = None, end: float | None = None) -> float:
    """A value a browser sent for ``slider`` (in the unit shown), checked, on the grid of steps and in SI units.

    A page sends what its user or a forged message gives: the explorer takes it only as a
    finite number inside the slider's range, and answers anything else in one line.

    Parameters
    ----------
    slider : Slider
    shown : object
        The value sent.
    start, end : float, optional
        The range of the slider shown, in the unit shown (default ``slider.start`` and ``slider.end``;
        a model whose own value lies outside widens it).

    Returns
    -------
    float
        :func:`from_shown` of the value [SI units].

    Raises
    ------
    ParameterError
        Not a real number (a string, a bool), NaN or infinite, or outside [start, end]; the field is
        the slider's label, e.g. ``mass [kg]: must be in [10, 80] (got 1e+06)``.
    """
    low = slider.start if start is None else start
    high = slider.end if end is None else end
    return from_shown(slider, in_range(slider.label, shown, low, high))


def decimals(slider: Slider) -> int:
    """Decimals a value of ``slider`` means: those of its step (0.5 kg: 1; 0.05: 2; 5 ms: 0).

    Parameters
    ----------
    slider : Slider

    Returns
    -------
    int
    """
    return len(f"{slider.step:g}".partition(".")[2])


def shown_text(slider: Slider, value: float) -> str:
    """A state's value as its slider shows it: in the unit shown, to the decimals of the step.

    Parameters
    ----------
    slider : Slider
    value : float
        In SI units.

    Returns
    -------
    str
        E.g. ``'24.1'`` for the mass 24.056578609556272 kg of a calibrated preset (steps of 0.5 kg).
    """
    return f"{value * slider.scale:.{decimals(slider)}f}"


def slider_for(field: str) -> Slider:
    """The slider of a state's field.

    Parameters
    ----------
    field : str
        A field of :class:`ExploreState`.

    Returns
    -------
    Slider
    """
    return next(s for s in SLIDERS if s.field == field)


def replace(state: ExploreState, **changes) -> ExploreState:
    """``state`` with some fields changed (:func:`dataclasses.replace`), every value a float.

    Parameters
    ----------
    state : ExploreState
    **changes : float
        New values by field name, in SI units.

    Returns
    -------
    ExploreState
    """
    return dataclasses.replace(state, **{name: float(value) for name, value in changes.items()})
