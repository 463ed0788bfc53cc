"""Clinical geometry: the lordosis as an angle in degrees, the eccentricity as a distance of the gravity line.

Clinicians measure the lumbar lordosis as the angle between the end plates of its end
vertebrae (e.g. T12-S1 or L1-S1, in degrees), not as the offset Lambda of a spline point.
With the end plates perpendicular to the spine line, that angle is the angle between the
line's tangents at its ends, P1 (y = L) and P2 (y = 0). The spine line is
x(y) = -E + Lambda phi(s), s = 1 - abs(y - L/2) / (L/2) (:func:`spinectl.model.geometry.lordosis_shape`;
docs/model.md, "The spine line"), so its slope at P2 is dx/dy = Lambda phi'(0) (2 / L) and at P1 the
same with the opposite sign: the tangents turn by

    theta = 2 atan(2 phi'(0) Lambda / L),

phi'(0) being 3/2 for natural end conditions (theta = 2 atan(3 Lambda / L)), 2 for not-a-knot (the
parabola) and 0 for clamped ends, whose tangents are vertical whatever Lambda (no angle to convert).
Degrees at the edges only; the library works in radians and metres (docs/atlas.md).

The eccentricity E is the horizontal distance of the gravity line (the vertical through the
upper body's point mass, x = 0) dorsal to the chord P1-P2 of the lumbar spine, the line through
its end joints; the gravity line's distance from CoR k is E - Lambda phi_k
(:func:`gravity_line_distance`).
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from .geometry import lordosis_shape
from .params import Model

END_SLOPES = {"natural": 1.5, "clamped": 0.0, "not-a-knot": 2.0}
"""phi'(0), the slope of :data:`spinectl.model.geometry.SPLINE_SHAPES` at an end of the spine, per
end condition [1]: d/ds of 1.5 s - 0.5 s^3, 3 s^2 - 2 s^3 and 2 s - s^2 at s = 0."""


def _end_gain(model: Model) -> float:
    """2 phi'(0) / L [1/m]: the spine line's end slope per unit lordosis."""
    return 2.0 * END_SLOPES[model.geometry.spline_bc] / model.geometry.spine_length


def lordosis_angle(lordosis, model: Model) -> np.ndarray:
    """The lordosis angle [deg]: the angle between the spine line's tangents at P1 and P2.

    theta = 2 atan(2 phi'(0) Lambda / L) (module docstring); positive for a lordosis
    (Lambda > 0, P3 ventral), negative for a kyphosis.

    Parameters
    ----------
    lordosis : array_like
        Lambda, ventral displacement of P3 [m]; any shape.
    model : Model
        Supplies ``geometry.spine_length`` L [m] and ``geometry.spline_bc``.

    Returns
    -------
    numpy.ndarray
        theta [deg], the shape of ``lordosis``; 0 everywhere for clamped end conditions.

    References
    ----------
    Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal lordosis
    optimizes the requirements for a stable erect posture. Theor Biol Med Model 9:13.
    doi:10.1186/1742-4682-9-13 (the spine line through P1, P3 and P2).
    """
    return np.degrees(2.0 * np.arctan(_end_gain(model) * np.asarray(lordosis, float)))


def lordosis_from_angle(angle, model: Model) -> np.ndarray:
    """Lambda [m] whose spine line has the lordosis angle ``angle`` [deg]: the inverse of :func:`lordosis_angle`.

    Lambda = L tan(theta / 2) / (2 phi'(0)).

    Parameters
    ----------
    angle : array_like
        theta [deg], strictly between -180 and 180; any shape.
    model : Model
        Supplies ``geometry.spine_length`` L [m] and ``geometry.spline_bc``.

    Returns
    -------
    numpy.ndarray
        Lambda [m], the shape of ``angle``.

    Raises
    ------
    ParameterError
        An angle not finite or not within (-180, 180) deg (field ``lordosis_angle_deg``), or clamped
        end conditions, whose end tangents are vertical for every Lambda (field ``geometry.spline_bc``).
    """
    theta = np.asarray(angle, float)
    if not np.all(np.isfinite(theta)) or np.any(np.abs(theta) >= 180.0):
        raise ParameterError("lordosis_angle_deg", "must be finite and strictly between -180 and 180 deg")
    gain = _end_gain(model)
    if gain == 0.0:
        raise ParameterError(
            "geometry.spline_bc", "'clamped' ends have vertical tangents for every lordosis: no angle to convert"
        )
    return np.tan(np.radians(theta) / 2.0) / gain


def gravity_line_distance(eccentricity, lordosis, model: Model) -> np.ndarray:
    """Horizontal distance of the gravity line ventral of each CoR: E - Lambda phi_k [m].

    The gravity line is the vertical x = 0 through the point mass; CoR k lies at
    x_k = -E + Lambda phi_k (:func:`spinectl.model.geometry.cor_positions`), so the line passes
    E - Lambda phi_k ventral of it (negative: dorsal). At P1 and P2 (phi = 0) this is E itself,
    the distance from the chord of the lumbar spine.

    Parameters
    ----------
    eccentricity : array_like
        E [m]; any shape.
    lordosis : array_like
        Lambda [m]; broadcast against E.
    model : Model
        Supplies the CoR heights and the spline.

    Returns
    -------
    numpy.ndarray, shape (..., n_cor)
        Distance of the gravity line ventral of each CoR [m].
    """
    e, lam = np.broadcast_arrays(np.asarray(eccentricity, float), np.asarray(lordosis, float))
    return e[..., None] - lam[..., None] * lordosis_shape(model.geometry)


def with_lordosis_angle(payload: dict, model: Model) -> dict:
    """``payload`` with ``lordosis_angle_deg`` [deg] just after its ``Lambda_m``: a JSON document's clinical angle.

    Parameters
    ----------
    payload : dict
        A command's JSON document; unchanged if it has no ``Lambda_m``.
    model : Model
        Converts Lambda to the angle.

    Returns
    -------
    dict
        A new dict, keys in the same order.
    """
    out = {}
    for key, value in payload.items():
        out[key] = value
        if key == "Lambda_m" and value is not None:
            out["lordosis_angle_deg"] = float(lordosis_angle(value, model))
    return out
