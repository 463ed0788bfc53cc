"""The chain's programmes (a) and (c) for many points at once: one Clarabel problem each (docs/chain.md).

The points of a chunk share no variable, so one Clarabel problem with a PSD cone per point solves
them all (:func:`least_local_stiffness_stacked`, :func:`least_cost_with_local_stacked`; the paper's
:func:`joint_optimum_stacked`, the landscape's variables); the per-point SDPs of
:mod:`spinectl.optimise.coupled.sdp` are the reference (benchmarks/bench_local_stiffness.py).
"""

from __future__ import annotations

import clarabel
import numpy as np

from ...model import chain
from ...units import M2_PER_CM2
from ..problem import OK_STATUSES, ProblemData, inequalities
from ..stacked import CLARABEL_STATUS, stacked_settings
from .sdp import shifted, svec


def least_local_stiffness_stacked(stiffness, margin: float, tolerance: float | None = None):
    """(a) at P points at once: one Clarabel problem with a 5 x 5 PSD cone per point.

    The points' problems share no variable, so the stacked problem is block diagonal: for each
    point p, min sum(k_p) s.t. diag(k_p) - K_p - mu I >= 0 (a PSD-triangle cone), k_p >= 0.
    The solution is made exactly feasible per point like
    :func:`~spinectl.optimise.coupled.sdp.least_local_stiffness_at`'s.
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
    rows, cols, scale = svec(n)
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
    k[finite] = shifted(a[finite], margin, np.asarray(solution.x).reshape(m, n))
    return status, k


def least_cost_with_local_stacked(
    stiffness_per_control, stiffness_offset, cost, margin: float, lhs, rhs, local_weight: float,
    local_per_unit: float, tolerance: float | None = None, lower=0.0,
):  # fmt: skip
    """(c) at P chains at once: one Clarabel problem, per chain a PSD cone, its linear rows and k >= 0.

    Per chain p, with z_p = (u_p, k_p): min c.u_p + w sum(k_p) / kappa subject to
    diag(k_p) - K_p(u_p) - mu I >= 0 (a PSD-triangle cone), G_p u_p <= h_p and k_p >= 0: the
    problem of :func:`~spinectl.optimise.coupled.sdp.least_cost_with_local_sdp` for each chain.
    The chains share no variable, so the problem is block diagonal; a stack that fails as a whole
    (an infeasible chain spoils it) returns its status and NaN, for the caller to solve per chain.

    Parameters
    ----------
    stiffness_per_control : array_like, shape (P, n, n, m)
        K_i of each chain (:attr:`LinearChain.stiffness_per_control`) [N m/rad per control unit].
    stiffness_offset : array_like, shape (P, n, n)
        K_0 of each chain [N m/rad].
    cost : array_like, shape (m,)
        c [1 per control unit].
    margin : float
        mu [N m/rad].
    lhs, rhs : array_like, shapes (P, r, m) and (P, r)
        The linear rows G u <= h of each chain (its bounds included).
    local_weight : float
        w [1].
    local_per_unit : float
        kappa [N m/rad per control unit].
    tolerance : float, optional
        Clarabel's gap and feasibility tolerance.
    lower : float or array_like, shape (m,)
        The controls' lower bounds, to which the solution is raised (the solver's rounding) [control unit].

    Returns
    -------
    status : str
        Clarabel's status in cvxpy's words.
    u : numpy.ndarray, shape (P, m)
        The controls [control unit]; NaN unless optimal.
    k : numpy.ndarray, shape (P, n)
        The added stiffness [N m/rad]; NaN unless optimal.

    References
    ----------
    Goulart PJ, Chen Y (2024). Clarabel: an interior-point solver for conic programs with
    quadratic objectives. arXiv:2405.12762. doi:10.48550/arXiv.2405.12762.
    """
    import scipy.sparse as sp

    per_var, offset = np.asarray(stiffness_per_control, float), np.asarray(stiffness_offset, float)
    points, n, v = per_var.shape[0], per_var.shape[1], per_var.shape[-1]
    rows, cols, scale = svec(n)
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
    cost = np.tile(np.concatenate([np.asarray(cost, float), np.full(n, local_weight / local_per_unit)]), points)
    cones = [clarabel.PSDTriangleConeT(n)] * points + [clarabel.NonnegativeConeT(b_linear.size)]
    x, k = np.full((points, v), np.nan), np.full((points, n), np.nan)
    try:
        solution = clarabel.DefaultSolver(
            sp.csc_matrix((cost.size, cost.size)), cost, lhs_matrix, np.concatenate([b_psd, b_linear]), cones,
            stacked_settings(tolerance),
        ).solve()  # fmt: skip
    except (ValueError, RuntimeError, ArithmeticError):
        return "solver_error", x, k
    status = CLARABEL_STATUS.get(solution.status, "solver_error")
    if status not in OK_STATUSES:
        return status, x, k
    z = np.asarray(solution.x).reshape(points, v + n)
    x = np.maximum(z[:, :v], lower)
    matrix = offset + np.einsum("pjkv,pv->pjk", per_var, x)
    return status, x, shifted(matrix, margin, z[:, v:])


def joint_optimum_stacked(
    data: ProblemData, coefficients: chain.ChainCoefficients, margin: float, local_per_cm2, cost_weight
):
    """(c) at P points at once: one Clarabel problem, per point a PSD cone, the LP rows and k >= 0.

    Per point p, with z_p = (x_p, k_p): min w.x_p + cost_weight sum(k_p) / kappa subject to
    diag(k_p) - K_p(x_p) - mu I >= 0 (a PSD-triangle cone), the per-segment rows of
    :func:`~spinectl.optimise.coupled.joint.joint_optimum_sdp` (damping rows, bounds on x) and
    k_p >= 0: :func:`least_cost_with_local_stacked` on the paper's chains. A chunk that fails as a
    whole (an infeasible point spoils the stack) returns its status and NaN, for the caller to
    solve per point.

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
    per_var = coefficients.stiffness_per_pcsa @ (data.to_muscles * M2_PER_CM2)  # (P, n, n, v)
    offset = coefficients.stiffness(np.zeros(data.to_muscles.shape[0]))  # (P, n, n)
    n = per_var.shape[1]
    lhs, rhs = inequalities(data)
    lhs, rhs = lhs[:, n:], rhs[:, n:]  # drop the per-segment stiffness rows, as joint_optimum_sdp does
    return least_cost_with_local_stacked(
        per_var, offset, data.weights, margin, lhs, rhs, cost_weight, local_per_cm2, data.tolerance
    )
