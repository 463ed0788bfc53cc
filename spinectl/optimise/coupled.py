"""Coupled stability of the lumbar chain: semidefinite programmes per point (docs/chain.md).

The paper tests each centre of rotation alone. With all five free at once
(:mod:`spinectl.model.chain`), the upright chain is statically stable when its stiffness
matrix is negative definite (Bergmark 1989), here with the margin mu
(``optimisation.stability_margin``, the per-segment margin):

    diag(k) - K(x) >= mu I   (a linear matrix inequality, LMI),

K(x) = K_g - diag(K_pas) + sum_i x_i K_i affine in the global PCSA x [cm^2] (the decision
variables of :class:`~spinectl.optimise.problem.ProblemData`, paired or independent), k >= 0
the stiffness of local muscles at each joint [N m/rad]. Three questions, each an SDP
solved with cvxpy and Clarabel (PSD cone; SCS as the fallback):

(a) :func:`least_local_stiffness`: at a given global activation, the least sum of k;
(b) :func:`min_global_pcsa`: global muscles only (k = 0), the least total PCSA;
(c) :func:`joint_optimum`: the least total global PCSA + w * local PCSA, with the local
    PCSA k / kappa of :func:`spinectl.model.chain.local_pcsa` and w ``local.cost_weight``;
    :func:`pareto_front`: every w at once, the least global PCSA for each bound on sum(k).

(b) and (c) keep the per-segment problem's rows (:func:`~spinectl.optimise.problem.inequalities`):
the damping rows D_k <= -damping_margin and the bounds on x; (b) also its stiffness rows
S_k <= -mu, which the LMI implies (they are its diagonal). So the coupled feasible set lies
inside the per-segment one and the coupled minimum is never below the paper's. A point where
no activation stabilises the chain is an answer: NaN values and the solver's status.

For grids, (a) and (c) also come stacked: the points of a chunk share no variable, so one
Clarabel problem with a PSD cone per point solves them all (:func:`least_local_stiffness_stacked`,
:func:`joint_optimum_stacked`; the landscape's variables), the per-point SDPs the reference.

The solver's k is made exactly feasible by a uniform shift, k + max(0, mu - margin): adding
c to every k_j adds c I to the matrix. The reported margin is that of numpy's eigvalsh.

References
----------
Bergmark A (1989). Stability of the lumbar spine. A study in mechanical engineering.
Acta Orthop Scand Suppl 230:1-54. doi:10.3109/17453678909154177.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import TYPE_CHECKING

import clarabel
import numpy as np

from ..errors import ParameterError
from ..model import chain, geometry
from ..model.checks import arithmetic_guard, checked_coefficients, expand_pcsa
from ..model.params import Model
from ..model.source import header, provenance
from ..model.stability import self_stable
from ..units import M2_PER_CM2, m2_to_cm2
from .problem import OK_STATUSES, ProblemData, inequalities, problem_data, to_si
from .reference import solve_with_fallback
from .stabilising import minimum_stabilising_pcsa
from .stacked import CLARABEL_STATUS, stacked_settings

if TYPE_CHECKING:  # imported where a problem is built: cvxpy takes over a second, and a sweep needs neither
    import cvxpy as cp


@dataclass(frozen=True)
class CoupledData:
    """The data of the coupled problems at one (E, Lambda), decision variables x in cm^2.

    Attributes
    ----------
    problem : ProblemData
        The per-segment formulation: weights, bounds, damping rows, x -> muscles, CT.
    coefficients : ChainCoefficients
        The chain's matrices per unit PCSA (SI), :func:`spinectl.model.chain.chain_coefficients`.
    stiffness : numpy.ndarray, shape (n_cor, n_cor, n_var)
        K per unit x [N m/rad per cm^2].
    stiffness_offset : numpy.ndarray, shape (n_cor, n_cor)
        K at x = 0: gravity and passive stiffness [N m/rad].
    margin : float
        mu [N m/rad] (``optimisation.stability_margin``).
    local_per_cm2 : float
        kappa, joint stiffness per cm^2 of local muscle [N m/rad per cm^2].
    cost_weight : float
        w, the cost of a cm^2 of local muscle in cm^2 of global muscle [1] (``local.cost_weight``).
    """

    problem: ProblemData
    coefficients: chain.ChainCoefficients
    stiffness: np.ndarray
    stiffness_offset: np.ndarray
    margin: float
    local_per_cm2: float
    cost_weight: float

    def matrix(self, x, local_stiffness=0.0) -> np.ndarray:
        """K(x) - diag(k) [N m/rad] for decision variables ``x`` [cm^2].

        Parameters
        ----------
        x : array_like, shape (n_var,)
            Decision variables [cm^2].
        local_stiffness : array_like, shape (n_cor,)
            k [N m/rad]; 0: none.

        Returns
        -------
        numpy.ndarray, shape (n_cor, n_cor)
            [N m/rad].
        """
        k = np.broadcast_to(np.asarray(local_stiffness, float), self.stiffness_offset.shape[:1])
        return self.stiffness_offset + self.stiffness @ np.asarray(x, float) - np.diag(k)


def coupled_data(model: Model, eccentricity: float, lordosis: float) -> CoupledData:
    """Assemble :class:`CoupledData` at one configuration.

    Parameters
    ----------
    model : Model
        ``optimisation`` (activation, margins, bounds, tolerance) and ``local``.
    eccentricity, lordosis : float
        E and Lambda [m], inside the modelled range.

    Returns
    -------
    CoupledData

    Raises
    ------
    ParameterError
        E or Lambda is outside the modelled range (:func:`~spinectl.model.checks.validate_position`).
    ModelError
        A fibre attachment lies on a CoR, or the arithmetic overflows.
    """
    e, lam = float(eccentricity), float(lordosis)
    data = problem_data(model, checked_coefficients(model, e, lam))
    with arithmetic_guard(e, lam):
        coeffs = chain.chain_coefficients(model, e, lam)
    per_var = data.to_muscles * M2_PER_CM2  # m^2 of each muscle per cm^2 of x
    return CoupledData(
        problem=data,
        coefficients=coeffs,
        stiffness=coeffs.stiffness_per_pcsa @ per_var,
        stiffness_offset=coeffs.stiffness(np.zeros(per_var.shape[0])),
        margin=model.optimisation.stability_margin,
        local_per_cm2=chain.local_stiffness_per_pcsa(model) * M2_PER_CM2,
        cost_weight=model.local.cost_weight,
    )


def _lmi(data: CoupledData, x, k=None) -> cp.Constraint:
    """diag(k) - K(x) - mu I >> 0 as a cvxpy constraint; x a cvxpy variable or fixed values [cm^2]."""
    import cvxpy as cp

    n = data.stiffness_offset.shape[0]
    if isinstance(x, cp.Expression):
        stiffness = data.stiffness_offset + sum(x[i] * data.stiffness[:, :, i] for i in range(data.stiffness.shape[-1]))
    else:
        stiffness = data.matrix(x)
    matrix = -stiffness - data.margin * np.eye(n)
    return (matrix if k is None else matrix + cp.diag(k)) >> 0


def _shifted(stiffness, margin: float, k) -> np.ndarray:
    """k >= 0 shifted so that diag(k) - K >= mu I holds to rounding (adding c to every k_j adds c I); vectorised."""
    k = np.maximum(np.asarray(k, float), 0.0)
    shortfall = margin - chain.coupled_margin(np.asarray(stiffness, float) - k[..., :, None] * np.eye(k.shape[-1]))
    return k + np.maximum(shortfall, 0.0)[..., None]


def _feasible_local(data: CoupledData, x, k) -> np.ndarray:
    """:func:`_shifted` at K(x)."""
    return _shifted(data.matrix(x), data.margin, k)


def least_local_stiffness_at(stiffness, margin: float, tolerance: float | None = None):
    """(a) The least total local stiffness sum(k) with diag(k) - K >= mu I, k >= 0, for one matrix K.

    Always feasible (large k); the dual is max <Z, K + mu I> over Z >= 0, diag(Z) <= 1. The
    per-point reference (cvxpy, Clarabel with SCS as the fallback) of
    :func:`least_local_stiffness_stacked`.

    Parameters
    ----------
    stiffness : array_like, shape (n, n)
        K [N m/rad].
    margin : float
        mu [N m/rad].
    tolerance : float, optional
        The solver's gap and feasibility tolerance.

    Returns
    -------
    status : str
        'optimal', 'optimal_inaccurate' or 'solver_error'.
    k : numpy.ndarray or None
        Local stiffness per joint [N m/rad], None unless optimal; exactly feasible (a uniform shift).
    """
    import cvxpy as cp

    stiffness = np.asarray(stiffness, float)
    n = stiffness.shape[0]
    k = cp.Variable(n, nonneg=True)
    problem = cp.Problem(cp.Minimize(cp.sum(k)), [cp.diag(k) - stiffness - margin * np.eye(n) >> 0])
    status = solve_with_fallback(problem, tolerance)
    if status not in OK_STATUSES:
        return status, None
    return status, _shifted(stiffness, margin, k.value)


def least_local_stiffness_sdp(data: CoupledData, x) -> tuple[str, np.ndarray | None]:
    """(a) The least total local stiffness sum(k) with diag(k) - K(x) >= mu I, k >= 0.

    :func:`least_local_stiffness_at` with K(x).

    Parameters
    ----------
    data : CoupledData
    x : array_like, shape (n_var,)
        Global activation as decision variables [cm^2].

    Returns
    -------
    status : str
        'optimal', 'optimal_inaccurate' or 'solver_error'.
    k : numpy.ndarray or None
        Local stiffness per joint [N m/rad], None unless optimal.
    """
    return least_local_stiffness_at(data.matrix(np.asarray(x, float)), data.margin, data.problem.tolerance)


def _svec(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Clarabel's PSD-triangle order: the upper triangle column by column, off-diagonals scaled by sqrt 2."""
    rows, cols = np.triu_indices(n)
    order = np.lexsort((rows, cols))  # column-major
    rows, cols = rows[order], cols[order]
    return rows, cols, np.where(rows == cols, 1.0, np.sqrt(2.0))


