"""Minimum PCSA and counter torques at one configuration: the readable reference.

Design page, "The optimisation at each grid point":

- minimum PCSA (Figure 3): the LP  min w.x  s.t.  S_k(x) <= -margin for every
  CoR k, 0 <= x <= pcsa_max, with S_k(x) = dM_k/dalpha affine in the PCSA x;
- counter torques (Figure 4): among activations with w.x <= (1 + tol) * min,
  the one of least ||CT||_2 (an SOCP); CT is affine in x.

Decision variables are in cm^2 (well scaled against torques in N m); results
are returned in SI (m^2). Infeasible points are answers, not exceptions:
NaN values and a ``status``.
"""

from __future__ import annotations

from dataclasses import dataclass

import cvxpy as cp
import numpy as np

from . import geometry
from .mechanics import SegmentCoefficients, segment_coefficients
from .params import Model
from .stability import validate_position
from .units import M2_PER_CM2

SOLVERS = ("CLARABEL", "SCS")
"""Solvers tried in order: Clarabel, then SCS as the fallback when Clarabel fails."""

OK_STATUSES = (cp.OPTIMAL, cp.OPTIMAL_INACCURATE)


@dataclass(frozen=True)
class ProblemData:
    """The linear data of the optimisation, decision variables x in cm^2.

    Leading dimensions (if any) are those of the grid of (E, Lambda).

    Attributes
    ----------
    stiffness : numpy.ndarray, shape (..., n_cor, n_var)
        dM_k/dalpha per unit x [N m/rad per cm^2].
    stiffness_bound : numpy.ndarray, shape (..., n_cor)
        Constraint right-hand side: stiffness @ x <= stiffness_bound [N m/rad],
        i.e. -margin - (gravity - passive) stiffness.
    torque : numpy.ndarray, shape (..., n_cor, n_var)
        Muscle torque per unit x [N m per cm^2].
    gravity_torque : numpy.ndarray, shape (..., n_cor)
        M_ext [N m]; CT = -(torque @ x + gravity_torque).
    weights : numpy.ndarray, shape (n_var,)
        Total PCSA [cm^2] per unit x: 2 for a pair (both sides), 1 for a muscle.
    to_muscles : numpy.ndarray, shape (n_muscles, n_var)
        Per-muscle PCSA [cm^2] = to_muscles @ x.
    upper : float
        Bound on every x [cm^2] (inf = none).
    """

    stiffness: np.ndarray
    stiffness_bound: np.ndarray
    torque: np.ndarray
    gravity_torque: np.ndarray
    weights: np.ndarray
    to_muscles: np.ndarray
    upper: float


