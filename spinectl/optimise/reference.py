"""Minimum PCSA and counter torques at one configuration: the readable reference.

docs/model.md, "The optimisation", and docs/optimisation.md, "Formulation". With the decision
variables x [cm^2], the self-stable set F = {S x <= b, D x <= -damping_margin,
0 <= x <= pcsa_max} (S_k(x) = dM_k/dalpha and D_k(x) = dM_k/domega affine in x,
b = -stability_margin - gravity + passive stiffness; :class:`ProblemData`) and
the counter torques CT(x) = -(T x + g), affine in x:

1. minimum PCSA (Figure 3), the LP  t* = min w.x over F;
2. counter torques (Figure 4), the SOCP  min ||CT(x)||_2 over F within the
   band w.x <= (1 + ct_tolerance) t*. Its CT* is unique (the point of least
   norm in a convex set), but x need not be: the torque of a planar force
   system about a point p is affine in p, so T has rank <= 3, and rank 1 with
   paired activation (CT_k is then proportional to the CoR's x, and every
   activation gives CT = 0 at position A);
3. the chosen activation, unique: least ||x||_2 in the band with CT(x) = CT*
   (a QP; the tie-break that makes both solution paths report the same x).

Every stage is solved with cvxpy (Clarabel, SCS as fallback) and its answer
polished to the exact optimum (:mod:`spinectl.optimise.polish`).

Minimum-norm activations are stage 2 without the band (least ||CT|| over all
self-stable activations), then the least total PCSA with that CT; the Pareto
front is stage 2 for budgets from t* up to the total PCSA of the minimum-norm
activation.

Results are returned in SI (m^2). Infeasible points are answers, not exceptions: NaN values and a
``status``. cvxpy is imported only where a problem is built here (about 2 s); this module imports
neither fast path, which fall back on it and are checked against it.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..model.params import Model
from ..units import M2_PER_CM2
from .problem import (
    INFEASIBLE_STATUSES,
    OK_STATUSES,
    SOLVER_ERROR,
    PointOptimum,
    ProblemData,
    inequalities,
    point_data,
    polished,
    solver_options,
    to_si,
    worst_status,
)

if TYPE_CHECKING:  # cvxpy is imported where a problem is built: it takes about 2 s
    import cvxpy as cp

SOLVERS = ("CLARABEL", "SCS")
"""Solvers tried in order: Clarabel, then SCS as the fallback when Clarabel fails."""


def solve_with_fallback(problem: cp.Problem, tolerance: float | None = None) -> str:
    """Solve with the first solver that answers; return the cvxpy status or 'solver_error'.

    An 'optimal' status without finite values for the variables (a broken
    solver) does not count as an answer. cvxpy's warnings (e.g. "Solution may
    be inaccurate") are silenced: the status records them, and a command-line
    user must see one line, not solver chatter. The per-point reference and the
    coupled chain's semidefinite programs (:mod:`spinectl.optimise.coupled`) share it.

    Parameters
    ----------
    problem : cvxpy.Problem
        The problem; its variables hold the answer afterwards.
    tolerance : float, optional
        Feasibility and gap tolerance (:func:`~spinectl.optimise.problem.solver_options`).

    Returns
    -------
    str
        cvxpy's status ('optimal', 'optimal_inaccurate', 'infeasible', ...) or 'solver_error'.
    """
    import cvxpy as cp

    for solver in SOLVERS:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # only solver code runs in this block
                problem.solve(solver=solver, **solver_options(solver, tolerance))
        except (cp.error.SolverError, ArithmeticError, ValueError):
            continue
        if problem.status in OK_STATUSES and _has_values(problem):
            return problem.status
        if problem.status in INFEASIBLE_STATUSES:
            return problem.status
    return SOLVER_ERROR


def _has_values(problem: cp.Problem) -> bool:
    values = [v.value for v in problem.variables()]
    return all(v is not None and np.all(np.isfinite(v)) for v in values)


def _stage(data: ProblemData, stage: str, cost, total_max=np.inf, x_ct=None) -> tuple[str, np.ndarray | None]:
    """Minimise ``cost(x)`` (a cvxpy expression builder) over G x <= h, then polish."""
    import cvxpy as cp

    lhs, rhs = inequalities(data, total_max, x_ct)
    x = cp.Variable(data.weights.size)
    problem = cp.Problem(cp.Minimize(cost(x)), [lhs @ x <= rhs])
    status = solve_with_fallback(problem, data.tolerance)
    if status not in OK_STATUSES:
        return status, None
    x_opt, verified = polished(data, stage, x.value, total_max, x_ct)
    return ("optimal" if verified else status), x_opt


def _ct_expression(data: ProblemData, x):
    return -(data.torque @ x + data.gravity_torque)


def min_pcsa_lp(data: ProblemData) -> tuple[str, np.ndarray | None]:
    """Stage 1: the minimum-PCSA LP at one point.

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
    return _stage(data, "min_pcsa", lambda x: data.weights @ x)


