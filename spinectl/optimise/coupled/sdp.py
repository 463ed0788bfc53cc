"""The chain's semidefinite programmes on any linearised chain (docs/chain.md, "Coupled stability").

Written on :class:`~spinectl.model.linear_chain.LinearChain`, K(u) = K_0 + sum_i u_i K_i, so that
any model that produces one (the paper's, :func:`spinectl.model.chain.linear_chain`; an anatomical
model) has the same programmes. The chain is statically stable with the margin mu when

    diag(k) - K(u) >= mu I   (a linear matrix inequality, LMI),

k >= 0 a stiffness added freely at each joint [N m/rad] (the paper's local muscles; none: k = 0):

- :func:`least_local_stiffness_at`, :func:`least_local_stiffness_of`: at fixed controls, the least sum(k);
- :func:`least_control_sdp`: k = 0, the least cost c.u;
- :func:`least_cost_with_local_sdp`: the least c.u + w sum(k) / kappa, or the least c.u with
  sum(k) bounded (the epsilon-constraint form);
- :func:`least_quadratic_cost_sdp`: k = 0, the least sum_i w_i u_i^2 with equality rows A u = b
  (equilibrium) and the LMI, its diagonal only (the joint-by-joint criterion) or no criterion
  (static optimisation of an anatomical model, docs/anatomy.md).

Each is solved with cvxpy and Clarabel (PSD cone; SCS as the fallback,
:func:`spinectl.optimise.reference.solve_with_fallback`). The linear rows the controls obey are the
chain's bounds unless the caller gives its own (the paper's per-segment rows, which include them).
The solver's k is made exactly feasible by a uniform shift, k + max(0, mu - margin): adding c to
every k_j adds c I to the matrix.

References
----------
Bergmark A (1989). Stability of the lumbar spine. A study in mechanical engineering.
Acta Orthop Scand Suppl 230:1-54. doi:10.3109/17453678909154177.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ...errors import ParameterError
from ...model.chain import coupled_margin
from ...model.linear_chain import LinearChain
from ..problem import OK_STATUSES
from ..reference import solve_with_fallback

if TYPE_CHECKING:  # imported where a problem is built: cvxpy takes over a second, and a sweep needs neither
    import cvxpy as cp


def lmi(chain: LinearChain, u, margin: float, k=None) -> cp.Constraint:
    """diag(k) - K(u) - mu I >> 0 as a cvxpy constraint.

    Parameters
    ----------
    chain : LinearChain
    u : cvxpy.Expression or array_like, shape (m,)
        The controls: a cvxpy variable, or fixed values [control unit].
    margin : float
        mu [N m/rad].
    k : cvxpy.Expression, shape (n,), optional
        Stiffness added at each joint [N m/rad]; None: none.

    Returns
    -------
    cvxpy.Constraint
    """
    import cvxpy as cp

    matrix = -_stiffness_expression(chain, u) - margin * np.eye(chain.n_joints)
    matrix = 0.5 * (matrix + matrix.T)  # K_i of a model's finite differences are symmetric to rounding only
    return (matrix if k is None else matrix + cp.diag(k)) >> 0


def _stiffness_expression(chain: LinearChain, u):
    """K(u) as one affine cvxpy expression (one product with the (n n, m) matrix, whatever m), or K(u)."""
    import cvxpy as cp

    if not isinstance(u, cp.Expression):
        return chain.stiffness(u)
    n, m = chain.n_joints, chain.n_controls
    flat = chain.stiffness_per_control.reshape(n * n, m)
    return chain.stiffness_offset + cp.reshape(flat @ u, (n, n), order="C")


def shifted(stiffness, margin: float, k) -> np.ndarray:
    """k >= 0 shifted so that diag(k) - K >= mu I holds to rounding (adding c to every k_j adds c I).

    Parameters
    ----------
    stiffness : array_like, shape (..., n, n)
        K [N m/rad].
    margin : float
        mu [N m/rad].
    k : array_like, shape (..., n)
        The solver's k [N m/rad].

    Returns
    -------
    numpy.ndarray, shape (..., n)
        [N m/rad].
    """
    k = np.maximum(np.asarray(k, float), 0.0)
    shortfall = margin - coupled_margin(np.asarray(stiffness, float) - k[..., :, None] * np.eye(k.shape[-1]))
    return k + np.maximum(shortfall, 0.0)[..., None]


def least_local_stiffness_at(stiffness, margin: float, tolerance: float | None = None):
    """(a) The least total local stiffness sum(k) with diag(k) - K >= mu I, k >= 0, for one matrix K.

    Always feasible (large k); the dual is max <Z, K + mu I> over Z >= 0, diag(Z) <= 1. The
    per-point reference (cvxpy, Clarabel with SCS as the fallback) of
    :func:`~spinectl.optimise.coupled.stacked_sdp.least_local_stiffness_stacked`.

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
    return status, shifted(stiffness, margin, k.value)


