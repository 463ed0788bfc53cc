"""What every landscape figure shares: its size, levels and colour bar, titles wrapped, K named with its unit.

The constants fix the look of Figures 3, 4, S1 and the ratio maps alike; the title helpers break a
title between words but never inside a value with its unit, and name K with the passive-stiffness
convention it was computed under (docs/model.md, "Passive stiffness: two conventions").
"""

from __future__ import annotations

import re
import textwrap

import numpy as np
import xarray as xr
from matplotlib.ticker import MaxNLocator

from ...model.source import stiffness_unit
from ...units import CM_PER_M

FIGURE_SIZE = (6.4, 5.2)
"""Inches."""

LEVELS = 16
"""Number of filled contour levels."""
EQUAL_ASPECT = 2.0
"""E and Lambda share one scale unless one axis spans more than this many times the other."""

NICE_STEPS = (1, 2, 5, 10)
"""Steps of round contour levels and colour-bar ticks (matplotlib's MaxNLocator ``steps``)."""
LINE_LEVELS = 6
"""At most about this many labelled contour lines (round values) on a landscape."""
TITLE_CHARS = 56, 46
"""Characters a title line holds at fontsize 9: on the landscape axes (about 4 in wide) and on those of
Figure 3 with the model drawn at its corners (about 3.4 in)."""

_CONVENTION = {"paper": "eq. 2 as printed", "physical": "physical, -K in dM/dα"}
"""How a title names the passive-stiffness convention (docs/model.md, "Passive stiffness: two conventions")."""


CM_DIGITS = 3
"""Significant digits of a position in cm on a figure: a grid corner read from an angle axis is 6.99 cm,
not 6.99162 cm (a figure's label is read, not computed with)."""


def cm_text(value: float) -> str:
    """A length [m] as a figure labels it in cm, to :data:`CM_DIGITS` significant digits (``0.0699162`` -> ``'6.99'``).

    Parameters
    ----------
    value : float
        The length [m].

    Returns
    -------
    str
        The number in cm, without the unit.
    """
    return f"{value * CM_PER_M:.{CM_DIGITS}g}"


COLOUR_BAR = (1.03, 0.0, 0.045, 1.0)
"""Left, bottom, width, height of a landscape's colour bar in its axes' coordinates: beside them, as tall."""

_UNBROKEN = re.compile(r"\([^()\n]{1,40}\)|(?:[\w.]+ = )?[\d.]+ (?:N m(?:/rad)?|1/s²|kg|cm|m|s)\b|N m/rad|N m")
"""Spans a title line is not broken inside: a short parenthesis, a setting with its value and unit, a unit."""


def _wrap(title: str, width: int) -> str:
    """``title`` broken into lines of at most ``width`` characters, its own line breaks kept, never inside a
    value with its unit or a short parenthesis (:data:`_UNBROKEN`; "K = 0 N / m/rad" read oddly)."""

    def glued(match):
        return match.group(0).replace(" ", "\u00a0")

    lines = (textwrap.fill(_UNBROKEN.sub(glued, line), width, break_long_words=False) for line in title.split("\n"))
    return "\n".join(lines).replace("\u00a0", " ")


def _round_levels(low: float, high: float, count: int) -> np.ndarray:
    """About ``count`` round values (steps of :data:`NICE_STEPS` times a power of ten) from ``low`` to ``high``."""
    return MaxNLocator(count, steps=NICE_STEPS).tick_values(low, high)


def k_unit(convention: str) -> str:
    """The unit of K under a ``passive.convention`` as a figure writes it (``N m/rad``, ``1/s²``).

    Parameters
    ----------
    convention : str
        ``"physical"`` or ``"paper"`` (a landscape's ``passive_convention`` attribute).

    Returns
    -------
    str
        :func:`spinectl.model.source.stiffness_unit` with a superscript square.
    """
    return stiffness_unit(convention).replace("^2", "²")


def _k_label(dataset: xr.Dataset) -> str:
    stiffness = float(dataset["K"])
    convention = dataset.attrs.get("passive_convention", "?")
    if stiffness == 0:  # no convention: 0 is 0 in both, but it has a unit (before: "K = 0" alone)
        return f"K = 0 {k_unit(convention if convention in _CONVENTION else 'physical')}"
    return f"K = {stiffness:g} {k_unit(convention)} (K convention: {_CONVENTION.get(convention, convention)})"