def least_local_stiffness_stacked(stiffness, margin: float, tolerance: float | None = None):
    """(a) at P points at once: one Clarabel problem with a 5 x 5 PSD cone per point.

    The points' problems share no variable, so the stacked problem is block diagonal: for each
    point p, min sum(k_p) s.t. diag(k_p) - K_p - mu I >= 0 (a PSD-triangle cone), k_p >= 0.
    The solution is made exactly feasible per point like :func:`least_local_stiffness_sdp`'s.
    The sum of the P objectives is minimised with the tolerance relative to it, so each point's
    own optimum holds to about P times the tolerance relative to the total; the benchmark
    (benchmarks/bench_local_stiffness.py) and the tests compare with the per-point SDP.

    Parameters
    ----------
    stiffness : array_like, shape (P, n, n)
        K at each point [N m/rad]; a point with a NaN gives NaN.
    margin : float
        mu [N m/rad].
    tolerance : float, optional
        Clarabel's gap and feasibility tolerance (``optimisation.solver_tolerance``).

    Returns
    -------
    status : str
        Clarabel's status in cvxpy's words ('optimal', 'optimal_inaccurate', 'solver_error').
    k : numpy.ndarray, shape (P, n)
        The least local stiffness at each point [N m/rad]; NaN unless optimal and finite.

    References
    ----------
    Goulart PJ, Chen Y (2024). Clarabel: an interior-point solver for conic programs with
    quadratic objectives. arXiv:2405.12762. doi:10.48550/arXiv.2405.12762.
    """
    import scipy.sparse as sp

    a = np.asarray(stiffness, float)
    points, n = a.shape[0], a.shape[-1]
    k = np.full((points, n), np.nan)
    finite = np.flatnonzero(np.all(np.isfinite(a), axis=(-2, -1)))
    if finite.size == 0:
        return "optimal", k
    m = finite.size
    rows, cols, scale = _svec(n)
    width = rows.size
    target = -(a[finite] + margin * np.eye(n))  # s = svec(diag(k) - K - mu I) = b - A k
    b_psd = (target[:, rows, cols] * scale).ravel()
    diagonal = np.flatnonzero(rows == cols)  # positions of (j, j) in a block, in j order
    psd = sp.csc_matrix(
        (np.full(m * n, -1.0), ((np.arange(m)[:, None] * width + diagonal).ravel(), np.arange(m * n))),
        shape=(m * width, m * n),
    )
    lhs = sp.vstack([psd, -sp.identity(m * n, format="csc")]).tocsc()
    rhs = np.concatenate([b_psd, np.zeros(m * n)])
    cones = [clarabel.PSDTriangleConeT(n)] * m + [clarabel.NonnegativeConeT(m * n)]
    try:
        solution = clarabel.DefaultSolver(
            sp.csc_matrix((m * n, m * n)), np.ones(m * n), lhs, rhs, cones, stacked_settings(tolerance)
        ).solve()
    except (ValueError, RuntimeError, ArithmeticError):  # a solver panic: unsolved
        return "solver_error", k
    status = CLARABEL_STATUS.get(solution.status, "solver_error")
    if status not in OK_STATUSES:
        return status, k
    k[finite] = _shifted(a[finite], margin, np.asarray(solution.x).reshape(m, n))
    return status, k


