"""Exact optima of small convex QPs from an interior-point answer: active-set polishing.

An interior-point solver stops at a tolerance. Where the optimum lies on a
face of the feasible polytope and the objective is flat along part of it
(least ||CT|| with rank-deficient T, see :mod:`spinectl.optimise`), its x is
then only good to about the square root of that tolerance: 1e-5, not 1e-9.
Polishing guesses the active constraints from the answer's slacks, solves the
KKT system of the equality-constrained problem exactly, and keeps the result
only if it is a verified KKT point (feasible, complementary, stationary with
multipliers >= 0), which for a convex problem proves it optimal. Otherwise the
solver's answer stands. The same idea as OSQP's solution polishing [1]_,
vectorised over any number of independent problems; the per-point reference
and the fast path both use it, so both report the exact optimum.

References
----------
.. [1] Stellato B, Banjac G, Goulart P, Bemporad A, Boyd S (2020). OSQP: an operator
   splitting solver for quadratic programs. Math Program Comput 12:637-672.
   doi:10.1007/s12532-020-00179-2
"""

from __future__ import annotations

import numpy as np

ACTIVE_RTOL = (1e-5, 1e-7, 1e-9)
"""Guesses of the active set: the constraints whose slack is below this fraction of their scale.

Tried in turn; the first guess that gives a verified KKT point wins. Where the
solver's x is poor (a flat objective) a loose threshold catches every active
constraint; where constraints are nearly but not quite active a tight one
leaves them out. A wrong guess cannot do harm: it fails the KKT check.
"""


REPAIRS = 2
"""After a guess, up to this many retries with the constraints the KKT point violated added to the active set."""


def _t(a):
    return np.swapaxes(a, -1, -2)


def _mv(a, v):
    return np.einsum("...ij,...j->...i", a, v)


def polish(hessian, linear, lhs, rhs, x0, tolerance: float, rank_rtol: float, eq_lhs=None, eq_rhs=None):
    """Polish approximate solutions of  min 1/2 x'Hx + q'x  s.t.  G x <= h (and A x = c).

    Parameters
    ----------
    hessian : array_like, shape (..., n, n), or None
        H, positive semidefinite (None: a linear objective).
    linear : array_like, shape (..., n)
        q.
    lhs, rhs : array_like, shapes (..., r, n) and (..., r)
        G and h.
    x0 : array_like, shape (..., n)
        Approximate optimum, e.g. from Clarabel.
    tolerance : float
        Relative tolerance of the KKT check [1].
    rank_rtol : float
        Singular values of the KKT matrix below this fraction of its largest
        entry are dropped (rank-deficient H, redundant active rows) [1].
    eq_lhs, eq_rhs : array_like, shapes (..., e, n) and (..., e), optional
        Equality constraints A x = c, always active; zero rows (0 = 0) are allowed.

    Returns
    -------
    x : numpy.ndarray, shape (..., n)
        The verified KKT point where polishing succeeded, else ``x0``.
    polished : numpy.ndarray of bool, shape (...)
    """
    x0 = np.asarray(x0, float)
    lead, n = x0.shape[:-1], x0.shape[-1]
    hess = np.zeros((n, n)) if hessian is None else hessian

    def flat(a, k):  # broadcast to the leading dimensions, then flatten them
        a = np.asarray(a, float)
        return np.broadcast_to(a, lead + a.shape[a.ndim - k :]).reshape((-1,) + a.shape[a.ndim - k :])

    hess, q, lhs, rhs, x0 = flat(hess, 2), flat(linear, 1), flat(lhs, 2), flat(rhs, 1), flat(x0, 1)
    n_eq = 0 if eq_lhs is None else np.shape(eq_rhs)[-1]
    scale = 1.0 + np.abs(rhs) + _mv(np.abs(lhs), np.abs(x0))
    slack = (rhs - _mv(lhs, x0)) / scale
    if eq_lhs is not None:  # equalities are rows that are always active, multipliers of either sign
        lhs = np.concatenate([lhs, flat(eq_lhs, 2)], axis=-2)
        rhs = np.concatenate([rhs, flat(eq_rhs, 1)], axis=-1)
    cutoff = rank_rtol * np.maximum(np.abs(lhs).max(axis=(-2, -1)), np.abs(hess).max(axis=(-2, -1)))
    x, done = x0.copy(), np.zeros(len(x0), bool)
    for threshold in ACTIVE_RTOL:
        todo = np.flatnonzero(~done)
        active = np.concatenate([slack[todo] <= threshold, np.ones((todo.size, n_eq), bool)], axis=-1)
        for _ in range(REPAIRS + 1):
            args = (hess[todo], q[todo], lhs[todo], rhs[todo])
            candidate, multipliers = _kkt_step(*args, x0[todo], active, cutoff[todo])
            ok, violated = _is_kkt_point(*args, candidate, multipliers, active, tolerance, n_eq)
            x[todo[ok]] = candidate[ok]
            done[todo[ok]] = True
            todo, active = todo[~ok], (active | violated)[~ok]
    return x.reshape(lead + (n,)), done.reshape(lead)


