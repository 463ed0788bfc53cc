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