def joint_optimum_stacked(
    data: ProblemData, coefficients: chain.ChainCoefficients, margin: float, local_per_cm2, cost_weight
):
    """(c) at P points at once: one Clarabel problem, per point a PSD cone, the LP rows and k >= 0.

    Per point p, with z_p = (x_p, k_p): min w.x_p + cost_weight sum(k_p) / kappa subject to
    diag(k_p) - K_p(x_p) - mu I >= 0 (a PSD-triangle cone), the per-segment rows of
    :func:`joint_optimum_sdp` (damping rows, bounds on x) and k_p >= 0. The points share no
    variable, so the problem is block diagonal; a chunk that fails as a whole (an infeasible
    point spoils the stack) returns its status and NaN, for the caller to solve per point.

    Parameters
    ----------
    data : ProblemData
        The per-segment problem at the P points (leading dimension P).
    coefficients : ChainCoefficients
        The chain's matrices at the same points (:func:`spinectl.model.chain.chain_coefficients`).
    margin : float
        mu [N m/rad].
    local_per_cm2 : float
        kappa [N m/rad per cm^2] (:func:`spinectl.model.chain.local_stiffness_per_pcsa`).
    cost_weight : float
        w_local [1].

    Returns
    -------
    status : str
        Clarabel's status in cvxpy's words.
    x : numpy.ndarray, shape (P, n_var)
        Global decision variables [cm^2]; NaN unless optimal.
    k : numpy.ndarray, shape (P, n_cor)
        Local stiffness [N m/rad]; NaN unless optimal.
    """
    import scipy.sparse as sp

    per_var = coefficients.stiffness_per_pcsa @ (data.to_muscles * M2_PER_CM2)  # (P, n, n, v)
    offset = coefficients.stiffness(np.zeros(data.to_muscles.shape[0]))  # (P, n, n)
    points, n, v = per_var.shape[0], per_var.shape[1], per_var.shape[-1]
    lhs, rhs = inequalities(data)
    lhs, rhs = lhs[:, n:], rhs[:, n:]  # drop the per-segment stiffness rows, as joint_optimum_sdp does
    rows, cols, scale = _svec(n)
    width = rows.size
    psd = np.zeros((points, width, v + n))
    psd[:, :, :v] = per_var[:, rows, cols, :] * scale[:, None]  # s = svec(-K0 - mu I - sum x_i K_i + diag k)
    psd[:, np.flatnonzero(rows == cols), v + np.arange(n)] = -1.0
    b_psd = (-(offset + margin * np.eye(n))[:, rows, cols] * scale).reshape(-1)
    nonneg = np.concatenate([np.zeros((n, v)), -np.eye(n)], axis=1)  # s = k >= 0
    linear = np.concatenate(
        [np.concatenate([lhs, np.zeros(lhs.shape[:2] + (n,))], axis=-1), np.broadcast_to(nonneg, (points, n, v + n))],
        axis=1,
    )
    b_linear = np.concatenate([rhs, np.zeros((points, n))], axis=1).reshape(-1)
    lhs_matrix = sp.vstack([sp.block_diag(list(psd), format="csc"), sp.block_diag(list(linear), format="csc")]).tocsc()
    cost = np.tile(np.concatenate([data.weights, np.full(n, cost_weight / local_per_cm2)]), points)
    cones = [clarabel.PSDTriangleConeT(n)] * points + [clarabel.NonnegativeConeT(b_linear.size)]
    x, k = np.full((points, v), np.nan), np.full((points, n), np.nan)
    try:
        solution = clarabel.DefaultSolver(
            sp.csc_matrix((cost.size, cost.size)), cost, lhs_matrix, np.concatenate([b_psd, b_linear]), cones,
            stacked_settings(data.tolerance),
        ).solve()  # fmt: skip
    except (ValueError, RuntimeError, ArithmeticError):
        return "solver_error", x, k
    status = CLARABEL_STATUS.get(solution.status, "solver_error")
    if status not in OK_STATUSES:
        return status, x, k
    z = np.asarray(solution.x).reshape(points, v + n)
    x = np.maximum(z[:, :v], 0.0)
    matrix = offset + np.einsum("pjkv,pv->pjk", per_var, x)
    return status, x, _shifted(matrix, margin, z[:, v:])


