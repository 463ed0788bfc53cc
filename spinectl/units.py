"""Unit conversions at the edges (CLI, reports, plots, JSON).

The numeric core is SI; PCSA is shown in cm^2, the paper's unit.
"""

from __future__ import annotations

import numpy as np

M2_PER_CM2 = 1e-4
"""Square metres per square centimetre."""

CM_PER_M = 100.0
"""Centimetres per metre: lengths on the figures' axes."""


def position_text(eccentricity: float, lordosis: float) -> str:
    """A point of the (E, Lambda) plane as the console prints it, in cm as every command does.

    Parameters
    ----------
    eccentricity, lordosis : float
        E and Lambda [m].

    Returns
    -------
    str
        ``"E = 3 cm, Lambda = 4 cm"`` (four significant digits at most; before, ``export`` printed m).
    """
    return f"E = {eccentricity * CM_PER_M:.4g} cm, Lambda = {lordosis * CM_PER_M:.4g} cm"


def cm2_to_m2(value):
    """PCSA [cm^2] -> [m^2].

    Parameters
    ----------
    value : array_like
        PCSA [cm^2].

    Returns
    -------
    numpy.ndarray
        PCSA [m^2], the shape of ``value``.
    """
    return np.asarray(value, float) * M2_PER_CM2


def m2_to_cm2(value):
    """PCSA [m^2] -> [cm^2].

    Parameters
    ----------
    value : array_like
        PCSA [m^2].

    Returns
    -------
    numpy.ndarray
        PCSA [cm^2], the shape of ``value``.
    """
    return np.asarray(value, float) / M2_PER_CM2


CM2_LEAST_PLAUSIBLE = 0.1
"""Smallest non-zero PCSA of one muscle [cm^2] taken without a warning at the command line: 10 mm^2,
under 1 % of the paper's least stabilising totals (tens of cm^2; 35.8 cm^2 at E = 3, Lambda = 4 cm,
docs/reproduction.md). A value below it is far more likely m^2 typed where the CLI takes cm^2
(0.001 m^2 = 10 cm^2), which the model accepts silently as a muscle too weak to matter."""


LEAST_CM_SLIP = 1e-3
"""Least length [m] (0.1 cm) that a value typed in cm is taken to mean: below it no cm hint is given."""


def centimetre_slip(values, low: float, high: float, typed: str, corrected: str) -> str:
    """The hint for lengths in cm typed where metres are meant, or ``""`` if that is not the likely slip.

    Parameters
    ----------
    values : array_like
        The lengths as given [m], some outside ``[low, high]``.
    low, high : float
        The allowed range [m].
    typed, corrected : str
        What the user typed (e.g. ``"3"``, ``"0:8:81"``) and the same in metres (``"0.03"``, ``"0:0.08:81"``).

    Returns
    -------
    str
        ``"; lengths are in metres: if you meant 3 cm, give 0.03"`` when every value divided by 100
        lies in the range, some value lies ten times beyond it and the largest read as cm is at least
        :data:`LEAST_CM_SLIP` [m], else ``""``.
    """
    values = np.asarray(values, float)
    scaled = values / CM_PER_M
    # an order of magnitude beyond the range (--E 3, not --E 0.5, which may be a plain slip)
    far = np.max(np.abs(values)) >= 10.0 * max(abs(low), abs(high))
    # a length typed in cm is rarely below 0.1 cm: --E 0.03 against a +-1 mm range (the coronal plane)
    # is a plain value out of range, not 0.03 cm
    plausible = np.max(np.abs(scaled)) >= LEAST_CM_SLIP
    if far and plausible and np.all((scaled >= low) & (scaled <= high)):
        return f"; lengths are in metres: if you meant {typed} cm, give {corrected}"
    return ""


LEAST_PLAUSIBLE_LORDOSIS_DEG = 5.0
"""Smallest non-zero lordosis angle [deg] taken without a warning at the command line. The standing lumbar
lordosis of asymptomatic adults is tens of degrees (160 volunteers: Roussouly et al. 2005, Spine 30:346-353,
doi:10.1097/01.brs.0000152379.54463.65); a value below 5 deg is far more likely radians typed where the
option takes degrees (0.7 rad = 40.1 deg), which the model accepts silently as a nearly straight spine."""


def radian_slip(angles_deg) -> str:
    """The warning for a lordosis angle in radians typed where degrees are meant, or ``""``.

    Parameters
    ----------
    angles_deg : array_like
        The angles as given [deg].

    Returns
    -------
    str
        E.g. ``"0.7 deg is a nearly straight spine (standing lordosis is tens of degrees); angles are in
        degrees here: if you meant 0.7 rad, give 40.107"``, for the largest non-zero value if every non-zero value
        lies below :data:`LEAST_PLAUSIBLE_LORDOSIS_DEG` and within pi; ``""`` otherwise (0 stays silent).
    """
    values = np.abs(np.asarray(angles_deg, float)).ravel()
    values = values[values > 0]
    if values.size == 0 or values.max() >= min(LEAST_PLAUSIBLE_LORDOSIS_DEG, np.pi):
        return ""
    value = float(values.max())
    return (
        f"{value:g} deg is a nearly straight spine (standing lordosis is tens of degrees); angles are in degrees "
        f"here: if you meant {value:g} rad, give {np.degrees(value):.5g}"
    )


def square_metre_slip(pcsa_cm2) -> str:
    """The warning for a PCSA in m^2 typed where cm^2 are meant, or ``""`` (see :data:`CM2_LEAST_PLAUSIBLE`).

    Parameters
    ----------
    pcsa_cm2 : array_like
        PCSA as given [cm^2].

    Returns
    -------
    str
        E.g. ``"0.001 cm^2 is less than any muscle's PCSA (below 0.1 cm^2); PCSA is in cm^2 here: if you
        meant 0.001 m^2, give 10"``, for the smallest such value; ``""`` if every value is 0 or plausible.
    """
    values = np.asarray(pcsa_cm2, float)
    tiny = values[(values > 0) & (values < CM2_LEAST_PLAUSIBLE)]
    if tiny.size == 0:
        return ""
    value = float(tiny.min())
    return (
        f"{value:g} cm^2 is less than any muscle's PCSA (below {CM2_LEAST_PLAUSIBLE:g} cm^2); PCSA is in cm^2 "
        f"here: if you meant {value:g} m^2, give {value / M2_PER_CM2:g}"
    )
