"""Unit conversions at the edges (CLI, reports, plots, JSON).

The numeric core is SI; PCSA is shown in cm^2, the paper's unit.
"""

from __future__ import annotations

import numpy as np

M2_PER_CM2 = 1e-4
"""Square metres per square centimetre."""

CM_PER_M = 100.0
"""Centimetres per metre: lengths on the figures' axes."""


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
