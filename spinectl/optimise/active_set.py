"""The fast path: every point's exact optimum from guessed active sets, verified, in batched numpy.

The three stages of :mod:`spinectl.optimise` (docs/optimisation.md) are tiny problems, 3 (paired)
or 6 (independent) variables and 13 to 20 constraints, whose active sets change rarely between
neighbouring grid points. Here every stage of a block of points is solved exactly:

1. minimum PCSA, the LP, by a batched dual simplex method (e.g. Nocedal and Wright [1]_,
   section 13.6) from the vertex x = 0, whose basis, the bounds x >= 0, is dual feasible
   because every weight is positive. Each pivot solves all points' n x n basis systems at
   once; a point whose most violated row has no admissible pivot is infeasible (a Farkas
   certificate), so infeasible points need no phase-1 problem;
2. least ||CT||, the QP, and 3. the least-norm tie-break, by guessing each point's active set
   (from the previous stage's, with one row exchanged, then by repair: add the most violated
   row, drop the most negative multiplier, then the sets that solved other points of the
   block), solving the equality-constrained KKT systems of all points with the same guess
   at once (``numpy.linalg.solve`` on stacked small matrices) and keeping a point's answer
   only if it is a KKT point: primal and dual feasible, complementary and stationary, each to
   the solver tolerance of its scale. For a convex problem that proves it optimal.

Points that no guess verifies go to the stacked Clarabel path (:func:`spinectl.optimise.stacked.solve_stacked`),
which falls back to the per-point reference in turn, so the answer is always complete. The
verified answers are exact (one linear solve each), like the polished answers of the other
paths, so the paths agree to rounding (tests/optimise/test_active_set.py; the benchmark
benchmarks/bench_sweep.py prints the largest differences).

References
----------
.. [1] Nocedal J, Wright SJ (2006). Numerical Optimization, 2nd ed. Springer.
   doi:10.1007/978-0-387-40065-5
"""

from __future__ import annotations

import itertools

import numpy as np

from ..model.params import Model
from . import stacked
from .problem import (
    DEFAULT_TOLERANCE,
    RANK_RTOL,
    PointOptimum,
    ProblemData,
    ct_slab,
    inequalities,
    objective,
    point_data,
    to_si,
)

PIVOTS = 60
"""Most dual simplex pivots per point; a point still running then (cycling at a degenerate vertex) falls back."""

STEPS = 12
"""Most steps of the primal active-set method for a point that the first guess did not solve."""

PATTERNS = 6
"""Most active sets of other points of the block tried on a point that no guess or repair solved."""

BATCH = 2048
"""Most (point, guess) pairs in one batched attempt: the guesses after the first are tried several at a time
(4, then twice as many each round) on the points still unsolved; each keeps its first guess, in order, that
verifies."""


def solve_block(data: ProblemData, ct_tolerance: float, *, min_pcsa_only: bool = False) -> stacked.BlockOptimum:
    """Stages 1-3 for a block of points (leading dimension P), exactly, in batched numpy; the fast path.

    Parameters
    ----------
    data : ProblemData
        A block of points (leading dimension P).
    ct_tolerance : float
        Relative band on the minimum total PCSA [1]; inf (the minimum-norm activation) is left
        to :func:`spinectl.optimise.stacked.solve_stacked`.
    min_pcsa_only : bool
        Solve stage 1 only: ``min_pcsa`` exact, ``pcsa`` and ``counter_torque`` those of a
        minimum-PCSA activation (as :func:`~spinectl.optimise.stacked.solve_stacked`).

    Returns
    -------
    BlockOptimum
        Status, minimum total PCSA [m^2], per-muscle PCSA [m^2] and CT_k [N m] of every point;
        ``per_point`` counts the points that the fallback's per-point reference solved.
    """
    n_points = len(data.stability)
    if not np.isfinite(ct_tolerance) or n_points == 0:
        return stacked.solve_stacked(data, ct_tolerance, min_pcsa_only=min_pcsa_only)
    tol = DEFAULT_TOLERANCE if data.tolerance is None else data.tolerance
    status = np.full(n_points, "optimal", dtype=object)
    total, x = np.full(n_points, np.nan), np.full((n_points, data.weights.size), np.nan)
    lhs, rhs = inequalities(data)
    code, x1, basis = min_pcsa_vertices(lhs, rhs, data.weights, data.stability.shape[-2], tol)
    status[code == INFEASIBLE] = "infeasible"
    solved = code == OPTIMAL
    total[solved] = x1[solved] @ data.weights
    if min_pcsa_only:
        x[solved] = x1[solved]
    else:
        good = np.flatnonzero(solved)
        stage1 = (lhs[good], rhs[good])
        x_good, ok = _least_counter_torque(data.point(good), x1[good], basis[good], ct_tolerance, tol, stage1)
        x[good[ok]] = x_good[ok]
        solved[good[~ok]] = False
    min_pcsa, pcsa, counter_torque = to_si(data, total, np.maximum(x, 0.0))
    redo = np.flatnonzero(~solved & (status != "infeasible"))
    per_point = 0
    if redo.size:  # unverified: the stacked Clarabel path, and the per-point reference behind it
        again = stacked.solve_stacked(data.point(redo), ct_tolerance, min_pcsa_only=min_pcsa_only)
        status[redo], min_pcsa[redo], pcsa[redo] = again.status, again.min_pcsa, again.pcsa
        counter_torque[redo], per_point = again.counter_torque, again.per_point
    return stacked.BlockOptimum(status.astype(str), min_pcsa, pcsa, counter_torque, per_point)