def min_global_pcsa_sdp(data: CoupledData) -> tuple[str, np.ndarray | None]:
    """(b) The least total global PCSA w.x with -K(x) >= mu I and the per-segment rows, k = 0.

    Parameters
    ----------
    data : CoupledData

    Returns
    -------
    status : str
        'optimal', 'optimal_inaccurate', 'infeasible', 'infeasible_inaccurate' or 'solver_error'.
    x : numpy.ndarray or None
        Decision variables [cm^2], None unless optimal.
    """
    import cvxpy as cp

    lhs, rhs = inequalities(data.problem)
    x = cp.Variable(data.problem.weights.size)
    problem = cp.Problem(cp.Minimize(data.problem.weights @ x), [lhs @ x <= rhs, _lmi(data, x)])
    status = solve_with_fallback(problem, data.problem.tolerance)
    if status not in OK_STATUSES:
        return status, None
    return status, np.maximum(x.value, 0.0)


def joint_optimum_sdp(data: CoupledData) -> tuple[str, np.ndarray | None, np.ndarray | None]:
    """(c) The least w.x + cost_weight * sum(k) / kappa with diag(k) - K(x) >= mu I, k >= 0.

    The per-segment damping rows and bounds on x hold; the per-segment stiffness rows do not
    apply, local stiffness entering each joint (the LMI's diagonal is S_k - k_k <= -mu).

    Parameters
    ----------
    data : CoupledData

    Returns
    -------
    status : str
        As for :func:`min_global_pcsa_sdp`.
    x : numpy.ndarray or None
        Global decision variables [cm^2], None unless optimal.
    k : numpy.ndarray or None
        Local stiffness per joint [N m/rad], None unless optimal.
    """
    import cvxpy as cp

    x, k, constraints = _joint_variables(data)
    cost = data.problem.weights @ x + data.cost_weight * cp.sum(k) / data.local_per_cm2
    return _solve_joint(data, cp.Problem(cp.Minimize(cost), constraints), x, k)


def _joint_variables(data: CoupledData):
    """x, k >= 0 and the constraints of (c): the per-segment rows without the stiffness rows, and the LMI."""
    import cvxpy as cp

    n_cor = data.stiffness_offset.shape[0]
    lhs, rhs = inequalities(data.problem)
    lhs, rhs = lhs[n_cor:], rhs[n_cor:]  # drop the per-segment stiffness rows (the first n_cor)
    x = cp.Variable(data.problem.weights.size)
    k = cp.Variable(n_cor, nonneg=True)
    return x, k, [lhs @ x <= rhs, _lmi(data, x, k)]


def _solve_joint(data: CoupledData, problem: cp.Problem, x, k):
    """Solve a problem in (x, k); status, x >= 0 and k made exactly feasible, or None, None."""
    status = solve_with_fallback(problem, data.problem.tolerance)
    if status not in OK_STATUSES:
        return status, None, None
    x_opt = np.maximum(x.value, 0.0)
    return status, x_opt, _feasible_local(data, x_opt, k.value)


def least_global_within_budget_sdp(data: CoupledData, budget: float):
    """The least total global PCSA w.x with at most ``budget`` of local stiffness: sum(k) <= budget.

    (c)'s constraints with the local total bounded instead of priced: the epsilon-constraint
    form of the trade-off between the two totals (:func:`pareto_front`). ``budget = inf``
    leaves k free; ``budget = 0`` is (b), global muscles only (the LMI's diagonal then
    implies the per-segment stiffness rows).

    Parameters
    ----------
    data : CoupledData
    budget : float
        The largest sum(k) [N m/rad]; inf: unbounded.

    Returns
    -------
    status : str
        As for :func:`min_global_pcsa_sdp`.
    x : numpy.ndarray or None
        Global decision variables [cm^2], None unless optimal.
    k : numpy.ndarray or None
        Local stiffness per joint [N m/rad], None unless optimal.
    """
    import cvxpy as cp

    x, k, constraints = _joint_variables(data)
    if np.isfinite(budget):
        constraints = constraints + [cp.sum(k) <= budget]
    return _solve_joint(data, cp.Problem(cp.Minimize(data.problem.weights @ x), constraints), x, k)


