"""Force-length and Hill force-velocity (paper, Methods).

docs/model.md, "The muscle fibre" and "Eccentric Hill constant C".
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from spinectl.model import muscle
from spinectl.model.params import Errata, Fibre

FIBRE = Fibre()
L_OPT = 0.3


def test_force_length_at_equilibrium_matches_hand_value():
    # l = l0 = l_opt / 1.2: u = ((1/1.2)^0.96 - 1)/0.35; f_l = exp(-u^2), by hand 0.8102.
    u = ((1 / 1.2) ** 0.96 - 1) / 0.35
    expected = math.exp(-(u**2))
    assert expected == pytest.approx(0.8102, abs=1e-4)
    assert muscle.force_length(L_OPT / 1.2, L_OPT, FIBRE) == pytest.approx(expected, rel=1e-12)


def test_force_length_slope_is_finite_difference_and_positive_on_ascending_limb():
    lengths = np.linspace(0.6, 0.99, 7) * L_OPT
    step = 1e-7
    fd = (muscle.force_length(lengths + step, L_OPT, FIBRE) - muscle.force_length(lengths - step, L_OPT, FIBRE)) / (
        2 * step
    )
    analytic = muscle.force_length_slope(lengths, L_OPT, FIBRE)
    np.testing.assert_allclose(analytic, fd, rtol=1e-6)
    assert np.all(analytic > 0)


def _hill(errata="corrected"):
    return muscle.hill_constants(L_OPT, FIBRE, Errata(eccentric_constant=errata))


def test_isometric_force_is_one():
    # f_H(0) = c/b - a = (1 + a) - a = 1 (per unit f_iso).
    assert muscle.force_velocity(0.0, _hill()) == pytest.approx(1.0, rel=1e-14)


def test_corrected_hill_curve_is_continuous_in_value_and_slope():
    hill = _hill()
    eps = 1e-9
    left, right = muscle.force_velocity([-eps, eps], hill)
    assert left == pytest.approx(right, abs=1e-8)
    slopes = muscle.force_velocity_slope([-eps, 0.0, eps], hill)
    # Slope of the concentric branch at 0: -c/b^2 = -(1 + a)/b.
    expected = -(1 + FIBRE.hill_a) / hill.b
    np.testing.assert_allclose(slopes, expected, rtol=1e-6)


def test_printed_eccentric_constant_breaks_continuity():
    # Printed C = (A - f_iso) b gives f_H(0-) = A - C/B = 1.5 - 0.5 b / (0.4 b) = 0.25, not 1.
    hill = _hill("printed")
    assert muscle.force_velocity(-1e-12, hill) == pytest.approx(0.25, rel=1e-6)
    assert muscle.force_velocity(0.0, hill) == pytest.approx(1.0)


def test_hill_slope_matches_finite_difference_on_both_branches():
    hill = _hill()
    v = np.array([-2.0, -0.5, -0.05, 0.05, 0.5, 2.0])
    step = 1e-7
    fd = (muscle.force_velocity(v + step, hill) - muscle.force_velocity(v - step, hill)) / (2 * step)
    np.testing.assert_allclose(muscle.force_velocity_slope(v, hill), fd, rtol=1e-6)


def test_hill_limits():
    hill = _hill()
    # Concentric force vanishes at v_max: c/(v_max + b) - a = 0 for c = b(1 + a), b = v_max/4, a = 1/4.
    vmax = muscle.max_velocity(L_OPT, FIBRE)
    assert vmax == pytest.approx(11 * L_OPT)  # (6 + 10 * 0.5) l_opt
    assert muscle.force_velocity(vmax, hill) == pytest.approx(0.0, abs=1e-12)
    # Eccentric force tends to A = f_ecc = 1.5.
    assert muscle.force_velocity(-1e6, hill) == pytest.approx(1.5, rel=1e-5)