def solve_point(model: Model, eccentricity: float, lordosis: float) -> PointOptimum:
    """Minimum PCSA and least counter torque at one configuration, by :func:`solve_block` on a block of one point.

    The answer of :func:`spinectl.optimise.reference.solve_point` (the same problems, docs/optimisation.md,
    "Formulation"; equal to rounding, tests/optimise/test_active_set.py) without importing cvxpy unless the
    point fails verification and falls back: what ``spinectl stability`` needs to start at once. Stage 1
    by the dual simplex method of [1]_ (the module's docstring).

    Parameters
    ----------
    model : Model
        ``optimisation`` sets activation mode, margin, bounds and tolerances.
    eccentricity, lordosis : float
        E and Lambda [m].

    Returns
    -------
    PointOptimum
        As :func:`spinectl.optimise.reference.solve_point`: status, minimum total PCSA [m^2], chosen PCSA
        of each muscle [m^2], CT_k [N m] (shape (n_cor,)); NaN values unless optimal.

    Raises
    ------
    ParameterError, ModelError
        As :func:`spinectl.optimise.problem.point_data`.

    References
    ----------
    .. [1] Nocedal J, Wright SJ (2006). Numerical Optimization, 2nd ed. Springer.
       doi:10.1007/978-0-387-40065-5
    """
    data = point_data(model, eccentricity, lordosis).point(np.newaxis)  # a leading axis: a block of one point
    block = solve_block(data, model.optimisation.ct_tolerance)
    return PointOptimum(
        float(eccentricity),
        float(lordosis),
        str(block.status[0]),
        float(block.min_pcsa[0]),
        block.pcsa[0],
        block.counter_torque[0],
    )


OPTIMAL, INFEASIBLE, UNFINISHED = range(3)
"""Outcomes of :func:`min_pcsa_vertices` per point."""