@dataclass(frozen=True)
class CoupledOptimum:
    """Result of a coupled problem at one (E, Lambda), in SI units; NaN unless optimal.

    Attributes
    ----------
    eccentricity, lordosis : float
        E and Lambda [m].
    status : str
        The solver's status: 'optimal' (or 'optimal_inaccurate'), 'infeasible' (no activation
        within the bounds stabilises the chain) or 'solver_error'.
    pcsa : numpy.ndarray, shape (n_muscles,)
        Global PCSA of each muscle [m^2].
    local_stiffness : numpy.ndarray, shape (n_cor,)
        k_j of the local muscles at each joint [N m/rad].
    local_pcsa : numpy.ndarray, shape (n_cor,)
        The least local-muscle PCSA giving k_j [m^2] (:func:`spinectl.model.chain.local_pcsa`).
    counter_torque : numpy.ndarray, shape (n_cor,)
        CT_k at the global activation [N m], as in the per-segment model.
    margin : float
        Smallest eigenvalue of -(K - diag(k)) [N m/rad]; >= stability_margin up to the solver tolerance.
    """

    eccentricity: float
    lordosis: float
    status: str
    pcsa: np.ndarray
    local_stiffness: np.ndarray
    local_pcsa: np.ndarray
    counter_torque: np.ndarray
    margin: float

    @property
    def total_pcsa(self) -> float:
        """Total global PCSA [m^2]."""
        return float(np.sum(self.pcsa))

    @property
    def total_local_pcsa(self) -> float:
        """Total local PCSA over the joints [m^2]."""
        return float(np.sum(self.local_pcsa))

    @property
    def ok(self) -> bool:
        """True if the optimum was found."""
        return self.status in OK_STATUSES


def _result(model: Model, data: CoupledData, e: float, lam: float, status: str, x, k) -> CoupledOptimum:
    """A :class:`CoupledOptimum` from decision variables x [cm^2] and k [N m/rad] (None: NaN)."""
    n_cor = data.stiffness_offset.shape[0]
    x = np.full(data.problem.weights.size, np.nan) if x is None else x
    k = np.full(n_cor, np.nan) if k is None else k
    _, pcsa, counter_torque = to_si(data.problem, np.nan, x)
    margin = np.nan if np.isnan(x).any() or np.isnan(k).any() else float(chain.coupled_margin(data.matrix(x, k)))
    return CoupledOptimum(e, lam, status, pcsa, k, chain.local_pcsa(k, model), counter_torque, margin)


def least_local_stiffness(
    model: Model, eccentricity: float, lordosis: float, pcsa, *, given: bool = True
) -> CoupledOptimum:
    """(a) The least local stiffness that makes the chain stable at a global activation.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    pcsa : array_like
        Global PCSA [m^2], one value per pair (both sides) or per muscle, whatever
        ``optimisation.activation`` says.
    given : bool
        False for a PCSA that spinectl computed (:func:`spinectl.model.checks.expand_pcsa`).

    Returns
    -------
    CoupledOptimum
        ``pcsa`` is the given activation, ``local_stiffness`` the least k.

    Raises
    ------
    ParameterError
        ``pcsa`` has the wrong length or a negative or non-finite entry; E or Lambda is
        outside the modelled range.
    ModelError
        A fibre attachment lies on a CoR, or the arithmetic overflows.

    References
    ----------
    Bergmark A (1989). Stability of the lumbar spine. A study in mechanical engineering.
    Acta Orthop Scand Suppl 230:1-54. doi:10.3109/17453678909154177.
    """
    independent = model.replace(optimisation=dataclasses.replace(model.optimisation, activation="independent"))
    data = coupled_data(independent, eccentricity, lordosis)  # one variable per muscle: x = pcsa in cm^2
    x = expand_pcsa(model, pcsa, given=given) / M2_PER_CM2
    status, k = least_local_stiffness_sdp(data, x)
    return _result(model, data, float(eccentricity), float(lordosis), status, x, k)


def min_global_pcsa(model: Model, eccentricity: float, lordosis: float) -> CoupledOptimum:
    """(b) The least global PCSA that makes the chain stable without local muscles.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].

    Returns
    -------
    CoupledOptimum
        ``local_stiffness`` is zero; NaN and status 'infeasible' where no activation can.

    Raises
    ------
    ParameterError
        E or Lambda is outside the modelled range.
    ModelError
        A fibre attachment lies on a CoR, or the arithmetic overflows.

    References
    ----------
    Bergmark A (1989). Stability of the lumbar spine. A study in mechanical engineering.
    Acta Orthop Scand Suppl 230:1-54. doi:10.3109/17453678909154177.
    """
    data = coupled_data(model, eccentricity, lordosis)
    status, x = min_global_pcsa_sdp(data)
    k = None if x is None else np.zeros(data.stiffness_offset.shape[0])
    return _result(model, data, float(eccentricity), float(lordosis), status, x, k)


def joint_optimum(model: Model, eccentricity: float, lordosis: float) -> CoupledOptimum:
    """(c) The least total global PCSA plus ``local.cost_weight`` times the local PCSA.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].

    Returns
    -------
    CoupledOptimum

    Raises
    ------
    ParameterError
        E or Lambda is outside the modelled range.
    ModelError
        A fibre attachment lies on a CoR, or the arithmetic overflows.

    References
    ----------
    Bergmark A (1989). Stability of the lumbar spine. A study in mechanical engineering.
    Acta Orthop Scand Suppl 230:1-54. doi:10.3109/17453678909154177.
    """
    data = coupled_data(model, eccentricity, lordosis)
    status, x, k = joint_optimum_sdp(data)
    return _result(model, data, float(eccentricity), float(lordosis), status, x, k)