def _kkt_step(hess, q, lhs, rhs, x0, active, cutoff):
    """x and multipliers of the KKT system with the rows ``active`` as equalities.

    The correction to ``x0`` of least norm (pseudo-inverse, singular values
    below ``cutoff`` dropped), so that directions the problem does not fix stay at x0.
    """
    n, r = x0.shape[-1], rhs.shape[-1]
    g_active = lhs * active[..., None]
    kkt = np.zeros(x0.shape[:-1] + (n + r, n + r))
    kkt[..., :n, :n] = hess
    kkt[..., :n, n:] = _t(g_active)
    kkt[..., n:, :n] = g_active
    residual = np.concatenate([-(_mv(hess, x0) + q), (rhs - _mv(lhs, x0)) * active], axis=-1)
    u, sing, vt = np.linalg.svd(kkt)
    kept = sing > cutoff[..., None]
    inverse = np.where(kept, 1.0 / np.where(kept, sing, 1.0), 0.0)  # not 1/subnormal: it overflows
    step = _mv(_t(vt), inverse * _mv(_t(u), residual))
    return x0 + step[..., :n], step[..., n:] * active


def _is_kkt_point(hess, q, lhs, rhs, x, multipliers, active, tolerance, n_eq):
    """Feasible and complementary, then stationary with multipliers >= 0, each to ``tolerance`` of its scale.

    Returns the verdict per problem and the mask of the rows the point violates.

    The last ``n_eq`` rows are equalities: no sign on their multipliers. At a
    degenerate vertex (more active rows than variables) the multipliers are
    not unique and those of least norm may have the wrong sign, so a failure
    of the sign check is settled by a non-negative least-squares fit.
    """
    scale = 1.0 + np.abs(rhs) + _mv(np.abs(lhs), np.abs(x))
    excess = (_mv(lhs, x) - rhs) / scale
    violated = excess > tolerance
    primal = ~np.any(violated, axis=-1) & np.all(~active | (np.abs(excess) <= tolerance), axis=-1)
    gradient = _mv(hess, x) + q
    grad_scale = 1.0 + np.abs(gradient) + _mv(np.abs(_t(lhs)), np.abs(multipliers))
    stationary = np.all(np.abs(gradient + _mv(_t(lhs), multipliers)) <= tolerance * grad_scale, axis=-1)
    sign_scale = 1.0 + np.max(np.abs(multipliers), axis=-1, keepdims=True)
    signs = np.all(multipliers[..., : rhs.shape[-1] - n_eq] >= -tolerance * sign_scale, axis=-1)
    ok = primal & stationary & signs
    for i in np.flatnonzero(primal & ~ok):
        ok[i] = _nonnegative_multipliers(lhs[i], gradient[i], active[i], n_eq, tolerance * grad_scale[i])
    return ok, violated


def _nonnegative_multipliers(lhs, gradient, active, n_eq, tolerance) -> bool:
    """True if  gradient + G_A' lambda = 0  has a solution with lambda >= 0 on the inequalities."""
    n_ineq = lhs.shape[0] - n_eq
    inequality = lhs[:n_ineq][active[:n_ineq]].T
    equality = lhs[n_ineq:].T
    columns = np.concatenate([inequality, equality, -equality], axis=1)
    if not (np.all(np.isfinite(columns)) and np.all(np.isfinite(gradient))):
        return False  # nnls raises on inf/NaN; such a point is no verified optimum
    if columns.shape[1] == 0:
        # No active row: stationary iff the gradient vanishes. SciPy's nnls aborts the
        # interpreter (double free) on a matrix without columns (scipy 1.17; cf. scipy#24866).
        return bool(np.all(np.abs(gradient) <= tolerance))
    from scipy.optimize import nnls  # here: scipy.optimize takes longer to import than numpy and scipy

    multipliers, _ = nnls(columns, -gradient)
    return bool(np.all(np.abs(columns @ multipliers + gradient) <= tolerance))
