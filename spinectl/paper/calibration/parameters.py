"""The unstated parameters of the paper as a vector with anatomical bounds, and its map to a Model.

A parameter vector maps to a :class:`~spinectl.model.params.Model` through dotted
parameter paths (:func:`to_model`, :func:`from_model`); one free parameter may
set several paths, e.g. the common height of all upper attachments.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from ...errors import ParameterError
from ...model.config import set_parameters
from ...model.params import Model


@dataclass(frozen=True)
class FreeParameter:
    """One unstated parameter of the paper, fitted within anatomical bounds.

    Attributes
    ----------
    name : str
        Identifier, e.g. ``"mass"``.
    unit : str
        Unit of the value and the bounds (SI).
    lower, upper : float
        Bounds, in ``unit``.
    paths : tuple of str
        Dotted parameter paths (:func:`spinectl.model.config.set_parameters`) that all
        take this value, e.g. the heights of every upper attachment.
    doc : str
        What the parameter is.
    source : str
        Where the bounds come from; "estimate" where they are one.
    """

    name: str
    unit: str
    lower: float
    upper: float
    paths: tuple[str, ...]
    doc: str
    source: str

    def value(self, model: Model) -> float:
        """The value in ``model`` (that of the first path).

        Parameters
        ----------
        model : Model

        Returns
        -------
        float
            The value, in :attr:`unit`.
        """
        node = model
        for key in self.paths[0].split("."):
            node = node[int(key)] if isinstance(node, tuple) else getattr(node, key)
        return float(node)


def _muscle_paths(template: str, pairs: Sequence[int] = (0, 1, 2)) -> tuple[str, ...]:
    return tuple(template.format(i) for i in pairs)


FREE_PARAMETERS: tuple[FreeParameter, ...] = (
    FreeParameter(
        "mass",
        "kg",
        24.0,
        55.0,
        ("body.mass",),
        "Upper-body point mass m.",
        "Head, neck, arms, thorax and half the abdomen are 47 % of the body mass in Dempster's segment "
        "fractions (Winter 2009, Biomechanics and Motor Control of Human Movement, table 4.1: "
        "8.1 + 2 x 5.0 + 21.6 + 13.9/2); the default preset reads 55 %. Adult body masses of about "
        "50-100 kg (estimate) give about 24-55 kg.",
    ),
    FreeParameter(
        "straight_x",
        "m",
        0.03,
        0.17,
        ("muscles.0.upper.0", "muscles.0.lower.0"),
        "Horizontal distance x of the straight pair from the body's symmetry axis (both ends).",
        "Estimate: global muscles lie between the vertebral bodies (about 3 cm from the midline) and the "
        "trunk surface: half the waist depth (sagittal, 20-25 cm) or half the waist breadth (coronal, "
        "30-34 cm) in adult anthropometric tables (e.g. NASA-STD-3000, Anthropometric Source Book vol. II).",
    ),
    FreeParameter(
        "oblique_wide_x",
        "m",
        0.03,
        0.17,
        ("muscles.1.upper.0", "muscles.2.lower.0"),
        "x of the oblique pairs' wide ends: the upper end of oblique_outer, the lower end of oblique_inner.",
        "As for straight_x (estimate).",
    ),
    FreeParameter(
        "oblique_narrow_x",
        "m",
        0.03,
        0.17,
        ("muscles.1.lower.0", "muscles.2.upper.0"),
        "x of the oblique pairs' narrow ends: the lower end of oblique_outer, the upper end of oblique_inner.",
        "As for straight_x (estimate).",
    ),
    FreeParameter(
        "upper_y",
        "m",
        0.176,
        0.326,
        _muscle_paths("muscles.{}.upper.1"),
        "Common height y of the upper (thoracic) attachments.",
        "The thoracic cage lies above P1, the thoracolumbar joint at 176 mm (paper), and a muscle of the "
        "lumbar region attaches below the upper body's centre of mass at 326 mm (paper; the lower ribs "
        "and the costal margin lie between, estimate).",
    ),
    FreeParameter(
        "lower_y",
        "m",
        -0.10,
        0.035,
        _muscle_paths("muscles.{}.lower.1"),
        "Common height y of the lower (pelvic) attachments.",
        "The iliac crest lies at the level of L4L5 (Tuffier's intercristal line; the paper's L4L5 CoR at "
        "35 mm) and the pubic crest and the dorsal sacrum about 10 cm below P2 (estimate).",
    ),
    FreeParameter(
        "spread",
        "m",
        0.0,
        0.05,
        _muscle_paths("muscles.{}.spread"),
        "Common width of the attachment surfaces across which each muscle's fibres are spread.",
        "Estimate: from a single line of action (0) to 5 cm, about the thickness of the erector spinae "
        "or the rectus abdominis in the plane of the model.",
    ),
)
"""The unstated parameters of the paper and their bounds, in the order of the parameter vector.