@dataclass(frozen=True)
class ParetoFront:
    """The trade-off between the global PCSA total and the local stiffness total at one (E, Lambda).

    Point i is the least global PCSA with at most ``budgets[i]`` of local stiffness
    (:func:`least_global_within_budget_sdp`); the budgets run from 0 (global muscles only,
    problem (b)) to the least local stiffness at the global minimum with k free (the other end).

    Attributes
    ----------
    eccentricity, lordosis : float
        E and Lambda [m].
    budgets : numpy.ndarray, shape (m,)
        Largest sum of k allowed [N m/rad], increasing.
    points : tuple of CoupledOptimum
        The optimum at each budget; NaN and the status where infeasible (e.g. at budget 0
        when no global activation alone stabilises the chain).
    """

    eccentricity: float
    lordosis: float
    budgets: np.ndarray
    points: tuple[CoupledOptimum, ...]

    @property
    def global_total(self) -> np.ndarray:
        """Global PCSA total of each point [m^2], shape (m,); non-increasing along the front."""
        return np.array([p.total_pcsa for p in self.points])

    @property
    def local_total(self) -> np.ndarray:
        """Local stiffness total sum(k) of each point [N m/rad], shape (m,)."""
        return np.array([float(np.sum(p.local_stiffness)) for p in self.points])

    @property
    def local_pcsa_total(self) -> np.ndarray:
        """Local-muscle PCSA total of each point [m^2], shape (m,) (:func:`spinectl.model.chain.local_pcsa`)."""
        return np.array([p.total_local_pcsa for p in self.points])

    def to_dict(self, model: Model) -> dict:
        """The front as a JSON-ready dict.

        Parameters
        ----------
        model : Model
            The model the front was computed with.

        Returns
        -------
        dict
            The model's :func:`~spinectl.model.source.provenance`, ``E_m``, ``Lambda_m`` and ``pareto``:
            ``local_budget_Nm_per_rad``, ``global_pcsa_total_cm2``, ``local_stiffness_total_Nm_per_rad``,
            ``local_pcsa_total_cm2``, ``status`` (m each), ``pcsa_cm2`` (m x n_muscles) and
            ``local_stiffness_Nm_per_rad`` (m x n_cor); NaN where a point is infeasible.
        """
        return provenance(model) | {
            "E_m": self.eccentricity,
            "Lambda_m": self.lordosis,
            "pareto": {
                "local_budget_Nm_per_rad": self.budgets.tolist(),
                "global_pcsa_total_cm2": m2_to_cm2(self.global_total).tolist(),
                "local_stiffness_total_Nm_per_rad": self.local_total.tolist(),
                "local_pcsa_total_cm2": m2_to_cm2(self.local_pcsa_total).tolist(),
                "status": [p.status for p in self.points],
                "pcsa_cm2": [m2_to_cm2(p.pcsa).tolist() for p in self.points],
                "local_stiffness_Nm_per_rad": [p.local_stiffness.tolist() for p in self.points],
            },
        }

    def table(self, model: Model) -> str:
        """The front as readable text, one row per point.

        Parameters
        ----------
        model : Model
            The model the front was computed with.

        Returns
        -------
        str
            No final newline.
        """
        lines = [
            header(model),
            f"Pareto front at E = {self.eccentricity * 100:.2f} cm, Lambda = {self.lordosis * 100:.2f} cm",
            f"{'budget [N m/rad]':>17}{'global [cm^2]':>15}{'local k [N m/rad]':>19}{'local [cm^2]':>14}  status",
        ]
        for budget, g, k, a, p in zip(
            self.budgets, m2_to_cm2(self.global_total), self.local_total, m2_to_cm2(self.local_pcsa_total), self.points,
            strict=True,
        ):  # fmt: skip
            lines.append(f"{budget:17.2f}{g:15.3f}{k:19.2f}{a:14.3f}  {p.status}")
        return "\n".join(lines)


def pareto_front(model: Model, eccentricity: float, lordosis: float, points: int = 11) -> ParetoFront:
    """The Pareto front between the global PCSA total and the local stiffness total (epsilon-constraint).

    The far end minimises the global PCSA with k free and takes the least local stiffness
    at that activation (problem (a)), sum k = k_max; the front is then the least global
    PCSA under sum(k) <= b for ``points`` budgets b evenly from 0 to k_max
    (:func:`least_global_within_budget_sdp`). Every problem is convex, so every Pareto
    point is reached, including those the weighted sum of :func:`joint_optimum` skips
    where the front is straight; the joint optimum at any ``local.cost_weight`` lies on it.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    points : int, optional
        Budgets on the front, >= 2.

    Returns
    -------
    ParetoFront

    Raises
    ------
    ParameterError
        E or Lambda is outside the modelled range, or ``points`` < 2.
    ModelError
        A fibre attachment lies on a CoR, or the arithmetic overflows.

    References
    ----------
    Miettinen K (1999). Nonlinear Multiobjective Optimization. Kluwer, Boston, ch. 3.2 (the
    epsilon-constraint method). doi:10.1007/978-1-4615-5563-6.
    """
    if int(points) < 2:
        raise ParameterError("points", f"must be an integer >= 2 (got {points!r})")
    e, lam = float(eccentricity), float(lordosis)
    data = coupled_data(model, e, lam)
    status, x, k = least_global_within_budget_sdp(data, np.inf)
    if x is not None:
        status, k = least_local_stiffness_sdp(data, x)
    if k is None:  # no activation within the bounds, whatever the local muscles: nothing to trade
        empty = _result(model, data, e, lam, status, None, None)
        return ParetoFront(e, lam, np.full(int(points), np.nan), (empty,) * int(points))
    budgets = np.linspace(0.0, float(np.sum(k)), int(points))
    far = _result(model, data, e, lam, status, x, k)
    inner = [_result(model, data, e, lam, *least_global_within_budget_sdp(data, b)) for b in budgets[:-1]]
    return ParetoFront(e, lam, budgets, tuple(inner) + (far,))