def min_counter_torque_socp(data: ProblemData, total_max: float) -> tuple[str, np.ndarray | None]:
    """Stage 2: least ||CT||_2 over self-stable activations with total PCSA <= ``total_max`` [cm^2].

    CT = -(torque @ x + gravity_torque) (paper, Methods; docs/model.md, "The
    counter torques"). Solved as the SOCP min ||CT||_2, then polished.

    Parameters
    ----------
    data : ProblemData
        The problem at one (E, Lambda) (no leading dimensions).
    total_max : float
        Bound on the total PCSA ``weights @ x`` [cm^2]; inf drops the band (minimum-norm activations).

    Returns
    -------
    status : str
        As for :func:`min_pcsa_lp`.
    x : numpy.ndarray or None
        Decision variables of least ||CT||_2 [cm^2], None unless optimal.
    """
    import cvxpy as cp

    return _stage(data, "counter_torque", lambda x: cp.norm(_ct_expression(data, x), 2), total_max)


def least_norm_activation_qp(data: ProblemData, total_max: float, x_ct) -> tuple[str, np.ndarray | None]:
    """Stage 3: the activation of least ||x||_2 in the band with the counter torques of ``x_ct``.

    CT(x) = CT(x_ct) is imposed through :func:`ct_slab`.

    Parameters
    ----------
    data : ProblemData
        The problem at one (E, Lambda).
    total_max : float
        The band [cm^2].
    x_ct : array_like
        The stage-2 optimum [cm^2].

    Returns
    -------
    status : str
        As for :func:`min_pcsa_lp`.
    x : numpy.ndarray or None
        [cm^2], None unless optimal.
    """
    import cvxpy as cp

    return _stage(data, "least_norm", cp.sum_squares, total_max, x_ct)


def least_total_pcsa_lp(data: ProblemData, x_ct) -> tuple[str, np.ndarray | None]:
    """The least total PCSA among self-stable activations with the counter torques of ``x_ct``.

    With ``x_ct`` of least ||CT|| over all of F this is the far end of the
    Pareto front: more PCSA buys no lower ||CT||.

    Parameters
    ----------
    data : ProblemData
        The problem at one (E, Lambda).
    x_ct : array_like
        An activation of least ||CT|| [cm^2].

    Returns
    -------
    status : str
        As for :func:`min_pcsa_lp`.
    x : numpy.ndarray or None
        [cm^2], None unless optimal.
    """
    return _stage(data, "min_pcsa", lambda x: data.weights @ x, np.inf, x_ct)


def optimum(data: ProblemData, ct_tolerance: float) -> tuple[str, float, np.ndarray | None]:
    """Stages 1-3 at one point: status, minimum total PCSA [cm^2], chosen x [cm^2].

    ``ct_tolerance = inf`` gives the minimum-norm activation: stage 2 without the
    band, then :func:`least_total_pcsa_lp` instead of the least-norm tie-break.
    The total is NaN and x None unless every stage is optimal.

    Parameters
    ----------
    data : ProblemData
        The problem at one (E, Lambda).
    ct_tolerance : float
        Relative band on the minimum total PCSA [1].

    Returns
    -------
    status : str
        The worst status of the three stages ('optimal' or 'optimal_inaccurate'), or
        the first stage's that failed ('infeasible', 'solver_error', ...).
    min_pcsa : float
        Minimum total PCSA t* [cm^2]; NaN unless every stage is optimal.
    x : numpy.ndarray or None, shape (n_var,)
        The chosen decision variables [cm^2], >= 0; None unless every stage is optimal.
    """
    status, x = min_pcsa_lp(data)
    if x is None:
        return status, np.nan, None
    total = float(data.weights @ x)
    limit = total * (1.0 + ct_tolerance)
    status_ct, x_ct = min_counter_torque_socp(data, limit)
    if x_ct is None:
        return status_ct, np.nan, None
    if np.isinf(limit):
        status_tie, x_tie = least_total_pcsa_lp(data, x_ct)
    else:
        status_tie, x_tie = least_norm_activation_qp(data, limit, x_ct)
    if x_tie is None:
        return status_tie, np.nan, None
    return worst_status(status, status_ct, status_tie), total, np.maximum(x_tie, 0.0)


def point_optimum(data: ProblemData, ct_tolerance: float, eccentricity=np.nan, lordosis=np.nan) -> PointOptimum:
    """:func:`optimum` as a :class:`PointOptimum` in SI units (NaN unless optimal).

    Parameters
    ----------
    data : ProblemData
        The problem at one (E, Lambda).
    ct_tolerance : float
        Relative band on the minimum total PCSA [1]; inf: the minimum-norm activation.
    eccentricity, lordosis : float
        E and Lambda [m], recorded in the result.

    Returns
    -------
    PointOptimum
        Status, minimum total PCSA [m^2], per-muscle PCSA [m^2] and CT_k [N m]; NaN
        values unless optimal.
    """
    status, total, x = optimum(data, ct_tolerance)
    if x is None:
        x = np.full(data.weights.size, np.nan)
    min_pcsa, pcsa, counter_torque = to_si(data, total, x)
    return PointOptimum(float(eccentricity), float(lordosis), status, float(min_pcsa), pcsa, counter_torque)