def problem_data(model: Model, coeffs: SegmentCoefficients) -> ProblemData:
    """Assemble :class:`ProblemData` from the segment coefficients (any leading shape).

    ``optimisation.activation = "paired"`` gives one variable per pair (both
    muscles equal, co-contraction); ``"independent"`` one per muscle.

    Parameters
    ----------
    model : Model
        Supplies the ``optimisation`` settings.
    coeffs : SegmentCoefficients
        Per-unit-PCSA mechanics from :func:`~spinectl.mechanics.segment_coefficients`.
    """
    n_muscles = coeffs.stiffness_per_pcsa.shape[-1]
    if model.optimisation.activation == "paired":
        to_muscles = geometry.pairing_matrix(n_muscles // 2)
    else:
        to_muscles = np.eye(n_muscles)
    per_var = to_muscles * M2_PER_CM2  # m^2 of each muscle per cm^2 of x
    return ProblemData(
        stiffness=coeffs.stiffness_per_pcsa @ per_var,
        stiffness_bound=-model.optimisation.stability_margin - (coeffs.gravity_stiffness - coeffs.passive_stiffness),
        torque=coeffs.torque_per_pcsa @ per_var,
        gravity_torque=coeffs.gravity_torque,
        weights=to_muscles.sum(axis=0),
        to_muscles=to_muscles,
        upper=model.optimisation.pcsa_max / M2_PER_CM2,
    )


def _solve(problem: cp.Problem) -> str:
    """Solve with the first solver that answers; return the cvxpy status or 'solver_error'."""
    for solver in SOLVERS:
        try:
            problem.solve(solver=solver)
        except (cp.error.SolverError, ArithmeticError, ValueError):
            continue
        if problem.status in OK_STATUSES or problem.status in (cp.INFEASIBLE, cp.INFEASIBLE_INACCURATE):
            return problem.status
    return "solver_error"


def _constraints(x: cp.Variable, data: ProblemData) -> list:
    cons = [data.stiffness @ x <= data.stiffness_bound, x >= 0]
    if np.isfinite(data.upper):
        cons.append(x <= data.upper)
    return cons


def min_pcsa_lp(data: ProblemData) -> tuple[str, np.ndarray | None]:
    """Solve the minimum-PCSA LP at one point.

    Parameters
    ----------
    data : ProblemData
        The problem at one (E, Lambda) (no leading dimensions).

    Returns
    -------
    status : str
        'optimal', 'optimal_inaccurate', 'infeasible', 'infeasible_inaccurate' or 'solver_error'.
    x : numpy.ndarray or None
        Optimal decision variables [cm^2], None unless optimal.
    """
    x = cp.Variable(data.weights.size)
    problem = cp.Problem(cp.Minimize(data.weights @ x), _constraints(x, data))
    status = _solve(problem)
    return status, (x.value if status in OK_STATUSES else None)


def min_counter_torque_socp(data: ProblemData, total_max: float) -> tuple[str, np.ndarray | None]:
    """Least ||CT||_2 over self-stable activations with total PCSA <= ``total_max`` [cm^2].

    CT = -(torque @ x + gravity_torque) (paper, Methods; design page, The optimisation).

    Parameters
    ----------
    data : ProblemData
        The problem at one (E, Lambda) (no leading dimensions).
    total_max : float
        Bound on the total PCSA ``weights @ x`` [cm^2].

    Returns
    -------
    status : str
        As for :func:`min_pcsa_lp`.
    x : numpy.ndarray or None
        Decision variables of least ||CT||_2 [cm^2], None unless optimal.
    """
    x = cp.Variable(data.weights.size)
    ct = -(data.torque @ x + data.gravity_torque)
    cons = _constraints(x, data) + [data.weights @ x <= total_max]
    problem = cp.Problem(cp.Minimize(cp.norm(ct, 2)), cons)
    status = _solve(problem)
    return status, (x.value if status in OK_STATUSES else None)


@dataclass(frozen=True)
class PointOptimum:
    """Result of the optimisation at one (E, Lambda).

    Attributes
    ----------
    eccentricity, lordosis : float
        E and Lambda [m].
    status : str
        'optimal' (or 'optimal_inaccurate'), 'infeasible' (no PCSA within the bounds
        stabilises every segment) or 'solver_error'.
    min_pcsa : float
        Minimum total PCSA for self-stability of every segment [m^2]; NaN unless optimal.
    pcsa : numpy.ndarray, shape (n_muscles,)
        Chosen activation: least ||CT|| within ``ct_tolerance`` of the minimum [m^2]; NaN unless optimal.
    counter_torque : numpy.ndarray, shape (n_cor,)
        CT_k at the chosen activation [N m].
    """

    eccentricity: float
    lordosis: float
    status: str
    min_pcsa: float
    pcsa: np.ndarray
    counter_torque: np.ndarray

    @property
    def counter_torque_norm(self) -> float:
        """||CT||_2 [N m] (paper, Figure 4)."""
        return float(np.linalg.norm(self.counter_torque))

    @property
    def ok(self) -> bool:
        """True if the optimum was found."""
        return self.status in OK_STATUSES


def solve_point(model: Model, eccentricity: float, lordosis: float) -> PointOptimum:
    """Minimum PCSA and least counter torque at one configuration (per-point cvxpy reference).

    Parameters
    ----------
    model : Model
        ``optimisation`` sets activation mode, margin, bounds and tolerance.
    eccentricity, lordosis : float
        E and Lambda [m].

    Returns
    -------
    PointOptimum
    """
    validate_position(model, eccentricity, lordosis)
    coeffs = segment_coefficients(model, float(eccentricity), float(lordosis))
    data = problem_data(model, coeffs)
    n_muscles, n_cor = data.to_muscles.shape[0], data.stiffness.shape[0]
    status, x = min_pcsa_lp(data)
    if x is not None:
        total = float(data.weights @ x)
        limit = total * (1.0 + model.optimisation.ct_tolerance)
        status_ct, x_ct = min_counter_torque_socp(data, limit)
        if x_ct is not None:
            x = x_ct
        else:
            status = status_ct
    if x is None or status not in OK_STATUSES:
        nan = np.full(n_muscles, np.nan)
        return PointOptimum(float(eccentricity), float(lordosis), status, np.nan, nan, np.full(n_cor, np.nan))
    pcsa = data.to_muscles @ np.maximum(x, 0.0) * M2_PER_CM2
    return PointOptimum(
        eccentricity=float(eccentricity),
        lordosis=float(lordosis),
        status=status,
        min_pcsa=total * M2_PER_CM2,
        pcsa=pcsa,
        counter_torque=coeffs.counter_torque(pcsa),
    )