@dataclass(frozen=True)
class CoupledStability:
    """The coupled chain at one (E, Lambda) and one global activation: ``spinectl stability --coupled``.

    Attributes
    ----------
    eccentricity, lordosis : float
        E and Lambda [m].
    segment_names : tuple of str
        The joints, top to bottom.
    variable_names : tuple of str
        The decision variables: the pairs (paired activation) or the muscles (independent).
    pcsa : numpy.ndarray, shape (n_muscles,)
        Global PCSA of each muscle [m^2].
    stiffness : numpy.ndarray, shape (n_cor, n_cor)
        K: global muscles, gravity and passive stiffness [N m/rad].
    gravity_stiffness : numpy.ndarray, shape (n_cor, n_cor)
        K_g [N m/rad].
    stiffness_per_variable : numpy.ndarray, shape (n_var, n_cor, n_cor)
        dK/dx of each decision variable [N m/rad per cm^2].
    damping : numpy.ndarray, shape (n_cor, n_cor)
        D [N m s/rad].
    mass : numpy.ndarray, shape (n_cor, n_cor)
        M [kg m^2] (:func:`spinectl.model.chain.mass_matrix`).
    local : CoupledOptimum
        The least local stiffness that makes the chain statically stable at this activation
        (:func:`least_local_stiffness`, problem (a)).
    margin : float
        Smallest eigenvalue of -K, global muscles only [N m/rad]; > 0 statically stable.
    eigenvalues : numpy.ndarray, shape (2 n_cor,), complex
        Of the state matrix [[0, I], [M^-1 K, M^-1 D]], global muscles only [1/s].
    local_eigenvalues : numpy.ndarray, shape (2 n_cor,), complex
        The same with the least local stiffness added, K - diag(k) [1/s]; NaN if (a) failed.
    """

    eccentricity: float
    lordosis: float
    segment_names: tuple[str, ...]
    variable_names: tuple[str, ...]
    pcsa: np.ndarray
    stiffness: np.ndarray
    gravity_stiffness: np.ndarray
    stiffness_per_variable: np.ndarray
    damping: np.ndarray
    mass: np.ndarray
    local: CoupledOptimum
    margin: float
    eigenvalues: np.ndarray
    local_eigenvalues: np.ndarray

    @property
    def self_stable(self) -> bool:
        """True if the chain is dynamically stable with the global muscles alone (every eigenvalue Re < 0)."""
        return bool(self_stable(self.eigenvalues))

    @property
    def stable_with_local(self) -> bool:
        """True if the chain is dynamically stable with the least local stiffness added."""
        return bool(self_stable(self.local_eigenvalues))

    def to_dict(self, model: Model, pcsa_source: str = "min_pcsa") -> dict:
        """The result as a JSON-ready dict: the document of ``spinectl stability --coupled --json``.

        Parameters
        ----------
        model : Model
            The model the result was computed with (muscle names, K and its convention).
        pcsa_source : {'given', 'min_pcsa', 'activation'}
            Where the PCSA came from (as in :meth:`spinectl.model.stability.StabilityResult.to_dict`);
            'activation': the reflex's activation times the minimum stabilising PCSA (:meth:`table`).

        Returns
        -------
        dict
            The model's :func:`~spinectl.model.source.provenance` (``preset``, ``config``, ``config_sha256``,
            ``overridden``, ``K_Nm_per_rad``, ``K_convention``), ``E_m``, ``Lambda_m``, ``pcsa_source`` and
            ``coupled``: ``segments``, ``decision_variables``, ``pcsa_cm2`` (muscle -> cm^2),
            ``stiffness_matrix_Nm_per_rad``, ``gravity_stiffness_matrix_Nm_per_rad``,
            ``stiffness_matrix_per_cm2`` (n_var x n_cor x n_cor, N m/rad per cm^2),
            ``damping_matrix_Nms_per_rad``, ``mass_matrix_kgm2``, ``local_stiffness_Nm_per_rad``
            (the least, per joint), ``local_stiffness_total_Nm_per_rad``, ``local_pcsa_cm2``,
            ``local_status``, ``margin_Nm_per_rad`` (global muscles only), ``eigenvalues`` as
            [real, imaginary] pairs [1/s] and ``self_stable`` (global muscles only), and
            ``eigenvalues_with_local`` and ``stable_with_local`` (with the least local stiffness).
        """
        local = self.local
        return provenance(model) | {
            "E_m": self.eccentricity,
            "Lambda_m": self.lordosis,
            "pcsa_source": pcsa_source,
            "coupled": {
                "segments": list(self.segment_names),
                "decision_variables": list(self.variable_names),
                "pcsa_cm2": dict(zip(model.muscle_names, m2_to_cm2(self.pcsa).tolist(), strict=True)),
                "stiffness_matrix_Nm_per_rad": self.stiffness.tolist(),
                "gravity_stiffness_matrix_Nm_per_rad": self.gravity_stiffness.tolist(),
                "stiffness_matrix_per_cm2": self.stiffness_per_variable.tolist(),
                "damping_matrix_Nms_per_rad": self.damping.tolist(),
                "mass_matrix_kgm2": self.mass.tolist(),
                "local_stiffness_Nm_per_rad": local.local_stiffness.tolist(),
                "local_stiffness_total_Nm_per_rad": float(np.sum(local.local_stiffness)),
                "local_pcsa_cm2": m2_to_cm2(local.local_pcsa).tolist(),
                "local_status": local.status,
                "margin_Nm_per_rad": self.margin,
                "eigenvalues": [[float(z.real), float(z.imag)] for z in self.eigenvalues],
                "self_stable": self.self_stable,
                "eigenvalues_with_local": [[float(z.real), float(z.imag)] for z in self.local_eigenvalues],
                "stable_with_local": self.stable_with_local,
            },
        }

    def table(self, model: Model, pcsa_source: str = "min_pcsa", activation: float = 1.0) -> str:
        """The result as readable text: the matrices row by row, then the verdicts.

        Parameters
        ----------
        model : Model
            The model the result was computed with.
        pcsa_source : {'given', 'min_pcsa', 'activation'}
            Where the PCSA came from: given, the minimum stabilising PCSA per segment, or
            ``activation`` times it (the reflex's operating point, ``spinectl margins --coupled``).
        activation : float
            The fraction of the minimum stabilising PCSA [1] the PCSA line names with 'activation'.

        Returns
        -------
        str
            The text ``spinectl stability --coupled`` prints (no final newline).
        """
        pcsa = m2_to_cm2(self.pcsa)
        names = self.segment_names
        source = {
            "given": "",
            "min_pcsa": " (minimum stabilising per segment)",
            "activation": f" ({activation:g} x the minimum stabilising per segment, the reflex's activation)",
        }[pcsa_source]
        lines = [
            header(model),
            f"Coupled chain at E = {self.eccentricity * 100:.2f} cm, Lambda = {self.lordosis * 100:.2f} cm",
            f"PCSA [cm^2]{source}: "
            + ", ".join(f"{n} {p:.2f}" for n, p in zip(model.muscle_names, pcsa, strict=True))
            + f"  (total {pcsa.sum():.2f})",
        ]
        for title, matrix, fmt in (
            ("stiffness K [N m/rad] (global muscles, gravity, passive)", self.stiffness, "10.3f"),
            ("damping D [N m s/rad]", self.damping, "10.4f"),
            ("mass M [kg m^2]", self.mass, "10.4f"),
        ):
            lines += ["", title, " " * 8 + "".join(f"{n:>10}" for n in names)]
            lines += [f"{n:8}" + "".join(f"{v:{fmt}}" for v in row) for n, row in zip(names, matrix, strict=True)]
        local = self.local.local_stiffness
        lines += [
            "",
            f"static margin (smallest eigenvalue of -K) = {self.margin:.3f} N m/rad "
            f"({'stable' if self.margin > 0 else 'UNSTABLE'})",
            "eigenvalues [1/s]: " + ", ".join(f"{z.real:.3f}{z.imag:+.3f}j" for z in self.eigenvalues),
            "global muscles alone: "
            + (
                "eigenvalues undefined, the mass matrix is singular (levels.mass = 0)"
                if np.isnan(self.eigenvalues).any()
                else f"{'dynamically stable' if self.self_stable else 'NOT stable'} "
                f"({int(np.sum(self.eigenvalues.real >= 0))} of {self.eigenvalues.size} eigenvalues with Re >= 0)"
            ),
            "least local stiffness [N m/rad]: "
            + ", ".join(f"{n} {k:.2f}" for n, k in zip(names, local, strict=True))
            + f"  (total {np.sum(local):.2f}; local PCSA {m2_to_cm2(self.local.total_local_pcsa):.2f} cm^2; "
            f"{self.local.status}); with it: {'dynamically stable' if self.stable_with_local else 'NOT stable'}, "
            f"slowest eigenvalue {self.local_eigenvalues[0].real:.3f}{self.local_eigenvalues[0].imag:+.3f}j 1/s",
        ]
        return "\n".join(lines)


