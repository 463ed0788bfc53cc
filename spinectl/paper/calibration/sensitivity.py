"""What the landmarks identify: the Jacobian of the log-landmarks in the free parameters.

docs/reproduction.md, "What the landmarks identify"; a singular value near zero
is a direction of the parameters that the landmarks cannot see.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ...model.params import Model
from .. import landmarks
from .landscapes import FIT_POINTS, coarse_landmarks
from .parameters import FREE_PARAMETERS, FreeParameter, bounds, from_model, to_model

STEP_LANDMARKS = ("ridge_slope", "ct_valley_slope", "optimum_lordosis", "ridge_slope_K15")
"""Landmarks read off grid arg-maxima: they move in steps of the grid, not continuously, so a
finite difference cannot see them (:func:`sensitivity`, the identifiability check)."""


def _log(value: float) -> float:
    return math.log(value) if value > 0 else math.nan  # NaN > 0 is False too


@dataclass(frozen=True)
class Sensitivity:
    """How the landmarks respond to the free parameters at one model: what the fit can identify.

    Attributes
    ----------
    landmarks : tuple of str
        The landmarks differentiated: continuous ones with a positive value, not exact zeros.
    jacobian : numpy.ndarray, shape (n_landmarks, n_parameters)
        d log(landmark) / d(parameter / width of its bounds) [1].
    singular_values : numpy.ndarray, shape (n_parameters,)
        Of the Jacobian, largest first [1]: a value near 0 is a direction the landmarks do not see.
    directions : numpy.ndarray, shape (n_parameters, n_parameters)
        Right singular vectors, one per row, in the order of ``singular_values``.
    """

    landmarks: tuple[str, ...]
    jacobian: np.ndarray
    singular_values: np.ndarray
    directions: np.ndarray


def sensitivity(
    model: Model, parameters: Sequence[FreeParameter] = FREE_PARAMETERS, points: int = FIT_POINTS, step: float = 0.01
) -> Sensitivity:
    """Central differences of the log-landmarks in the free parameters, scaled to their bounds.

    Parameters
    ----------
    model : Model
        Where to differentiate (e.g. the calibrated preset); its convention is used at K = 15.
    parameters : sequence of FreeParameter
    points : int
        Grid points per axis of the landscapes.
    step : float
        Half step, as a fraction of each bound's width (clipped to the bounds).

    Returns
    -------
    Sensitivity
        The landmarks used, the Jacobian [1], shape (n_landmarks, n_parameters), its
        singular values and right singular vectors.
    """
    parameters = tuple(parameters)
    centre = from_model(model, parameters)
    lows, highs = np.array(bounds(parameters)).T

    def logs(vector) -> dict[str, float]:
        found = landmarks.measure(coarse_landmarks(to_model(model, vector, parameters), points))
        return {m.landmark.name: m.value for m in found}

    base = logs(centre)
    exact = {m.name for m in landmarks.LANDMARKS if m.relation == "="}  # zero up to rounding: no log-ratio
    names = tuple(n for n, v in base.items() if n not in STEP_LANDMARKS and n not in exact and v > 0)
    columns = []
    for i in range(len(parameters)):
        up, down = centre.copy(), centre.copy()
        up[i] = min(centre[i] + step * (highs[i] - lows[i]), highs[i])
        down[i] = max(centre[i] - step * (highs[i] - lows[i]), lows[i])
        hi, lo = logs(up), logs(down)
        width = (up[i] - down[i]) / (highs[i] - lows[i])
        columns.append([(_log(hi[n]) - _log(lo[n])) / width for n in names])
    jacobian = np.array(columns).T
    _, singular, directions = np.linalg.svd(jacobian, full_matrices=False)
    return Sensitivity(names, jacobian, singular, directions)