def least_local_stiffness_of(chain: LinearChain, u, margin: float, tolerance: float | None = None):
    """(a) :func:`least_local_stiffness_at` with K(u) of ``chain``.

    Parameters
    ----------
    chain : LinearChain
    u : array_like, shape (m,)
        The controls [control unit].
    margin : float
        mu [N m/rad].
    tolerance : float, optional
        The solver's gap and feasibility tolerance.

    Returns
    -------
    status : str
        'optimal', 'optimal_inaccurate' or 'solver_error'.
    k : numpy.ndarray or None
        The least stiffness per joint [N m/rad], None unless optimal.
    """
    return least_local_stiffness_at(chain.stiffness(np.asarray(u, float)), margin, tolerance)


def least_control_sdp(chain: LinearChain, cost, margin: float, rows=None, tolerance: float | None = None):
    """(b) The least cost c.u with -K(u) >= mu I and the linear rows G u <= h (no added stiffness).

    Parameters
    ----------
    chain : LinearChain
    cost : array_like, shape (m,)
        c, the price of each control [1 per control unit].
    margin : float
        mu [N m/rad].
    rows : tuple of numpy.ndarray, optional
        (G, h) that the controls obey; default the chain's bounds (:meth:`LinearChain.bound_rows`).
        Rows given replace the bounds: they must include them.
    tolerance : float, optional
        The solver's gap and feasibility tolerance.

    Returns
    -------
    status : str
        'optimal', 'optimal_inaccurate', 'infeasible', 'infeasible_inaccurate' or 'solver_error'.
    u : numpy.ndarray or None
        The controls [control unit], raised to the lower bounds (the solver's rounding); None unless optimal.
    """
    import cvxpy as cp

    lhs, rhs = chain.bound_rows() if rows is None else rows
    u = cp.Variable(chain.n_controls)
    problem = cp.Problem(cp.Minimize(cost @ u), [lhs @ u <= rhs, lmi(chain, u, margin)])
    status = solve_with_fallback(problem, tolerance)
    if status not in OK_STATUSES:
        return status, None
    return status, np.maximum(u.value, chain.lower)


def least_cost_with_local_sdp(
    chain: LinearChain,
    cost,
    margin: float,
    rows=None,
    tolerance: float | None = None,
    *,
    local_weight: float | None = None,
    local_per_unit: float = 1.0,
    local_budget: float = np.inf,
):
    """(c) The least c.u + w sum(k) / kappa with diag(k) - K(u) >= mu I, k >= 0 and G u <= h.

    With ``local_weight`` None the objective is c.u alone; ``local_budget`` bounds sum(k)
    (the epsilon-constraint form of the trade-off between the two).

    Parameters
    ----------
    chain : LinearChain
    cost : array_like, shape (m,)
        c [1 per control unit].
    margin : float
        mu [N m/rad].
    rows : tuple of numpy.ndarray, optional
        (G, h); default the chain's bounds (as in :func:`least_control_sdp`).
    tolerance : float, optional
        The solver's gap and feasibility tolerance.
    local_weight : float, optional
        w, the price of a control unit of added stiffness in units of c [1]; None: k is free.
    local_per_unit : float
        kappa, the joint stiffness per control unit of what adds it [N m/rad per control unit].
    local_budget : float
        The largest sum(k) [N m/rad]; inf: unbounded.

    Returns
    -------
    status : str
        As for :func:`least_control_sdp`.
    u : numpy.ndarray or None
        The controls [control unit], None unless optimal.
    k : numpy.ndarray or None
        The added stiffness per joint [N m/rad], exactly feasible; None unless optimal.
    """
    import cvxpy as cp

    lhs, rhs = chain.bound_rows() if rows is None else rows
    u = cp.Variable(chain.n_controls)
    k = cp.Variable(chain.n_joints, nonneg=True)
    constraints = [lhs @ u <= rhs, lmi(chain, u, margin, k)]
    if np.isfinite(local_budget):
        constraints = constraints + [cp.sum(k) <= local_budget]
    objective = cost @ u if local_weight is None else cost @ u + local_weight * cp.sum(k) / local_per_unit
    status = solve_with_fallback(cp.Problem(cp.Minimize(objective), constraints), tolerance)
    if status not in OK_STATUSES:
        return status, None, None
    u_opt = np.maximum(u.value, chain.lower)
    return status, u_opt, shifted(chain.stiffness(u_opt), margin, k.value)