def solve_point(model: Model, eccentricity: float, lordosis: float) -> PointOptimum:
    """Minimum PCSA and least counter torque at one configuration (per-point cvxpy reference).

    The paper's two questions [1]_: the minimum PCSA for self-stability of every
    segment by eq. 1 (its Figure 3) and the counter torques at that activation (its
    Figure 4), as the convex problems of docs/model.md, "The optimisation".

    Parameters
    ----------
    model : Model
        ``optimisation`` sets activation mode, margin, bounds and tolerances.
    eccentricity, lordosis : float
        E and Lambda [m].

    Returns
    -------
    PointOptimum
        Status ('optimal', 'optimal_inaccurate', 'infeasible' or 'solver_error'), the
        minimum total PCSA [m^2], the chosen PCSA of each muscle [m^2] and CT_k [N m]
        (shape (n_cor,)); NaN values unless optimal.

    Raises
    ------
    ParameterError
        E or Lambda outside the modelled range.
    ModelError
        The model cannot be evaluated there (see :func:`~spinectl.model.checks.validate_position`).

    References
    ----------
    .. [1] Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal
       lordosis optimizes the requirements for a stable erect posture. Theor Biol Med
       Model 9:13. doi:10.1186/1742-4682-9-13

    Examples
    --------
    >>> from spinectl import load_preset
    >>> from spinectl.optimise import solve_point
    >>> optimum = solve_point(load_preset("wagner2012"), 0.03, 0.04)
    >>> optimum.status, round(optimum.min_pcsa * 1e4, 1)  # [cm^2]
    ('optimal', 35.8)
    """
    data = point_data(model, eccentricity, lordosis)
    return point_optimum(data, model.optimisation.ct_tolerance, eccentricity, lordosis)


def min_norm_activation(model: Model, eccentricity: float, lordosis: float) -> PointOptimum:
    """The minimum-norm activation: least ||CT||_2 over all self-stable activations.

    No budget on the total PCSA (docs/optimisation.md, "Formulation": minimum-norm
    activations); ties broken by least total PCSA. ``min_pcsa`` is still the
    minimum total PCSA of stage 1, ``total_pcsa`` what this activation uses.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].

    Returns
    -------
    PointOptimum
        As :func:`solve_point`, with the minimum-norm activation as ``pcsa`` [m^2].
    """
    data = point_data(model, eccentricity, lordosis)
    return point_optimum(data, np.inf, eccentricity, lordosis)


@dataclass(frozen=True)
class CounterTorqueFront:
    """Least ||CT||_2 against the budget of total PCSA at one configuration.

    Attributes
    ----------
    eccentricity, lordosis : float
        E and Lambda [m].
    total_pcsa : numpy.ndarray, shape (n,)
        Budgets on the total PCSA [m^2], from the minimum to that of the minimum-norm activation.
    counter_torque_norm : numpy.ndarray, shape (n,)
        Least ||CT||_2 within each budget [N m]; non-increasing.
    status : tuple of str
        Solver status per budget.
    """

    eccentricity: float
    lordosis: float
    total_pcsa: np.ndarray
    counter_torque_norm: np.ndarray
    status: tuple[str, ...]


def counter_torque_front(model: Model, eccentricity: float, lordosis: float, n_points: int = 21) -> CounterTorqueFront:
    """The Pareto front between total PCSA and ||CT||_2 (docs/optimisation.md, "Formulation").

    Stage 2 with the budget as a cvxpy Parameter, for ``n_points`` budgets
    evenly spaced from the minimum total PCSA to the total of the minimum-norm
    activation. An infeasible point gives empty arrays and its status.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    n_points : int
        Number of budgets.

    Returns
    -------
    CounterTorqueFront
        Budgets on the total PCSA [m^2], shape (n_points,), the least ||CT||_2 within
        each [N m] and the status per budget.
    """
    data = point_data(model, eccentricity, lordosis)
    far = point_optimum(data, np.inf)
    if not far.ok:
        return CounterTorqueFront(float(eccentricity), float(lordosis), np.array([]), np.array([]), (far.status,))
    lowest = far.min_pcsa / M2_PER_CM2
    budgets = np.linspace(lowest, max(far.total_pcsa / M2_PER_CM2, lowest), n_points)
    norms, statuses = [], []
    import cvxpy as cp

    lhs, rhs = inequalities(data)
    budget = cp.Parameter(nonneg=True)
    x = cp.Variable(data.weights.size)
    constraints = [lhs @ x <= rhs, data.weights @ x <= budget]
    problem = cp.Problem(cp.Minimize(cp.norm(_ct_expression(data, x), 2)), constraints)
    for value in budgets:
        budget.value = value
        status = solve_with_fallback(problem, data.tolerance)
        statuses.append(status)
        norm = np.nan
        if status in OK_STATUSES:
            norm = np.linalg.norm(data.counter_torque(polished(data, "counter_torque", x.value, value)[0]))
        norms.append(norm)
    return CounterTorqueFront(
        float(eccentricity), float(lordosis), budgets * M2_PER_CM2, np.asarray(norms), tuple(statuses)
    )
