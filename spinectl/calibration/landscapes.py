"""The landscapes the landmarks are measured on: coarse ones for fitting, the paper's grid for verifying.

The fitting landscapes are coarse (17 x 17 by default) and use the fast path
(:mod:`spinectl.batch`); the K = 15 N m/rad landscape needs only the minimum
PCSA (stage 1). The fitted model is measured again on the paper's 81 x 81 grid
with full sweeps (:func:`measure_model`), as ``spinectl reproduce`` does.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from .. import batch, landmarks, sweep
from ..config import set_parameters
from ..landmarks import Landmarks, Measurement
from ..optimise import problem_data
from ..params import Model
from ..stability import checked_coefficients
from ..units import m2_to_cm2

CONVENTIONS = ("physical", "paper")
"""The two readings of the passive stiffness K in eq. 2 (design page, erratum eq. 2)."""

PAPER_RANGE = (0.0, 0.08)
"""E and Lambda [m] of the paper's grid (paper, Methods: 0 to 8 cm)."""

FIT_POINTS = 17
"""Grid points per axis while fitting: 5 mm steps, which contain the paper's positions
A-D and its optimum (E = 3 cm, Lambda = 4 cm)."""

PAPER_POINTS = 81
"""Grid points per axis of the paper's grid (1 mm steps; paper, Methods; design page), on which
the calibrated model is measured."""


def paper_axis(points: int) -> np.ndarray:
    """The paper's E and Lambda axis, 0 to 8 cm, with ``points`` points [m].

    Parameters
    ----------
    points : int
        Number of grid points (81: 1 mm steps).
    """
    return np.linspace(*PAPER_RANGE, int(points))


def other_convention(model: Model) -> str:
    """The passive-stiffness convention that ``model`` does not use.

    Parameters
    ----------
    model : Model
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
    """
    values = {"passive.stiffness": float(stiffness)}
    if convention is not None:
        values["passive.convention"] = convention
    return set_parameters(model, values)


def coarse_landscape(model: Model, axis, *, counter_torque: bool = True) -> xr.Dataset:
    """Minimum PCSA (and ‖CT‖) on the grid axis x axis by the fast path, for fitting.

    The variables that :func:`spinectl.landmarks.measure` reads, without the rest
    of a :func:`spinectl.sweep.sweep` Dataset. Without ``counter_torque`` only
    stage 1 is solved (:func:`spinectl.batch.solve_stacked`), and
    ``counter_torque_norm_Nm`` is absent.

    Parameters
    ----------
    model : Model
    axis : array_like, 1-D
        E and Lambda axis [m].
    counter_torque : bool
        Also solve for the least counter torques.
    """
    axis = np.asarray(axis, float)
    e, lam = (a.ravel() for a in np.meshgrid(axis, axis, indexing="ij"))
    data = problem_data(model, checked_coefficients(model, e, lam))
    result = batch.solve_stacked(data, model.optimisation.ct_tolerance, min_pcsa_only=not counter_torque)
    shape, dims = (axis.size, axis.size), ("E", "Lambda")
    variables = {"min_pcsa_cm2": (dims, m2_to_cm2(result.min_pcsa).reshape(shape))}
    if counter_torque:
        variables["counter_torque_norm_Nm"] = (dims, np.linalg.norm(result.counter_torque, axis=-1).reshape(shape))
    return xr.Dataset(variables, coords={"E": axis, "Lambda": axis})


def coarse_landmarks(model: Model, points: int = FIT_POINTS, *, other: bool = False) -> Landmarks:
    """The landscapes the landmarks need, on a coarse grid (:func:`coarse_landscape`).

    K = 0 with counter torques; K = 15 N m/rad with the model's convention; with
    ``other``, K = 15 with the other convention too.

    Parameters
    ----------
    model : Model
    points : int
        Grid points per axis.
    other : bool
        Also the K = 15 landscape of the other convention.
    """
    axis = paper_axis(points)
    k15 = landmarks.PAPER_STIFFNESS
    k0 = coarse_landscape(with_stiffness(model, 0.0), axis)
    own = coarse_landscape(with_stiffness(model, k15), axis, counter_torque=False)
    alt = None
    if other:
        alt = coarse_landscape(with_stiffness(model, k15, other_convention(model)), axis, counter_torque=False)
    return Landmarks(k0, own, alt)


def paper_landscapes(model: Model, points: int = PAPER_POINTS, progress=None) -> tuple[xr.Dataset, xr.Dataset]:
    """Full sweeps for the landmarks: K = 0 and 15 N m/rad (model's convention), and K = 15 (other).

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
        :func:`spinectl.sweep.stiffness_sweep` over K = 0 and 15.
    other : xarray.Dataset
        :func:`spinectl.sweep.sweep` at K = 15 with the other convention.
    """
    axis = paper_axis(points)
    k15 = landmarks.PAPER_STIFFNESS
    both = sweep.stiffness_sweep(model, [0.0, k15], axis, axis, progress=progress)
    other = sweep.sweep(with_stiffness(model, k15, other_convention(model)), axis, axis, progress=progress)
    return both, other


def measure_model(model: Model, points: int = PAPER_POINTS, progress=None) -> list[Measurement]:
    """Every landmark of ``model`` measured afresh on the paper's grid (:func:`paper_landscapes`).

    Parameters
    ----------
    model : Model
    points : int
        Grid points per axis.
    progress : bool or None
        Progress bars.
    """
    both, other = paper_landscapes(model, points, progress)
    k15 = landmarks.PAPER_STIFFNESS
    return landmarks.measure(Landmarks(both.sel(K=0.0), both.sel(K=k15), other))
