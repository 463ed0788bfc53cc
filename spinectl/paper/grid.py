"""The paper's study, defined once: its grid, positions A-D, stiffnesses and conventions.

Wagner et al. (2012), Methods: E and Lambda from 0 to 8 cm in 1 mm steps (81 x 81 points),
the passive stiffness K = 0 and K = 15 N m/rad; docs/model.md, "Passive stiffness: two
conventions", for the two readings of K in eq. 2. :func:`paper_landscapes` solves the study's landscapes; the
main job (:func:`spinectl.paper.reproduce`), the calibration and the notebooks
all start from here.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ..landscape import sweep
from ..model.config import set_parameters
from ..model.params import Model

POSITIONS = {"A": (0.0, 0.0), "B": (0.08, 0.0), "C": (0.08, 0.08), "D": (0.0, 0.08)}
"""(E, Lambda) [m] of positions A-D, the corners of Figures 3 and 4.

docs/optimisation.md, "Reading of the positions", and docs/glossary.md."""


PAPER_STIFFNESS = 15.0
"""Passive stiffness K of the ligamentous sheath [N m/rad] (paper, Elastic elements; its ref. 26)."""

STIFFNESSES = (0.0, PAPER_STIFFNESS)
"""The passive stiffnesses K [N m/rad] of the paper's landscapes: Figure 3 (K = 0) and Figure S1 (K = 15)."""

CONVENTIONS = ("physical", "paper")
"""The two readings of the passive stiffness K in eq. 2 (docs/model.md, "Passive stiffness: two conventions")."""


PAPER_RANGE = (0.0, 0.08)
"""E and Lambda [m] of the paper's grid (paper, Methods: 0 to 8 cm)."""


PAPER_POINTS = 81
"""Grid points per axis of the paper's grid, on which the calibrated model is measured: 1 mm steps
(paper, Methods, Stability analysis and calculation of counter torques; its section on the
musculoskeletal model speaks of 100 equidistant steps instead)."""


def paper_axis(points: int) -> np.ndarray:
    """The paper's E and Lambda axis, 0 to 8 cm, with ``points`` points [m].

    Parameters
    ----------
    points : int
        Number of grid points (81: 1 mm steps).

    Returns
    -------
    numpy.ndarray, shape (points,)
        The axis [m], evenly spaced from 0 to 0.08.
    """
    return np.linspace(*PAPER_RANGE, int(points))


def other_convention(model: Model) -> str:
    """The passive-stiffness convention that ``model`` does not use.

    Parameters
    ----------
    model : Model

    Returns
    -------
    str
        'paper' for a 'physical' model and vice versa.
    """
    return next(c for c in CONVENTIONS if c != model.passive.convention)


def with_stiffness(model: Model, stiffness: float, convention: str | None = None) -> Model:
    """``model`` with passive stiffness K [N m/rad] and, if given, its convention.

    Parameters
    ----------
    model : Model
    stiffness : float
        K [N m/rad].
    convention : str, optional
        'physical' or 'paper'.

    Returns
    -------
    Model
        A new, validated model; ``model`` is unchanged.
    """
    values = {"passive.stiffness": float(stiffness)}
    if convention is not None:
        values["passive.convention"] = convention
    return set_parameters(model, values)


def paper_landscapes(model: Model, points: int = PAPER_POINTS, progress=None) -> tuple[xr.Dataset, xr.Dataset]:
    """Full sweeps for the landmarks: K = 0 and 15 N m/rad (model's convention), and K = 15 (other).

    The three share the grid and everything but K, so they are solved in one pass
    (:func:`spinectl.landscape.sweep.passive_sweeps`: the coefficients computed once).

    Parameters
    ----------
    model : Model
    points : int
        Grid points per axis (81: the paper's 1 mm).
    progress : bool or None
        Progress bars (None: on a terminal only).

    Returns
    -------
    both : xarray.Dataset
        :func:`spinectl.landscape.sweep.stiffness_sweep` over K = 0 and 15.
    other : xarray.Dataset
        :func:`spinectl.landscape.sweep.sweep` at K = 15 with the other convention.
    """
    axis = paper_axis(points)
    models = [with_stiffness(model, k) for k in STIFFNESSES] + [
        with_stiffness(model, PAPER_STIFFNESS, other_convention(model))
    ]
    *parts, other = sweep.passive_sweeps(models, axis, axis, progress=progress)
    return sweep.stack_stiffnesses(parts, model), other
