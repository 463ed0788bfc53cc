"""The landscapes the landmarks are measured on: coarse ones for fitting, the paper's grid for verifying.

The fitting landscapes are coarse (17 x 17 by default) and use the fast path
(:mod:`spinectl.optimise.active_set`); the K = 15 N m/rad landscape needs only the minimum
PCSA (stage 1). The fitted model is measured again on the paper's 81 x 81 grid
with full sweeps (:func:`measure_model`), as ``spinectl reproduce`` does.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ...landscape.columns import with_passive
from ...model.checks import checked_coefficients
from ...model.params import Model
from ...optimise import active_set
from ...optimise.problem import problem_data
from ...units import m2_to_cm2
from .. import grid, landmarks
from ..landmarks import Landmarks, Measurement

FIT_POINTS = 17
"""Grid points per axis while fitting: 5 mm steps, which contain the paper's positions
A-D and its optimum (E = 3 cm, Lambda = 4 cm)."""


def coarse_landscape(model: Model, axis, *, counter_torque: bool = True, coefficients=None) -> xr.Dataset:
    """Minimum PCSA (and ‖CT‖) on the grid axis x axis by the fast path, for fitting.

    The variables that :func:`spinectl.paper.landmarks.measure` reads, without the rest
    of a :func:`spinectl.landscape.sweep.sweep` Dataset. Without ``counter_torque`` only
    stage 1 is solved (:func:`spinectl.optimise.active_set.solve_block`), and
    ``counter_torque_norm_Nm`` is absent.

    Parameters
    ----------
    model : Model
    axis : array_like, 1-D
        E and Lambda axis [m].
    counter_torque : bool
        Also solve for the least counter torques.
    coefficients : SegmentCoefficients, optional
        Checked coefficients of ``model`` on the grid, E major (as :func:`coarse_landmarks` shares
        them between its landscapes); default: computed here.

    Returns
    -------
    xarray.Dataset
        ``min_pcsa_cm2`` [cm^2] (and ``counter_torque_norm_Nm`` [N m]) over ``E``, ``Lambda``
        [m]; NaN at infeasible points.
    """
    axis = np.asarray(axis, float)
    e, lam = (a.ravel() for a in np.meshgrid(axis, axis, indexing="ij"))
    data = problem_data(model, checked_coefficients(model, e, lam) if coefficients is None else coefficients)
    result = active_set.solve_block(data, model.optimisation.ct_tolerance, min_pcsa_only=not counter_torque)
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

    Returns
    -------
    Landmarks
        K = 0 with ‖CT‖, K = 15 N m/rad (minimum PCSA only) and, with ``other``, K = 15
        in the other convention (else None).
    """
    axis = grid.paper_axis(points)
    k15 = grid.PAPER_STIFFNESS
    e, lam = (a.ravel() for a in np.meshgrid(axis, axis, indexing="ij"))
    zero = grid.with_stiffness(model, 0.0)
    shared = checked_coefficients(zero, e, lam)  # K enters as K_pas alone: computed once (columns.with_passive)

    def landscape(model_k: Model, counter_torque: bool = False) -> xr.Dataset:
        coefficients = with_passive(model_k, shared, e, lam)
        return coarse_landscape(model_k, axis, counter_torque=counter_torque, coefficients=coefficients)

    k0 = landscape(zero, counter_torque=True)
    own = landscape(grid.with_stiffness(model, k15))
    alt = landscape(grid.with_stiffness(model, k15, grid.other_convention(model))) if other else None
    return Landmarks(k0, own, alt)


def measure_model(model: Model, points: int = grid.PAPER_POINTS, progress=None) -> list[Measurement]:
    """Every landmark of ``model`` measured afresh on the paper's grid (:func:`spinectl.paper.grid.paper_landscapes`).

    Parameters
    ----------
    model : Model
    points : int
        Grid points per axis.
    progress : bool or None
        Progress bars.

    Returns
    -------
    list of Measurement
        As :func:`spinectl.paper.landmarks.measure`, one per landmark.
    """
    both, other = grid.paper_landscapes(model, points, progress)
    k15 = grid.PAPER_STIFFNESS
    return landmarks.measure(Landmarks(both.sel(K=0.0), both.sel(K=k15), other))