Tied to the three pairs of the default preset (straight, oblique_outer,
oblique_inner), whose obliques are mirror images of each other in height.
"""


def parameter_set(names: Sequence[str] | None = None) -> tuple[FreeParameter, ...]:
    """The free parameters called ``names`` (all of :data:`FREE_PARAMETERS` if None).

    Parameters
    ----------
    names : sequence of str, optional
        Subset of the names of :data:`FREE_PARAMETERS`, in the order wanted.

    Returns
    -------
    tuple of FreeParameter
        In the order of ``names``.

    Raises
    ------
    ParameterError
        An unknown or repeated name, or an empty list (field ``parameters``).
    """
    if names is None:
        return FREE_PARAMETERS
    known = {p.name: p for p in FREE_PARAMETERS}
    unknown = [n for n in names if n not in known]
    if unknown or not names or len(set(names)) != len(names):
        raise ParameterError("parameters", f"must be distinct names among {', '.join(known)} (got {list(names)})")
    return tuple(known[n] for n in names)


MASS_FREE = (10.0, 55.0)
"""Bounds of the mass [kg] for the preset of what the paper's numbers imply (docs/reproduction.md):
wide enough to let the landmarks choose, below any adult upper body at the low end."""


def with_bounds(
    parameters: Sequence[FreeParameter], name: str, lower: float, upper: float
) -> tuple[FreeParameter, ...]:
    """``parameters`` with the bounds of the one called ``name`` replaced.

    Parameters
    ----------
    parameters : sequence of FreeParameter
    name : str
        The parameter whose bounds change, e.g. ``"mass"``.
    lower, upper : float
        The new bounds, in its unit.

    Returns
    -------
    tuple of FreeParameter
        The same parameters in the same order; the one changed says in its source that its
        bounds were set for this run.

    Raises
    ------
    ParameterError
        ``name`` not among ``parameters`` (field ``bounds``), or not ``lower < upper`` (both finite).
    """
    names = [p.name for p in parameters]
    if name not in names:
        raise ParameterError("bounds", f"must name one of {', '.join(names)} (got {name!r})")
    if not (np.isfinite(lower) and np.isfinite(upper) and lower < upper):
        raise ParameterError("bounds", f"{name} needs finite LOW < HIGH (got {lower:g}, {upper:g})")
    return tuple(
        replace(p, lower=float(lower), upper=float(upper), source=f"Set for this run: [{lower:g}, {upper:g}] {p.unit}.")
        if p.name == name
        else p
        for p in parameters
    )


def to_model(base: Model, vector, parameters: Sequence[FreeParameter] = FREE_PARAMETERS) -> Model:
    """``base`` with the free parameters set to ``vector``.

    Parameters
    ----------
    base : Model
        Supplies every parameter that is not free.
    vector : array_like, shape (n,)
        Values of ``parameters``, each in its unit.
    parameters : sequence of FreeParameter

    Returns
    -------
    Model
        A new, validated model with every path of every free parameter set.
    """
    values = {path: float(v) for p, v in zip(parameters, vector, strict=True) for path in p.paths}
    return set_parameters(base, values)


def from_model(model: Model, parameters: Sequence[FreeParameter] = FREE_PARAMETERS) -> np.ndarray:
    """The parameter vector of ``model`` (the first path of each free parameter).

    Parameters
    ----------
    model : Model
    parameters : sequence of FreeParameter

    Returns
    -------
    numpy.ndarray, shape (n,)
        One value per free parameter, each in its unit.
    """
    return np.array([p.value(model) for p in parameters])


def bounds(parameters: Sequence[FreeParameter] = FREE_PARAMETERS) -> list[tuple[float, float]]:
    """The (lower, upper) bounds of ``parameters``, in their units.

    Parameters
    ----------
    parameters : sequence of FreeParameter

    Returns
    -------
    list of tuple of float
        ``[(lower, upper), ...]``, as :func:`scipy.optimize.differential_evolution` takes them.
    """
    return [(p.lower, p.upper) for p in parameters]
