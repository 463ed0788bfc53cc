"""The fast path: the optimisation of :mod:`spinectl.optimise` for a block of grid points at once.

Every stage of the per-point reference (minimum PCSA, least ||CT||, the
least-norm tie-break) is a tiny problem: 3 (paired) or 6 (independent)
variables and a few linear constraints. Here a block of points is stacked
block-diagonally into one sparse problem and handed to Clarabel through its
own Python API with scipy.sparse matrices, without cvxpy's canonicalisation.

Why the answers are the same: the stacked problem is separable, so its
optimum is the per-point optima side by side, and Clarabel's optimality test
on the whole block is at least as strict as on each point (the gaps add up).
Stage 2 is solved as the QP min ||CT||^2 rather than the SOCP min ||CT||:
squaring is monotone on norms, so the minimisers are the same, and thousands of
tiny second-order cones would cost more than one quadratic objective.
Stage 3 makes x unique, so the paths agree on x too, not only on CT.

Infeasible points are found by a phase-1 problem (least violation of the
stability constraints) only when a block is infeasible. Points that a stacked
problem leaves unsolved for any other reason go to the per-point reference,
so a bad block costs time, never an exception.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import clarabel
import numpy as np

from .problem import (
    DEFAULT_TOLERANCE,
    INFEASIBLE_STATUSES,
    OK_STATUSES,
    SLAB_FACTOR,
    SOLVER_ERROR,
    ProblemData,
    inequalities,
    objective,
    polished,
    solver_options,
    to_si,
)
from .reference import optimum

if TYPE_CHECKING:  # scipy.sparse is imported where a block is stacked: it takes longer to import than scipy
    import scipy.sparse as sp

CLARABEL_STATUS = {
    clarabel.SolverStatus.Solved: "optimal",
    clarabel.SolverStatus.AlmostSolved: "optimal_inaccurate",
    clarabel.SolverStatus.PrimalInfeasible: "infeasible",
    clarabel.SolverStatus.AlmostPrimalInfeasible: "infeasible_inaccurate",
}
"""Clarabel's statuses in cvxpy's words (those of the reference); anything else is 'solver_error'."""


@dataclass(frozen=True)
class BlockOptimum:
    """Results for a block of points, the arrays of :class:`~spinectl.optimise.problem.PointOptimum`.

    Attributes
    ----------
    status : numpy.ndarray of str, shape (P,)
    min_pcsa : numpy.ndarray, shape (P,)
        Minimum total PCSA [m^2]; NaN unless optimal.
    pcsa : numpy.ndarray, shape (P, n_muscles)
        Chosen activation [m^2].
    counter_torque : numpy.ndarray, shape (P, n_cor)
        CT at the chosen activation [N m].
    per_point : int
        Number of points that the per-point reference solved (a failed block falls back to it).
    """

    status: np.ndarray
    min_pcsa: np.ndarray
    pcsa: np.ndarray
    counter_torque: np.ndarray
    per_point: int = 0


def block_diagonal(blocks) -> sp.csc_matrix:
    """The block-diagonal sparse matrix of ``blocks``.

    Parameters
    ----------
    blocks : array_like, shape (P, r, c)
        One dense block per point.

    Returns
    -------
    scipy.sparse.csc_matrix, shape (P r, P c)
    """
    import scipy.sparse as sp

    blocks = np.asarray(blocks, float)
    n, r, c = blocks.shape
    rows = np.broadcast_to(np.arange(n)[:, None, None] * r + np.arange(r)[None, :, None], blocks.shape)
    cols = np.broadcast_to(np.arange(n)[:, None, None] * c + np.arange(c)[None, None, :], blocks.shape)
    return sp.csc_matrix((blocks.ravel(), (rows.ravel(), cols.ravel())), shape=(n * r, n * c))


def stacked_settings(tolerance: float | None) -> clarabel.DefaultSettings:
    """Clarabel's settings, quiet, with the gap and feasibility tolerance of the per-point reference.

    Parameters
    ----------
    tolerance : float or None
        [1]; None: Clarabel's defaults (:func:`~spinectl.optimise.problem.solver_options`).

    Returns
    -------
    clarabel.DefaultSettings
    """
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    for name, value in solver_options("CLARABEL", tolerance).items():
        setattr(settings, name, value)
    return settings


def stacked_qp(hessian, linear, lhs, rhs, tolerance: float | None) -> tuple[str, np.ndarray]:
    """Solve min 1/2 x'Hx + q'x s.t. G x <= h for P independent points in one Clarabel call.

    Parameters
    ----------
    hessian : array_like, shape (P, n, n), or None
        H per point (None: a linear objective).
    linear : array_like, shape (P, n)
        q per point.
    lhs, rhs : array_like, shapes (P, r, n) and (P, r)
        G and h per point.
    tolerance : float or None
        Solver tolerance [1].

    Returns
    -------
    status : str
        In cvxpy's words ('optimal', 'infeasible', ...), for the whole block.
    x : numpy.ndarray, shape (P, n)
    """
    import scipy.sparse as sp

    linear = np.asarray(linear, float)
    n_points, n = linear.shape
    if hessian is None:
        quad = sp.csc_matrix((n_points * n, n_points * n))
    else:
        quad = sp.triu(block_diagonal(hessian), format="csc")
    lhs_matrix = block_diagonal(lhs)
    cones = [clarabel.NonnegativeConeT(lhs_matrix.shape[0])]
    try:
        solver = clarabel.DefaultSolver(
            quad, linear.ravel(), lhs_matrix, np.ravel(rhs), cones, stacked_settings(tolerance)
        )
        solution = solver.solve()
    except (ValueError, RuntimeError, ArithmeticError):  # bad data or a solver panic: the block is unsolved
        return SOLVER_ERROR, np.full((n_points, n), np.nan)
    x = np.asarray(solution.x, float).reshape(n_points, n)
    status = CLARABEL_STATUS.get(solution.status, SOLVER_ERROR)
    return (status if np.all(np.isfinite(x)) else SOLVER_ERROR), x


def _stage(data: ProblemData, stage: str, total_max=np.inf, x_ct=None) -> tuple[str, np.ndarray, np.ndarray]:
    """One stage of :mod:`spinectl.optimise` for the whole block: stacked solve, then polish.

    Returns the block's status, x [cm^2] and the mask of points whose x is
    trustworthy: all of them if Clarabel solved the block, else those whose
    polished x is a verified KKT point.
    """
    lhs, rhs = inequalities(data, total_max, x_ct)
    status, x = stacked_qp(*objective(data, stage), lhs, rhs, data.tolerance)
    if status not in OK_STATUSES:
        return status, x, np.zeros(len(x), bool)
    x, verified = polished(data, stage, x, total_max, x_ct)
    return status, x, verified | (status == "optimal")


def feasible_points(data: ProblemData) -> np.ndarray | None:
    """Mask of the points where F is not empty, from one phase-1 LP for the block.

    min sum_p v_p  s.t.  S x_p - v_p <= b_p,  0 <= x_p (<= upper),  v_p >= 0:
    always feasible; a point is feasible iff its least violation v_p is zero,
    read as below :data:`SLAB_FACTOR` solver tolerances of its bound.
    None if the phase-1 problem itself fails.

    Parameters
    ----------
    data : ProblemData
        A block of points (leading dimension P).

    Returns
    -------
    numpy.ndarray of bool, shape (P,) or None
        True where some activation within the bounds makes every segment self-stable;
        None if the phase-1 problem failed.
    """
    n_points, n_rows, n = data.stability.shape
    lhs, rhs = inequalities(data)
    bound = rhs[:, :n_rows]  # the stability bounds as the solver sees them (equilibrated, problem.equilibrated)
    violation = np.zeros(lhs.shape[:2] + (1,))
    violation[:, :n_rows] = -1.0
    floor = np.zeros((n_points, 1, n + 1))
    floor[..., -1] = -1.0
    lhs = np.concatenate([np.concatenate([lhs, violation], axis=2), floor], axis=1)
    rhs = np.concatenate([rhs, np.zeros((n_points, 1))], axis=1)
    linear = np.zeros((n_points, n + 1))
    linear[:, -1] = 1.0
    status, v = stacked_qp(None, linear, lhs, rhs, data.tolerance)
    if status != "optimal":
        return None
    tol = DEFAULT_TOLERANCE if data.tolerance is None else data.tolerance
    return v[:, -1] <= SLAB_FACTOR * tol * (1.0 + np.abs(bound).max(axis=-1))


def _stages(
    data: ProblemData, ct_tolerance: float, first=None, min_pcsa_only: bool = False
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Stages 1-3 for a block of feasible points: minimum total, chosen x [cm^2], mask of good points.

    ``first``: the result of stage 1 for this block, if already solved.
    ``min_pcsa_only``: stop after stage 1 (x is then a minimum-PCSA activation).
    """
    failed = (*_unsolved(data), np.zeros(len(data.stability), bool))
    status, x, good = _stage(data, "min_pcsa") if first is None else first
    if not good.any():
        return failed
    if min_pcsa_only:
        return x @ data.weights, np.maximum(x, 0.0), good
    total = x @ data.weights
    limit = np.where(good, total, 0.0) * (1.0 + ct_tolerance)  # keeps bad points finite for the solver
    status, x_ct, good_ct = _stage(data, "counter_torque", limit)
    if not good_ct.any():
        return failed
    status, x, good_tie = _stage(data, "least_norm", limit, np.where(good_ct[:, None], x_ct, 0.0))
    return total, np.maximum(x, 0.0), good & good_ct & good_tie