QUADRATIC_CRITERIA = ("chain", "joints", "none")
"""The stability criteria of :func:`least_quadratic_cost_sdp`: the chain's LMI, each joint's diagonal entry, none."""


def least_quadratic_cost_sdp(
    chain: LinearChain,
    weights,
    margin: float,
    criterion: str = "chain",
    equalities=None,
    rows=None,
    tolerance: float | None = None,
):
    """(d) The least sum_i w_i u_i^2 with A u = b, G u <= h and a stability criterion (no added stiffness).

    The criterion: ``"chain"``, -K(u) >= mu I; ``"joints"``, -K_jj(u) >= mu at each joint (the
    paper's joint-by-joint criterion, linear rows); ``"none"``, nothing (classic static
    optimisation, Anderson and Pandy 2001). Convex: a quadratic cost, linear rows, one LMI.

    Parameters
    ----------
    chain : LinearChain
    weights : array_like, shape (m,)
        w_i >= 0, the price of each control squared [1 per control unit^2].
    margin : float
        mu [N m/rad].
    criterion : str
        One of :data:`QUADRATIC_CRITERIA`.
    equalities : tuple of numpy.ndarray, optional
        (A, b), shapes (r, m) and (r,): rows the controls meet exactly (e.g. equilibrium,
        the net torque A u - b = 0 [N m]); None: none.
    rows : tuple of numpy.ndarray, optional
        (G, h); default the chain's bounds (as in :func:`least_control_sdp`).
    tolerance : float, optional
        The solver's gap and feasibility tolerance.

    Returns
    -------
    status : str
        As for :func:`least_control_sdp`.
    u : numpy.ndarray or None
        The controls [control unit], clipped to the bounds (the solver's rounding); None unless optimal.

    References
    ----------
    Anderson FC, Pandy MG (2001). Static and dynamic optimization solutions for gait are
    practically equivalent. J Biomech 34(2):153-161. doi:10.1016/S0021-9290(00)00155-X.
    """
    import cvxpy as cp

    if criterion not in QUADRATIC_CRITERIA:
        raise ParameterError("criterion", f"must be one of {QUADRATIC_CRITERIA} (got {criterion!r})")
    lhs, rhs = chain.bound_rows() if rows is None else rows
    u = cp.Variable(chain.n_controls)
    constraints = [lhs @ u <= rhs]
    if equalities is not None:
        constraints.append(equalities[0] @ u == equalities[1])
    if criterion == "chain":
        constraints.append(lmi(chain, u, margin))
    elif criterion == "joints":
        constraints.append(-cp.diag(_stiffness_expression(chain, u)) >= margin)
    objective = cp.Minimize(cp.sum(cp.multiply(np.asarray(weights, float), cp.square(u))))
    status = solve_with_fallback(cp.Problem(objective, constraints), tolerance)
    if status not in OK_STATUSES:
        return status, None
    return status, np.clip(u.value, chain.lower, chain.upper)


def svec(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Clarabel's PSD-triangle order: the upper triangle column by column, off-diagonals scaled by sqrt 2.

    Parameters
    ----------
    n : int
        The matrix's size.

    Returns
    -------
    rows, cols : numpy.ndarray, shape (n (n + 1) / 2,)
        The entries in order.
    scale : numpy.ndarray, shape (n (n + 1) / 2,)
        1 on the diagonal, sqrt 2 off it.
    """
    rows, cols = np.triu_indices(n)
    order = np.lexsort((rows, cols))  # column-major
    rows, cols = rows[order], cols[order]
    return rows, cols, np.where(rows == cols, 1.0, np.sqrt(2.0))
