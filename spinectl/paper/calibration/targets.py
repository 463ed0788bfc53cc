"""The paper's landmarks as fitting targets, and the loss (docs/reproduction.md, "The loss").

A weighted sum over the landmarks: squared log-ratio residuals log(value /
paper) for the "about" landmarks, one-sided (hinge) squared log-ratios for "<"
and ">", each hinge demanding a margin of :data:`STRICT_MARGIN`, and
:data:`MISSING_PENALTY` for a landmark that cannot be measured (e.g. a ridge
that leaves the grid).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .. import landmarks
from ..landmarks import Measurement

STRICT_MARGIN = 0.05
"""Margin of the hinge for '<' and '>' landmarks, as a log-ratio (5 %): a value at the
paper's bound does not satisfy a strict inequality, and one just inside is fragile."""

MISSING_PENALTY = 4.0
"""Penalty of a landmark that cannot be measured (NaN, or a ratio <= 0): as much as a
value off by a factor e^2 = 7.4."""

C_READINGS = 3
"""Readings of the paper's position C (:mod:`~spinectl.paper.landmarks`): corner, text's optimum, ridge line."""

WEIGHTS = {
    "ct_A": 0.0,
    "ridge_rise": 0.0,
    **{f"ct_{r}_over_C{s}": 1.0 / C_READINGS for r in "DB" for s in ("", "_text", "_ridge")},
    "halving_K15_other": 0.0,
}
"""Weights of the landmarks in the loss; 1 for any landmark not listed.

``ct_A`` is zero by symmetry under paired activation, whatever the parameters;
``ridge_rise`` is zero wherever one CoR binds along the ridge (docs/reproduction.md), which
has no log-ratio, so it would add a constant, not a direction;
the three readings of position C share one weight; ``halving_K15_other`` belongs
to the convention not being fitted (it is reported, not fitted).
"""


@dataclass(frozen=True)
class Target:
    """One landmark as a fitting target.

    Attributes
    ----------
    name : str
        Landmark name (:data:`spinectl.paper.landmarks.LANDMARKS`).
    value : float
        Target value, in the landmark's unit (> 0).
    relation : str
        '~', '<' or '>'.
    weight : float
        Weight in the loss.
    """

    name: str
    value: float
    relation: str
    weight: float = 1.0


def paper_targets(weights: dict[str, float] | None = None) -> tuple[Target, ...]:
    """The paper's landmarks as targets, weighted by ``weights`` (default :data:`WEIGHTS`).

    A landmark whose value is zero (‖CT‖ at A) has no log-ratio and is left out.

    Parameters
    ----------
    weights : dict, optional
        Landmark name to weight; unlisted landmarks weigh 1.

    Returns
    -------
    tuple of Target
        The landmarks with a positive value and a positive weight, in the order of
        :data:`spinectl.paper.landmarks.LANDMARKS`.
    """
    weights = WEIGHTS if weights is None else weights
    return tuple(
        Target(m.name, m.paper, m.relation, weights.get(m.name, 1.0))
        for m in landmarks.LANDMARKS
        if m.paper > 0 and weights.get(m.name, 1.0) > 0
    )


def synthetic_targets(measurements: Sequence[Measurement], names: Sequence[str] | None = None) -> tuple[Target, ...]:
    """Targets '~' equal to measured values, for the identifiability check.

    Parameters
    ----------
    measurements : sequence of Measurement
        From :func:`spinectl.paper.landmarks.measure` on a model with known parameters.
    names : sequence of str, optional
        Landmarks to use; default every one with a finite positive value. Exact zeros
        (relation '=', e.g. ‖CT‖ at A, whose measured value is rounding) are left out.

    Returns
    -------
    tuple of Target
        One '~' target of weight 1 per chosen landmark, its value the measured one.
    """
    chosen = [m for m in measurements if (names is None or m.landmark.name in names) and m.landmark.relation != "="]
    return tuple(Target(m.landmark.name, m.value, "~") for m in chosen if np.isfinite(m.value) and m.value > 0)


def penalty(target: Target, value: float) -> float:
    """The loss term of one landmark [1]: weight times a squared log-ratio (docs/reproduction.md).

    '~': log(value/target)^2; '<': max(0, log(value/target) + margin)^2; '>':
    max(0, margin - log(value/target))^2, with the margin :data:`STRICT_MARGIN`;
    :data:`MISSING_PENALTY` if the value is not finite and positive.

    Parameters
    ----------
    target : Target
    value : float
        spinectl's measurement, in the landmark's unit.

    Returns
    -------
    float
        The term [1], >= 0.
    """
    if not (np.isfinite(value) and value > 0):
        return target.weight * MISSING_PENALTY
    residual = math.log(value / target.value)
    if target.relation == "<":
        residual = max(0.0, residual + STRICT_MARGIN)
    elif target.relation == ">":
        residual = min(0.0, residual - STRICT_MARGIN)
    return target.weight * residual**2


def loss(measurements: Sequence[Measurement], targets: Sequence[Target]) -> float:
    """The calibration loss: the sum of :func:`penalty` over ``targets``.

    Parameters
    ----------
    measurements : sequence of Measurement
        From :func:`spinectl.paper.landmarks.measure`.
    targets : sequence of Target

    Returns
    -------
    float
        The loss [1], >= 0.
    """
    values = {m.landmark.name: m.value for m in measurements}
    return float(sum(penalty(t, values[t.name]) for t in targets))


@dataclass(frozen=True)
class Residual:
    """One landmark of a calibrated model.

    Attributes
    ----------
    name : str
        Landmark name.
    relation : str
        '~', '=', '<' or '>'.
    paper : float
        The paper's value.
    value : float
        spinectl's value.
    unit : str
    log_ratio : float
        log(value / paper); NaN where undefined.
    penalty : float
        Its term in the loss (0 for a landmark that is not fitted).
    agrees : bool
        Within the tolerance of :mod:`spinectl.paper.landmarks`.
    """

    name: str
    relation: str
    paper: float
    value: float
    unit: str
    log_ratio: float
    penalty: float
    agrees: bool


def residuals(measurements: Sequence[Measurement], targets: Sequence[Target]) -> tuple[Residual, ...]:
    """Every landmark with its log-ratio residual and its term in the loss.

    Parameters
    ----------
    measurements : sequence of Measurement
        From :func:`spinectl.paper.landmarks.measure`.
    targets : sequence of Target
        The fitted landmarks; the others get penalty 0.

    Returns
    -------
    tuple of Residual
        One per measurement, in their order.
    """
    by_name = {t.name: t for t in targets}
    out = []
    for m in measurements:
        mark, value = m.landmark, m.value
        ratio = math.log(value / mark.paper) if mark.paper > 0 and np.isfinite(value) and value > 0 else math.nan
        term = penalty(by_name[mark.name], value) if mark.name in by_name else 0.0
        out.append(Residual(mark.name, mark.relation, mark.paper, value, mark.unit, ratio, term, m.agrees))
    return tuple(out)