def solve_stacked(data: ProblemData, ct_tolerance: float, *, min_pcsa_only: bool = False) -> BlockOptimum:
    """Stages 1-3 for a block of points (leading dimension P), stacked; the fast path.

    Only a block whose stage 1 is infeasible pays for :func:`feasible_points`.
    Points that a stacked problem leaves unsolved (a failed block, or an
    inaccurate one whose answer does not polish) go to the per-point
    reference, so the answer is always complete.

    Parameters
    ----------
    data : ProblemData
        A block of points (leading dimension P).
    ct_tolerance : float
        Relative band on the minimum total PCSA [1].
    min_pcsa_only : bool
        Solve stage 1 only (about a fifth of the time): ``min_pcsa`` is exact, but
        ``pcsa`` and ``counter_torque`` belong to a minimum-PCSA activation, not
        to the one of least ||CT|| (the calibration's K = 15 landscapes need
        only the minimum).

    Returns
    -------
    BlockOptimum
        Status, minimum total PCSA [m^2], per-muscle PCSA [m^2] and CT_k [N m] of every
        point (leading dimension P), and how many points the per-point reference solved.
    """
    n_points = len(data.stability)
    status = np.full(n_points, "optimal", dtype=object)
    total, x = _unsolved(data)
    feasible = np.arange(n_points)
    first = _stage(data, "min_pcsa")
    if first[0] in INFEASIBLE_STATUSES:
        first, mask = None, feasible_points(data)
        if mask is not None:
            feasible = np.flatnonzero(mask)
            status[~mask] = "infeasible"
    good = np.zeros(n_points, bool)
    if feasible.size:
        total[feasible], x[feasible], good[feasible] = _stages(data.point(feasible), ct_tolerance, first, min_pcsa_only)
    redo = np.flatnonzero(~good & (status != "infeasible"))
    if redo.size:
        status[redo], total[redo], x[redo] = _per_point(data.point(redo), ct_tolerance)
    return _block_optimum(data, status, total, x, per_point=redo.size)