def min_pcsa_vertices(lhs, rhs, weights, first_bound: int, tolerance: float):
    """The LP  min w.x  s.t.  G x <= h  for P points, by a batched dual simplex method from x = 0.

    The basis is a set of n rows of G taken as equalities; x = B^-1 h_B is its vertex and
    lambda = -B^-T w its multipliers, >= 0 throughout (dual feasible). Each pivot brings in the
    point's most violated row i (violation relative to its scale, as in the KKT check of
    :mod:`spinectl.optimise.polish`) and takes out the basic row j of least lambda_j / alpha_j
    over alpha = B^-T g_i > 0 (the dual ratio test), which keeps lambda >= 0; where no alpha_j > 0,
    the rows of the basis and row i prove the point infeasible (Farkas: y = (-alpha, 1) >= 0,
    y'G = 0, y'h < 0). A vertex that violates no row is optimal: feasible, dual feasible and
    complementary.

    Parameters
    ----------
    lhs, rhs : numpy.ndarray, shapes (P, r, n) and (P, r)
        G and h of :func:`~spinectl.optimise.problem.inequalities` [1 per cm^2, 1 or cm^2].
    weights : numpy.ndarray, shape (n,)
        w > 0 [1].
    first_bound : int
        Index of the first of the n rows -x <= 0: the starting basis.
    tolerance : float
        Relative feasibility tolerance [1].

    Returns
    -------
    code : numpy.ndarray of int, shape (P,)
        :data:`OPTIMAL`, :data:`INFEASIBLE` or :data:`UNFINISHED` (pivots ran out, or a basis was singular).
    x : numpy.ndarray, shape (P, n)
        The optimal vertex [cm^2] where optimal, else NaN.
    basis : numpy.ndarray of int, shape (P, n)
        The rows active at x.
    """
    n_points, n_rows, n = lhs.shape
    basis = np.tile(np.arange(first_bound, first_bound + n), (n_points, 1))
    code = np.full(n_points, UNFINISHED)
    x = np.full((n_points, n), np.nan)
    running = np.arange(n_points)
    cost = np.broadcast_to(-np.asarray(weights, float), (n_points, n))
    for _ in range(PIVOTS):
        if not running.size:
            break
        g, h, rows = lhs[running], rhs[running], basis[running]
        b = np.take_along_axis(g, rows[..., None], axis=1)
        try:
            vertex = _solve(b, np.take_along_axis(h, rows, axis=1))
            multipliers = _solve(np.swapaxes(b, 1, 2), cost[running])
        except np.linalg.LinAlgError:
            break  # a singular basis (not expected: pivots are > 0); every running point falls back
        violation = (_mv(g, vertex) - h) / (1.0 + np.abs(h) + _mv(np.abs(g), np.abs(vertex)))
        np.put_along_axis(violation, rows, -np.inf, axis=1)
        entering = np.argmax(violation, axis=1)
        feasible = violation[np.arange(running.size), entering] <= tolerance
        code[running[feasible]] = OPTIMAL
        x[running[feasible]] = vertex[feasible]
        pivot = ~feasible
        alpha = _solve(np.swapaxes(b[pivot], 1, 2), g[pivot, entering[pivot]])
        admissible = alpha > tolerance * np.abs(alpha).max(axis=1, keepdims=True)
        ratio = np.where(admissible, multipliers[pivot] / np.where(admissible, alpha, 1.0), np.inf)
        leaving = np.argmin(ratio, axis=1)
        infeasible = ~admissible.any(axis=1)
        code[running[pivot][infeasible]] = INFEASIBLE
        moving = np.flatnonzero(~infeasible)
        basis[running[pivot][moving], leaving[moving]] = entering[pivot][moving]
        running = running[pivot][~infeasible]
    return code, x, basis


def _least_counter_torque(data: ProblemData, x1, basis, ct_tolerance: float, tol: float, stage1):
    """Stages 2 and 3 for points whose stage 1 is solved: x [cm^2] and the mask of verified points.

    Stage 2's G and h are stage 1's (``stage1``, of these points) with the band w.x <= limit appended, as
    :func:`~spinectl.optimise.problem.inequalities` orders them (the limit is finite: x1 is a vertex).
    """
    n_points, n = x1.shape
    limit = (x1 @ data.weights) * (1.0 + ct_tolerance)
    lhs = np.concatenate([stage1[0], np.broadcast_to(data.weights, (n_points, 1, n))], axis=1)
    rhs = np.concatenate([stage1[1], limit[:, None]], axis=1)
    band = lhs.shape[1] - 1
    first = np.zeros(lhs.shape[:2], bool)
    np.put_along_axis(first, basis, True, axis=1)
    swaps = (_exchanged(first, basis[:, j], band) for j in range(n))
    with_band = first.copy()
    with_band[:, band] = True  # a tie between vertices: more tight rows than variables
    subsets = (subset for size in range(n, max(n - 3, 0), -1) for subset in _subsets(with_band, size))
    hessian, linear = objective(data, "counter_torque")
    guesses = itertools.chain([first], swaps, subsets)  # built only while some point is unsolved
    x_ct, ok_ct, active_ct = verified_qp(hessian, linear, lhs, rhs, None, None, guesses, x1, tol)
    x = np.full((n_points, n), np.nan)
    good = np.flatnonzero(ok_ct)
    rows, keep, centre, _ = ct_slab(data.torque[good], x_ct[good], data.tolerance, _scale(data, good))
    hessian, linear = objective(data.point(good), "least_norm")
    guess = active_ct[good]
    sizes = sorted({n - k for k in np.unique(keep.sum(axis=1))}, reverse=True)
    subsets = (subset for size in sizes for subset in _subsets(guess, size))
    problem = (hessian, linear, lhs[good], rhs[good], (rows, keep), centre)
    x3, ok3, _ = verified_qp(*problem, itertools.chain([guess], subsets), x_ct[good], tol)
    x[good] = x3
    verified = np.zeros(n_points, bool)
    verified[good] = ok3
    return x, verified