def coupled_stability_at(model: Model, eccentricity: float, lordosis: float, pcsa=None) -> CoupledStability:
    """The coupled chain at a global activation, by default the per-segment optimum.

    The matrices of :func:`spinectl.model.chain.chain_coefficients` and
    :func:`spinectl.model.chain.mass_matrix` at that activation, the static margin
    (:func:`spinectl.model.chain.coupled_margin`), the dynamic eigenvalues
    (:func:`spinectl.model.chain.dynamic_eigenvalues`) and the least local stiffness
    (:func:`least_local_stiffness`); docs/chain.md.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    pcsa : array_like, optional
        Global PCSA [m^2], per pair or per muscle; default the minimum stabilising PCSA of
        :func:`spinectl.optimise.reference.solve_point`
        (:func:`~spinectl.optimise.stabilising.minimum_stabilising_pcsa`).

    Returns
    -------
    CoupledStability

    Raises
    ------
    ModelError
        ``pcsa`` not given and no activation stabilises every segment; or the model cannot be
        evaluated there.
    ParameterError
        E, Lambda or ``pcsa`` out of range.

    References
    ----------
    Bergmark A (1989). Stability of the lumbar spine. A study in mechanical engineering.
    Acta Orthop Scand Suppl 230:1-54. doi:10.3109/17453678909154177.
    """
    e, lam = float(eccentricity), float(lordosis)
    given = pcsa is not None
    pcsa = expand_pcsa(model, pcsa) if given else minimum_stabilising_pcsa(model, e, lam)
    data = coupled_data(model, e, lam)
    coefficients = data.coefficients
    local = least_local_stiffness(model, e, lam, pcsa, given=given)  # the SDP, outside numpy's guard
    with arithmetic_guard(e, lam):
        stiffness = coefficients.stiffness(pcsa)
        damping = coefficients.damping(pcsa)
        mass = chain.mass_matrix(model, geometry.cor_positions(e, lam, model.geometry))
        eigenvalues = chain.dynamic_eigenvalues(mass, stiffness, damping)
        with_local = chain.dynamic_eigenvalues(mass, stiffness - np.diag(local.local_stiffness), damping)
    paired = model.optimisation.activation == "paired"
    return CoupledStability(
        eccentricity=e,
        lordosis=lam,
        segment_names=model.geometry.cor_names,
        variable_names=model.pair_names if paired else model.muscle_names,
        pcsa=pcsa,
        stiffness=stiffness,
        gravity_stiffness=coefficients.gravity_stiffness,
        stiffness_per_variable=np.moveaxis(data.stiffness, -1, 0),
        damping=damping,
        mass=mass,
        local=local,
        margin=float(chain.coupled_margin(stiffness)),
        eigenvalues=eigenvalues,
        local_eigenvalues=with_local,
    )
