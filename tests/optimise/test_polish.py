"""Active-set polishing: exact optima from approximate ones, and no harm from wrong guesses."""

from __future__ import annotations

import numpy as np

from spinectl.optimise.polish import polish

TOL, RTOL = 1e-9, 1.5e-8


def _box(n):
    """G x <= h for lower <= x <= upper, as rows [-I; I]."""
    eye = np.eye(n)
    return np.concatenate([-eye, eye])


def test_projection_onto_a_box_is_exact(rng):
    """min ||x - a||^2 over a box is clip(a) in closed form; polish a noisy copy of it."""
    n_problems, n = 50, 4
    a = rng.normal(0, 2, (n_problems, n))
    lower, upper = -np.ones(n), np.ones(n)
    exact = np.clip(a, lower, upper)
    x0 = exact + rng.normal(0, 1e-6, exact.shape)
    lhs = _box(n)
    rhs = np.concatenate([-lower, upper])
    x, ok = polish(2 * np.eye(n), -2 * a, lhs, rhs, x0, TOL, RTOL)
    assert ok.all()
    np.testing.assert_allclose(x, exact, atol=1e-12)


def test_lp_vertex_with_redundant_active_rows():
    """min x1 + x2 s.t. x >= 0 and x1 + x2 >= 0: a degenerate vertex at 0 (three active rows in 2-D)."""
    lhs = np.array([[-1.0, 0.0], [0.0, -1.0], [-1.0, -1.0]])
    x, ok = polish(None, np.ones(2), lhs, np.zeros(3), np.array([3e-8, 1e-8]), TOL, RTOL)
    assert ok
    np.testing.assert_allclose(x, 0.0, atol=1e-15)


def test_equalities_are_imposed():
    """min ||x||^2 s.t. x1 + x2 = 2, x >= 0 is (1, 1) by symmetry."""
    x, ok = polish(2 * np.eye(2), np.zeros(2), -np.eye(2), np.zeros(2), [1.1, 0.9], TOL, RTOL, [[1.0, 1.0]], [2.0])
    assert ok
    np.testing.assert_allclose(x, [1.0, 1.0], atol=1e-14)


def test_a_wrong_active_set_is_rejected():
    """min (x + 0.5)^2 on [-1, 1] from x0 = 1: the upper bound looks active but its multiplier
    would be -3 < 0, so no guess verifies and x0 comes back unchanged."""
    x, ok = polish([[2.0]], [1.0], _box(1), np.ones(2), [1.0], TOL, RTOL)
    assert not ok and x == 1.0


def test_an_interior_start_reaches_the_constrained_optimum():
    """From an interior x0 the unconstrained step violates x1 <= 1; the repair makes it active."""
    x, ok = polish(2 * np.eye(2), [-6.0, 0.0], _box(2), np.ones(4), [0.5, -0.2], TOL, RTOL)
    assert ok
    np.testing.assert_allclose(x, [1.0, 0.0], atol=1e-14)


def test_no_active_rows_does_not_reach_nnls():
    """With no active inequality and no equality the multiplier fit has no columns; SciPy's
    nnls aborts the interpreter on such a matrix (found by the CLI fuzz test), so the
    check answers directly: stationary iff the gradient is zero (to tolerance)."""
    from spinectl.optimise.polish import _nonnegative_multipliers

    lhs = np.eye(3)
    inactive = np.zeros(3, bool)
    assert _nonnegative_multipliers(lhs, np.zeros(3), inactive, 0, 1e-9)
    assert not _nonnegative_multipliers(lhs, np.array([1.0, 0.0, 0.0]), inactive, 0, 1e-9)
    assert not _nonnegative_multipliers(lhs, np.array([np.nan, 0.0, 0.0]), np.ones(3, bool), 0, 1e-9)