def solve_points(data: ProblemData, ct_tolerance: float, progress=None) -> BlockOptimum:
    """Stages 1-3 for a block of points, one cvxpy reference solve per point.

    Parameters
    ----------
    data : ProblemData
        A block of points (leading dimension P).
    ct_tolerance : float
        Relative band on the minimum total PCSA [1].
    progress : callable, optional
        Called with 1 after every point (e.g. a tqdm bar's ``update``).

    Returns
    -------
    BlockOptimum
        As :func:`solve_stacked`, every point solved by the reference (``per_point = P``).
    """
    status, total, x = _per_point(data, ct_tolerance, progress)
    return _block_optimum(data, status, total, x, per_point=len(total))


def _per_point(data: ProblemData, ct_tolerance: float, progress=None):
    total, x = _unsolved(data)
    status = np.empty(len(total), dtype=object)
    for i in range(len(total)):
        status[i], total[i], x_i = optimum(data.point(i), ct_tolerance)
        if x_i is not None:
            x[i] = x_i
        if progress is not None:
            progress(1)
    return status, total, x


def _unsolved(data: ProblemData) -> tuple[np.ndarray, np.ndarray]:
    """NaN totals and x [cm^2] for a block: what a point holds until it is solved."""
    n_points = len(data.stability)
    return np.full(n_points, np.nan), np.full((n_points, data.weights.size), np.nan)


def _block_optimum(data: ProblemData, status, total, x, per_point: int) -> BlockOptimum:
    min_pcsa_m2, pcsa, counter_torque = to_si(data, total, x)
    return BlockOptimum(status.astype(str), min_pcsa_m2, pcsa, counter_torque, per_point)