def _scale(data: ProblemData, index):
    return None if data.torque_scale is None else data.torque_scale[index]


def _exchanged(active, row, band: int):
    """``active`` with ``row`` (one per point) taken out and the band row put in."""
    guess = active.copy()
    guess[np.arange(len(guess)), row] = False
    guess[:, band] = True
    return guess


def _subsets(active, size: int):
    """Every choice of ``size`` of each point's active rows, as guesses (a point with fewer keeps its own).

    Where stage 2 ends at a vertex that its tight rows fix alone, the counter torques fix x
    again in stage 3: the KKT system needs only n - rank(T) of the tight rows, and which ones
    decides the signs of the multipliers (a dual degenerate vertex).
    """
    if size <= 0:  # the equalities fix x alone
        yield np.zeros_like(active)
        return
    count = active.sum(axis=1)
    first = np.argsort(~active, axis=1, kind="stable")  # each point's active rows first, in order
    for combo in itertools.combinations(range(int(count.max(initial=0))), size):
        guess = np.zeros_like(active)
        np.put_along_axis(guess, first[:, combo], True, axis=1)
        short = count <= max(combo)
        guess[short] = active[short]
        yield guess


def verified_qp(hessian, linear, lhs, rhs, equalities, eq_rhs, guesses, x_start, tolerance: float):
    """Solve  min 1/2 x'Hx + q'x  s.t.  G x <= h (and A x = c)  for P points from guessed active sets.

    The first guess is tried on every point; then, from the feasible ``x_start`` with the first
    guess as working set, up to :data:`STEPS` steps of the primal active-set method (Nocedal and
    Wright [1]_, Algorithm 16.3: step towards the working set's minimiser until a row blocks, and
    add it; at that minimiser drop the row of the most negative multiplier); then each other guess
    on the points still unsolved; then up to :data:`PATTERNS` of the active sets that solved other
    points, most common first. (The steps come before the other guesses because, with independent
    activation, they solve in a dozen batched attempts most of the points that the combinatorial
    guesses took about a hundred for; docs/optimisation.md, "Benchmark", gives the measured saving.)
    A point's answer is kept only if it passes :func:`kkt_check`.

    Parameters
    ----------
    hessian : numpy.ndarray, shape (P, n, n)
        H, positive semidefinite.
    linear : numpy.ndarray, shape (P, n)
        q.
    lhs, rhs : numpy.ndarray, shapes (P, r, n) and (P, r)
        G and h.
    equalities : tuple (rows, keep) or None
        A as rows of shape (P, e, n) and the mask (P, e) of the rows that count (the others,
        directions T does not act on, are dropped).
    eq_rhs : numpy.ndarray, shape (P, e), or None
        c.
    guesses : iterable of numpy.ndarray of bool, shape (P, r)
        Active sets to try, in order; the first must hold at ``x_start``. The others are taken a batch
        at a time (:data:`BATCH`), and no more once every point is solved (a generator builds only the
        guesses that are tried); a point keeps the first that verifies, as if tried one by one.
    x_start : numpy.ndarray, shape (P, n)
        A feasible point of each problem.
    tolerance : float
        Relative tolerance of the KKT check [1].

    Returns
    -------
    x : numpy.ndarray, shape (P, n)
        The verified optimum; NaN where none verified.
    verified : numpy.ndarray of bool, shape (P,)
    active : numpy.ndarray of bool, shape (P, r)
        The active set of each verified point.

    References
    ----------
    .. [1] Nocedal J, Wright SJ (2006). Numerical Optimization, 2nd ed. Springer.
       doi:10.1007/978-0-387-40065-5
    """
    n_points, n_rows, n = lhs.shape
    if equalities is None:
        eq_rows, keep, eq_rhs = np.zeros((n_points, 0, n)), np.zeros((n_points, 0), bool), np.zeros((n_points, 0))
    else:
        eq_rows, keep = equalities
    problem = (hessian, linear, lhs, rhs, eq_rows, keep, eq_rhs, tolerance)
    x, done = np.full((n_points, n), np.nan), np.zeros(n_points, bool)
    active = np.zeros((n_points, n_rows), bool)

    def attempt(guess, todo, equalities_first=True):
        trial = _attempt(problem, guess, todo, equalities_first)
        ok = trial.ok
        x[todo[ok]], active[todo[ok]], done[todo[ok]] = trial.x[ok], trial.used[ok], True
        return trial

    guesses = iter(guesses)
    start = next(guesses)
    todo = np.flatnonzero(~done)
    attempt(start[todo], todo)
    rest = np.flatnonzero(~done)
    if equalities is not None and rest.size:
        attempt(start[rest], rest, equalities_first=False)
    todo = np.flatnonzero(~done)
    working, point = start[todo], np.asarray(x_start, float)[todo]
    for _ in range(STEPS):  # before the other guesses: a few batched steps solve most points they leave
        if not todo.size:
            break
        trial = attempt(working, todo)
        working, point, going = _step(problem, trial, todo, point)
        todo, working, point = todo[going], working[going], point[going]
    size = 2
    while (todo := np.flatnonzero(~done)).size:  # the other guesses, several in one batched attempt
        size = min(2 * size, max(1, BATCH // todo.size))  # 4, 8, 16, ...: few wasted where one soon verifies
        batch = list(itertools.islice(guesses, size))  # none built once all are solved
        if not batch:
            break
        trial = _attempt(problem, np.concatenate([guess[todo] for guess in batch]), np.tile(todo, len(batch)))
        ok = trial.ok.reshape(len(batch), todo.size)
        found = np.flatnonzero(ok.any(axis=0))
        pick = np.argmax(ok[:, found], axis=0) * todo.size + found  # each point's first guess that verifies
        x[todo[found]], active[todo[found]], done[todo[found]] = trial.x[pick], trial.used[pick], True
    keys = active[done] @ (1 << np.arange(n_rows, dtype=np.int64))
    _, first, counts = np.unique(keys, return_index=True, return_counts=True)
    for pattern in active[done][first[np.argsort(-counts)][:PATTERNS]]:
        todo = np.flatnonzero(~done)
        if todo.size:
            attempt(np.broadcast_to(pattern, (todo.size, n_rows)), todo)
    return x, done, active


class _Trial:
    """The KKT solution of the points ``todo`` with their working sets: x, the rows used, the check."""

    def __init__(self, x, used, ok, solved, negative):
        self.x, self.used, self.ok, self.solved, self.negative = x, used, ok, solved, negative


def _step(problem, trial: _Trial, todo, point):
    """One step of the primal active-set method for the points of ``trial`` not verified.

    Returns the new working sets and points, and the mask of the points to go on with.
    """
    lhs, rhs, tolerance = problem[2][todo], problem[3][todo], problem[7]
    working = trial.used.copy()
    direction = np.where(trial.solved[:, None], trial.x - point, 0.0)
    size = np.linalg.norm(direction, axis=1)
    moving = trial.solved & (size > tolerance * (1.0 + np.linalg.norm(point, axis=1)))
    dropping = trial.solved & ~moving & ~trial.ok & (trial.negative < 0).any(axis=1)
    rows = np.flatnonzero(dropping)
    working[rows, np.argmin(trial.negative[rows], axis=1)] = False
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # over: a bound too far to reach, inf
        rate = _mv(lhs, direction)
        room = np.maximum(rhs - _mv(lhs, point), 0.0)
        blocking = ~working & (rate > RANK_RTOL * size[:, None])  # rows the step moves towards their bound
        ratio = np.where(blocking, room / rate, np.inf)
    first = np.argmin(ratio, axis=1)
    alpha = np.minimum(1.0, ratio[np.arange(len(todo)), first])
    point = point + np.where(moving, alpha, 0.0)[:, None] * direction
    blocked = np.flatnonzero(moving & (alpha < 1.0))
    working[blocked, first[blocked]] = True
    return working, point, ~trial.ok & (moving | dropping)


def _attempt(problem, guess, todo, equalities_first=True) -> _Trial:
    """The KKT solutions of the points ``todo`` with the active sets ``guess``, checked.

    Rows of the guess that depend on the equalities and on the rows before them are left out
    (:func:`independent_rows`): a vertex with more tight rows than variables gives no singular system.
    """
    hessian, linear, lhs, rhs, eq_rows, keep, eq_rhs = (a[todo] for a in problem[:7])
    tolerance = problem[7]
    n_rows = rhs.shape[1]
    order = np.r_[n_rows : n_rows + keep.shape[1], :n_rows]  # the equalities first: they always hold
    if not equalities_first:  # where the tight rows fix x alone, the equalities' multipliers may be 0
        order = np.r_[:n_rows, n_rows : n_rows + keep.shape[1]]
    rows, chosen = np.concatenate([lhs, eq_rows], axis=1), np.concatenate([guess, keep], axis=1)
    kept = np.empty_like(chosen)
    kept[:, order] = independent_rows(rows[:, order], chosen[:, order])
    guess, keep = kept[:, :n_rows], kept[:, n_rows:]
    x, multipliers, solved = _kkt_solve(hessian, linear, lhs, rhs, eq_rows, keep, eq_rhs, guess)
    equality = (eq_rows * keep[..., None], eq_rhs * keep)
    ok, _, negative = kkt_check(hessian, linear, lhs, rhs, equality, x, multipliers, guess, tolerance)
    return _Trial(x, guess, ok & solved, solved, negative)


def independent_rows(rows, chosen):
    """The chosen rows that are linearly independent of the chosen rows before them, in order (Gram-Schmidt).

    Parameters
    ----------
    rows : numpy.ndarray, shape (P, R, n)
    chosen : numpy.ndarray of bool, shape (P, R)

    Returns
    -------
    numpy.ndarray of bool, shape (P, R)
        A subset of ``chosen``: a row counts as dependent when the part of it outside the span of
        those kept before it is below :data:`~spinectl.optimise.problem.RANK_RTOL` of its norm.
    """
    n_points, n_rows, n = rows.shape
    basis = np.zeros((n_points, n, n))
    count = np.zeros(n_points, int)
    kept = np.zeros_like(chosen)
    for j in np.flatnonzero(chosen.any(axis=0)):  # most rows are active nowhere
        at = np.flatnonzero(chosen[:, j] & (count < n))  # and the others at few points: only there
        row, span = rows[at, j], basis[at]
        residual = row
        for _ in range(2):  # twice is enough (Giraud et al. 2005, doi:10.1007/s00211-005-0615-4)
            residual = residual - np.einsum("pkn,pk->pn", span, np.einsum("pkn,pn->pk", span, residual))
        size = np.linalg.norm(residual, axis=1)
        new = size > RANK_RTOL * np.linalg.norm(row, axis=1)
        index = at[new]
        basis[index, count[index]] = residual[new] / size[new, None]
        count[index] += 1
        kept[index, j] = True
    return kept


def _kkt_solve(hessian, linear, lhs, rhs, eq_rows, keep, eq_rhs, active):
    """x and the multipliers (P, r + e) of the KKT systems with the rows ``active`` (and the kept equalities) as
    equalities; points with the same rows share one batched solve. Singular systems give NaN (not solved)."""
    n_points, n_rows, n = lhs.shape
    rows = np.concatenate([lhs, eq_rows], axis=1)
    bound = np.concatenate([rhs, eq_rhs], axis=1)
    chosen = np.concatenate([active, keep], axis=1)
    x = np.full((n_points, n), np.nan)
    multipliers = np.zeros((n_points, rows.shape[1]))
    keys = chosen @ (1 << np.arange(chosen.shape[1], dtype=np.int64))  # one integer per set of rows
    _, first, group = np.unique(keys, return_index=True, return_inverse=True)
    for k, pattern in enumerate(chosen[first]):
        members = np.flatnonzero(group.ravel() == k)
        picked = np.flatnonzero(pattern)
        a = rows[members][:, picked]
        m = len(picked)
        kkt = np.zeros((members.size, n + m, n + m))
        kkt[:, :n, :n] = hessian[members]
        kkt[:, :n, n:] = np.swapaxes(a, 1, 2)
        kkt[:, n:, :n] = a
        right = np.concatenate([-linear[members], bound[members][:, picked]], axis=1)
        solution = _solve_each(kkt, right)
        x[members] = solution[:, :n]
        multipliers[members[:, None], picked] = solution[:, n:]
    return x, multipliers, np.all(np.isfinite(x), axis=1)


def _solve_each(matrices, right):
    """Batched solve; where a batch holds a singular matrix, halves until the singular ones stand alone (NaN)."""
    try:
        return _solve(matrices, right)
    except np.linalg.LinAlgError:
        if len(matrices) == 1:
            return np.full(right.shape, np.nan)
        half = len(matrices) // 2
        return np.concatenate([_solve_each(matrices[:half], right[:half]), _solve_each(matrices[half:], right[half:])])


def kkt_check(hessian, linear, lhs, rhs, equalities, x, multipliers, active, tolerance: float):
    """Whether x with ``multipliers`` is a KKT point, each condition to ``tolerance`` of its scale (vectorised).

    The conditions and scales of :mod:`spinectl.optimise.polish`'s check: every row feasible,
    the active rows tight, the multipliers of inequalities >= 0 (inactive ones are 0 by
    construction: complementarity), and Hx + q + G'lambda + A'mu = 0.

    Parameters
    ----------
    hessian : numpy.ndarray, shape (P, n, n)
    linear : numpy.ndarray, shape (P, n)
    lhs, rhs : numpy.ndarray, shapes (P, r, n) and (P, r)
        G and h.
    equalities : tuple of numpy.ndarray, shapes (P, e, n) and (P, e)
        A and c (rows that do not count are zero).
    x : numpy.ndarray, shape (P, n)
    multipliers : numpy.ndarray, shape (P, r + e)
        lambda, then mu.
    active : numpy.ndarray of bool, shape (P, r)
    tolerance : float
        [1].

    Returns
    -------
    ok : numpy.ndarray of bool, shape (P,)
    violation : numpy.ndarray, shape (P, r)
        Each row's excess over its bound, relative to its scale (> tolerance: violated).
    negative : numpy.ndarray, shape (P, r)
        The inequality multipliers below -tolerance of their scale (else 0).
    """
    n_rows = rhs.shape[1]
    eq_rows, eq_rhs = equalities
    with np.errstate(invalid="ignore"):
        scale = 1.0 + np.abs(rhs) + _mv(np.abs(lhs), np.abs(x))
        excess = (_mv(lhs, x) - rhs) / scale
        primal = np.all(excess <= tolerance, axis=1) & np.all(~active | (np.abs(excess) <= tolerance), axis=1)
        eq_scale = 1.0 + np.abs(eq_rhs) + _mv(np.abs(eq_rows), np.abs(x))
        primal &= np.all(np.abs(_mv(eq_rows, x) - eq_rhs) <= tolerance * eq_scale, axis=1)
        gradient = _mv(hessian, x) + linear
        rows = np.concatenate([lhs, eq_rows], axis=1)
        reaction = np.einsum("pri,pr->pi", rows, multipliers)
        grad_scale = 1.0 + np.abs(gradient) + np.einsum("pri,pr->pi", np.abs(rows), np.abs(multipliers))
        stationary = np.all(np.abs(gradient + reaction) <= tolerance * grad_scale, axis=1)
        sign_scale = 1.0 + np.max(np.abs(multipliers), axis=1, keepdims=True)
        lam = multipliers[:, :n_rows]
        negative = np.where(lam < -tolerance * sign_scale, lam / sign_scale, 0.0)
    ok = primal & stationary & ~(negative < 0).any(axis=1)
    return ok, np.nan_to_num(excess, nan=np.inf), negative


def _solve(matrices, right):
    return np.linalg.solve(matrices, right[..., None])[..., 0]


def _mv(a, v):
    return np.einsum("...ij,...j->...i", a, v)
