"""The shared formulation: row equilibration keeps the feasible set (docs/robustness.md, absurd K)."""

from __future__ import annotations

import numpy as np

from spinectl.optimise.problem import equilibrated


def test_equilibrated_rows_define_the_same_set(rng):
    """G x <= h and its scaled form agree at random points; the largest entry of each scaled row is 1.

    The rows mimic the stiffness rows with an absurd K: coefficients of order 1, bounds of order 1e12.
    """
    rows = rng.normal(0, 1, (50, 6, 3))
    bound = rng.normal(0, 1, (50, 6)) * np.array([1e12, 1, 1, 1e-3, 0, 1])
    x = rng.normal(0, 1, (50, 3)) * 10.0 ** rng.integers(-3, 13, (50, 1))
    scaled_rows, scaled_bound = equilibrated(rows, bound)
    before = np.einsum("prn,pn->pr", rows, x) <= bound
    after = np.einsum("prn,pn->pr", scaled_rows, x) <= scaled_bound
    np.testing.assert_array_equal(before, after)
    np.testing.assert_allclose(np.maximum(np.abs(scaled_rows).max(-1), np.abs(scaled_bound)), 1.0)
    zero_rows, zero_bound = equilibrated(np.zeros((1, 2)), np.zeros(1))  # a zero row stays a zero row
    assert np.all(zero_rows == 0) and np.all(zero_bound == 0)
