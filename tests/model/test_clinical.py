"""The lordosis angle and the gravity line's distance against the spine line's own tangents and positions."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from spinectl.errors import ParameterError
from spinectl.model import clinical, geometry
from spinectl.model.params import Model

BCS = ("natural", "not-a-knot")


def _with_bc(model: Model, bc: str) -> Model:
    return dataclasses.replace(model, geometry=dataclasses.replace(model.geometry, spline_bc=bc))


def _numerical_angle(model: Model, lordosis: float, step: float = 1e-5) -> float:
    """The angle between the end tangents of spinectl's spine line, by one-sided np.gradient at P2 and P1 [deg]."""
    length = model.geometry.spine_length
    y = np.array([length, length - step, length - 2 * step, 2 * step, step, 0.0])
    ends = dataclasses.replace(model.geometry, cor_heights=tuple(y), cor_names=tuple("abcdef"))
    x = lordosis * geometry.lordosis_shape(ends)  # x(y) + E at the six heights
    top = np.gradient(x[:3], y[:3], edge_order=2)[0]
    bottom = np.gradient(x[3:], y[3:], edge_order=2)[-1]
    return np.degrees(np.arctan(bottom) - np.arctan(top))


@pytest.mark.parametrize("bc", BCS)
@pytest.mark.parametrize("lordosis", [-0.03, 0.01, 0.04, 0.08])
def test_angle_is_the_turn_of_the_spine_lines_tangents(model, bc, lordosis):
    """lordosis_angle equals the angle between the end tangents of geometry.lordosis_shape's line (np.gradient)."""
    m = _with_bc(model, bc)
    assert clinical.lordosis_angle(lordosis, m) == pytest.approx(_numerical_angle(m, lordosis), abs=1e-6)


@pytest.mark.parametrize("bc", ["natural", "clamped", "not-a-knot"])
def test_end_slopes_are_scipys_spline_derivative(bc):
    """END_SLOPES is phi'(0) of scipy's CubicSpline through (0, 0), (1/2, 1), (1, 0), rescaled to s."""
    spline = CubicSpline([0.0, 0.5, 1.0], [0.0, 1.0, 0.0], bc_type=bc)
    # s = 2 y on the lower half, so dphi/ds = (dphi/dy) / 2
    assert clinical.END_SLOPES[bc] == pytest.approx(spline(0.0, 1) / 2, abs=1e-12)


def test_the_papers_optimum_is_about_69_degrees(model):
    """Lambda = 4 cm, natural ends, L = 176 mm: 2 atan(3 * 0.04 / 0.176) = 2 * 34.287 = 68.57 deg (by hand)."""
    assert model.geometry.spline_bc == "natural" and model.geometry.spine_length == 0.176
    assert clinical.lordosis_angle(0.04, model) == pytest.approx(68.574, abs=1e-3)


@pytest.mark.parametrize("bc", BCS)
def test_angle_round_trips(model, bc, rng):
    """lordosis_from_angle inverts lordosis_angle, vectorised, to rounding."""
    m = _with_bc(model, bc)
    lam = rng.uniform(-0.1, 0.1, (3, 4))
    np.testing.assert_allclose(clinical.lordosis_from_angle(clinical.lordosis_angle(lam, m), m), lam, atol=1e-15)


def test_angle_errors(model):
    """No angle for clamped ends (vertical tangents) and none at or beyond 180 deg: one error naming the field."""
    with pytest.raises(ParameterError, match="spline_bc"):
        clinical.lordosis_from_angle(50.0, _with_bc(model, "clamped"))
    for bad in (180.0, -200.0, np.nan):
        with pytest.raises(ParameterError, match="lordosis_angle_deg"):
            clinical.lordosis_from_angle(bad, model)


def test_gravity_line_distance_is_the_cor_positions(model, rng):
    """E - Lambda phi_k is minus the x of each CoR from geometry.cor_positions (the gravity line is x = 0)."""
    e, lam = rng.uniform(-0.05, 0.08, 5), rng.uniform(-0.05, 0.08, 5)
    cor = geometry.cor_positions(e, lam, model.geometry)
    np.testing.assert_allclose(clinical.gravity_line_distance(e, lam, model), -cor[..., 0], atol=1e-15)
