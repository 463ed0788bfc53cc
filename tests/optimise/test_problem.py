"""The shared formulation: row equilibration keeps the feasible set (docs/robustness.md, absurd K); the margins."""

from __future__ import annotations

import numpy as np
import pytest

from spinectl import optimise
from spinectl.model import config
from spinectl.model.checks import checked_coefficients
from spinectl.model.stability import segment_stability
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


def test_a_relative_margin_scales_the_binding_constraint():
    """optimisation.relative_margin: S_k <= -max(mu, rho G_k). At A of wagner2012 L1L2 alone binds, so the
    minimum PCSA grows by (1 + rho) G_1 / (G_1 + mu) (the LP's one active row, closed form), the optimum's
    segments all keep S_k <= -rho G_k, and the slowest time constant falls from minutes to seconds."""
    preset = config.load_preset("wagner2012")
    strict = config.set_parameter(preset, "optimisation.relative_margin", 0.1)
    g = checked_coefficients(preset, 0.0, 0.0).gravity_stiffness
    mu = preset.optimisation.stability_margin
    loose, tight = optimise.solve_point(preset, 0.0, 0.0), optimise.solve_point(strict, 0.0, 0.0)
    assert tight.min_pcsa / loose.min_pcsa == pytest.approx(1.1 * g[0] / (g[0] + mu), rel=1e-6)
    result = segment_stability(strict, 0.0, 0.0, tight.pcsa)
    assert np.all(result.stiffness <= -0.1 * g * (1 - 1e-7))
    assert segment_stability(preset, 0.0, 0.0, loose.pcsa).slowest_time_constant > 60.0
    assert result.slowest_time_constant < 10.0
