"""Torques, analytic derivatives and symmetry of the segment mechanics."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from spinectl.model import geometry, mechanics
from spinectl.model.params import Errata, Model

STEP = 1e-6


def _random_positions(rng, n=6):
    return rng.uniform(-0.08, 0.08, n), rng.uniform(-0.08, 0.08, n)


def test_stiffness_is_central_difference_of_nonlinear_torque(model, rng):
    """dM/dalpha per unit PCSA, every muscle and CoR, at random (E, Lambda)."""
    E, L = _random_positions(rng)
    coeffs = mechanics.segment_coefficients(model, E, L)
    cor = geometry.cor_positions(E, L, model.geometry)
    plus = mechanics.muscle_torque_per_pcsa(model, cor, STEP, 0.0)
    minus = mechanics.muscle_torque_per_pcsa(model, cor, -STEP, 0.0)
    fd = (plus - minus) / (2 * STEP)
    scale = np.abs(fd).max()
    np.testing.assert_allclose(coeffs.stiffness_per_pcsa, fd, atol=1e-6 * scale)


def test_damping_is_central_difference_of_nonlinear_torque(model, rng):
    E, L = _random_positions(rng)
    coeffs = mechanics.segment_coefficients(model, E, L)
    cor = geometry.cor_positions(E, L, model.geometry)
    fd = (
        mechanics.muscle_torque_per_pcsa(model, cor, 0.0, STEP)
        - mechanics.muscle_torque_per_pcsa(model, cor, 0.0, -STEP)
    ) / (2 * STEP)
    np.testing.assert_allclose(coeffs.damping_per_pcsa, fd, atol=1e-6 * np.abs(fd).max())
    assert np.all(coeffs.damping_per_pcsa <= 0)


def test_torque_coefficient_is_nonlinear_torque_at_rest(model, rng):
    E, L = _random_positions(rng)
    coeffs = mechanics.segment_coefficients(model, E, L)
    cor = geometry.cor_positions(E, L, model.geometry)
    np.testing.assert_allclose(
        coeffs.torque_per_pcsa, mechanics.muscle_torque_per_pcsa(model, cor, 0.0, 0.0), rtol=1e-12
    )


@pytest.mark.parametrize("sign", ["destabilising", "printed"])
def test_gravity_stiffness_is_central_difference(rng, sign):
    model = Model(errata=Errata(gravity_sign=sign))
    E, L = _random_positions(rng)
    coeffs = mechanics.segment_coefficients(model, E, L)
    cor = geometry.cor_positions(E, L, model.geometry)
    fd = (mechanics.gravity_torque(STEP, cor, model) - mechanics.gravity_torque(-STEP, cor, model)) / (2 * STEP)
    np.testing.assert_allclose(coeffs.gravity_stiffness, fd, rtol=1e-7)
    # Inverted pendulum (erratum): +m g r_y; printed sign: its negative.
    r_y = model.body.mass_height - cor[..., 1]
    expected = model.body.mass * model.body.gravity * r_y * (1 if sign == "destabilising" else -1)
    np.testing.assert_allclose(coeffs.gravity_stiffness, expected, rtol=1e-12)


def test_vertical_fibre_matches_closed_form(vertical_model):
    """A vertical fibre at x = d spanning a CoR at the origin, by hand.

    U = (d, a), P = (d, -b) relative to the CoR: h = -d, dh/dalpha = a b / (a + b),
    so dM/dalpha / f_iso = f_l a b/(a+b) - d^2 f_l'. (Crisco & Panjabi's
    buckling term: the tension acts like a compressive load.)
    """
    from spinectl.model import muscle

    m = vertical_model
    coeffs = mechanics.segment_coefficients(m, 0.0, 0.0)
    d, top, bottom = 0.12, 0.24, 0.0
    a = top - np.asarray(m.geometry.cor_heights)
    b = np.asarray(m.geometry.cor_heights) - bottom
    l0 = top - bottom
    l_opt = 1.2 * l0
    f_l = muscle.force_length(l0, l_opt, m.fibre)
    f_l_slope = muscle.force_length_slope(l0, l_opt, m.fibre)
    sigma = m.fibre.specific_tension
    ventral = sigma * (f_l * a * b / (a + b) - d**2 * f_l_slope)
    np.testing.assert_allclose(coeffs.stiffness_per_pcsa[:, 0], ventral, rtol=1e-12)
    np.testing.assert_allclose(coeffs.stiffness_per_pcsa[:, 1], ventral, rtol=1e-12)  # mirror
    np.testing.assert_allclose(coeffs.torque_per_pcsa[:, 0], -d * f_l * sigma, rtol=1e-12)  # flexion


def test_mirroring_the_geometry_mirrors_the_torques(model, rng):
    """E, Lambda -> -E, -Lambda mirrors x: torques change sign, sides swap, stiffness is kept."""
    E, L = _random_positions(rng)
    a = mechanics.segment_coefficients(model, E, L)
    b = mechanics.segment_coefficients(model, -E, -L)
    swap = np.arange(a.torque_per_pcsa.shape[-1]).reshape(-1, 2)[:, ::-1].ravel()
    np.testing.assert_allclose(b.torque_per_pcsa, -a.torque_per_pcsa[..., swap], atol=1e-9)
    np.testing.assert_allclose(b.stiffness_per_pcsa, a.stiffness_per_pcsa[..., swap], atol=1e-9)
    np.testing.assert_allclose(b.damping_per_pcsa, a.damping_per_pcsa[..., swap], atol=1e-9)
    np.testing.assert_allclose(b.gravity_torque, -a.gravity_torque, atol=1e-9)


def test_symmetric_position_has_zero_counter_torque_with_paired_activation(model, rng):
    """Position A (E = 0, Lambda = 0): mirror-symmetric, so CT = 0 (paper, Discussion: position A)."""
    coeffs = mechanics.segment_coefficients(model, 0.0, 0.0)
    pcsa = geometry.pairing_matrix(len(model.muscles)) @ rng.uniform(0, 20e-4, len(model.muscles))
    np.testing.assert_allclose(coeffs.counter_torque(pcsa), 0.0, atol=1e-9)


def test_counter_torque_balances_the_nonlinear_torques(model):
    """CT_k = -(sum M_i + M_ext) at rest: adding CT gives zero net torque (an equilibrium)."""
    E, L = 0.05, 0.02
    pcsa = np.array([5, 3, 8, 1, 2, 6]) * 1e-4
    coeffs = mechanics.segment_coefficients(model, E, L)
    cor = geometry.cor_positions(E, L, model.geometry)
    net = mechanics.muscle_torque_per_pcsa(model, cor, 0.0, 0.0) @ pcsa + mechanics.gravity_torque(0.0, cor, model)
    np.testing.assert_allclose(net + coeffs.counter_torque(pcsa), 0.0, atol=1e-9)


def test_coefficients_broadcast_over_a_grid(model):
    E, L = np.meshgrid(np.linspace(0, 0.08, 4), np.linspace(0, 0.08, 3), indexing="ij")
    grid = mechanics.segment_coefficients(model, E, L)
    assert grid.stiffness_per_pcsa.shape == (4, 3, 5, 6)
    one = mechanics.segment_coefficients(model, E[2, 1], L[2, 1])
    np.testing.assert_allclose(grid.stiffness_per_pcsa[2, 1], one.stiffness_per_pcsa, rtol=1e-12)


def test_lordosis_shape_natural_spline_closed_form(model):
    """phi = 1.5 s - 0.5 s^3, s = 1 - |y - L/2|/(L/2), for natural end conditions (worked by hand)."""
    h = model.geometry.spine_length / 2
    s = 1 - np.abs(np.asarray(model.geometry.cor_heights) - h) / h
    np.testing.assert_allclose(geometry.lordosis_shape(model.geometry), 1.5 * s - 0.5 * s**3, rtol=1e-12)


@pytest.mark.parametrize("bc", ["natural", "clamped", "not-a-knot"])
def test_lordosis_shape_is_scipys_cubic_spline(model, bc):
    """The closed forms equal scipy.interpolate.CubicSpline through (0, 0), (L/2, 1), (L, 0) (a second method)."""
    from scipy.interpolate import CubicSpline

    length = model.geometry.spine_length
    heights = tuple(np.linspace(length, 0.0, len(model.geometry.cor_heights)))  # both ends and between
    shape = geometry.lordosis_shape(dataclasses.replace(model.geometry, cor_heights=heights, spline_bc=bc))
    spline = CubicSpline([0.0, length / 2, length], [0.0, 1.0, 0.0], bc_type=bc)
    np.testing.assert_allclose(shape, spline(np.asarray(heights)), rtol=1e-12, atol=1e-15)


def test_cor_positions_follow_eccentricity_and_lordosis(model):
    cor = geometry.cor_positions(0.03, 0.0, model.geometry)
    np.testing.assert_allclose(cor[:, 0], -0.03)
    np.testing.assert_allclose(cor[:, 1], model.geometry.cor_heights)


def test_coefficients_equal_the_per_fibre_sums(model):
    """The monomial form of segment_coefficients equals the per-fibre formulas summed directly (torque h f_l,
    stiffness h' f_l - h^2 f_l', damping h^2 f_l f_H'(0); lever arms from fibre_length_and_lever_arm and
    lever_arm_slope) to rounding, at CoRs over and beyond the paper's range."""
    axis = np.linspace(-0.08, 0.08, 9)
    e, lam = np.meshgrid(axis, axis, indexing="ij")
    coeffs = mechanics.segment_coefficients(model, e, lam)
    expected = mechanics.per_fibre_sums(model, e, lam)
    for name, value in zip(("torque_per_pcsa", "stiffness_per_pcsa", "damping_per_pcsa"), expected, strict=True):
        got = getattr(coeffs, name)
        np.testing.assert_allclose(got, value, rtol=0, atol=1e-13 * np.abs(value).max(), err_msg=name)
