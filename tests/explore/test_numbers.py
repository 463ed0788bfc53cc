"""The explorer's numbers: equal to the library's answers at the same point, and checked by a second method."""

from __future__ import annotations

import numpy as np
import pytest

from spinectl.explore import numbers as nb
from spinectl.explore.state import ExploreState
from spinectl.model.config import load_preset, set_parameters
from spinectl.model.stability import segment_stability
from spinectl.optimise.reference import solve_point
from spinectl.reflex.margins import analyse


@pytest.fixture
def state():
    return ExploreState(0.035, 0.02, mass=30.0, stiffness=15.0, delay=0.08, activation=0.6, activation_lag=0.04)


def _library_model(base, state):
    """The state's model built here from the parameters' dotted names (docs/parameters.md), not from SLIDERS."""
    return set_parameters(
        base,
        {
            "body.mass": state.mass,
            "passive.stiffness": state.stiffness,
            "reflex.delay": state.delay,
            "reflex.activation": state.activation,
            "reflex.activation_time_constant": state.activation_lag,
        },
    )


def test_point_numbers_equal_the_library_at_the_same_point(state):
    """Margins as `spinectl margins` computes them (reflex.margins.analyse); eigenvalues and CT as
    `spinectl stability` at PCSA = activation x the optimum (docs/reflex.md)."""
    base = load_preset("wagner2012")
    got = nb.point_numbers(base, state)
    model = _library_model(base, state)
    report = analyse(model, state.eccentricity, state.lordosis)
    np.testing.assert_array_equal(got.delay_margin, [s.delay_margin for s in report.segments])
    assert list(got.stable_at_delay) == [s.stable_at_delay for s in report.segments]
    pcsa = state.activation * solve_point(model, state.eccentricity, state.lordosis).pcsa
    at = segment_stability(model, state.eccentricity, state.lordosis, pcsa)
    np.testing.assert_allclose(got.pcsa, pcsa, rtol=1e-12, atol=0)
    np.testing.assert_allclose(got.eigenvalues, at.eigenvalues, rtol=1e-12, atol=0)
    np.testing.assert_allclose(got.counter_torque, at.counter_torque, rtol=1e-12, atol=1e-12)
    assert [r["counter_torque_Nm"] for r in got.rows()] == [nb.shown(x) for x in at.counter_torque]


def test_eigenvalues_are_the_roots_of_theta_s2_minus_d_s_minus_s(state):
    """Second method: numpy.roots of theta s^2 - D s - S (paper eq. 1) from each segment's S, D, theta."""
    got = nb.point_numbers(load_preset("default"), state)
    for segment, eigs in zip(got.report.segments, got.eigenvalues, strict=True):
        roots = np.roots([segment.inertia, -segment.damping, -segment.stiffness])
        np.testing.assert_allclose(np.sort_complex(eigs), np.sort_complex(roots), rtol=1e-9)


def test_at_activation_one_every_segment_is_self_stable_one_at_the_margin(state):
    """Activation 1 is the minimum stabilising PCSA: every S_k <= -stability_margin (0.1 N m/rad,
    params.Optimisation), the binding segment at it, so every eigenvalue has Re < 0."""
    got = nb.point_numbers(load_preset("default"), ExploreState(**{**state.__dict__, "activation": 1.0}))
    stiffness = np.array([s.stiffness for s in got.report.segments])
    assert np.all(stiffness <= -0.1 + 1e-6) and stiffness.max() == pytest.approx(-0.1, abs=1e-4)
    assert np.all(got.eigenvalues.real < 0)


def test_shown_numbers():
    """Four significant digits; complex as a+bj; inf and nan as Python writes them."""
    assert [nb.shown(x) for x in (np.pi, -1.5 + 2.25j, np.inf, np.nan, 1e-7)] == [
        "3.142",
        "-1.5+2.25j",
        "inf",
        "nan",
        "1e-07",
    ]


def test_landscapes_match_the_reference_solver_at_grid_points(state):
    """The fast path's minimum PCSA and ||CT|| at three grid points against the cvxpy reference
    (optimise.reference.solve_point, a second method; docs/optimisation.md: they agree to the solver tolerance)."""
    base = load_preset("default")
    dataset = nb.landscapes(base, state, points=5)
    assert dict(dataset.sizes) == {"E": 5, "Lambda": 5}
    model = _library_model(base, state)
    for i, j in [(0, 0), (2, 3), (4, 1)]:
        e, lam = float(dataset.E[i]), float(dataset.Lambda[j])
        reference = solve_point(model, e, lam)
        assert float(dataset.min_pcsa_cm2[i, j]) == pytest.approx(reference.min_pcsa * 1e4, rel=1e-5)
        assert float(dataset.counter_torque_norm_Nm[i, j]) == pytest.approx(
            np.linalg.norm(reference.counter_torque), rel=1e-4, abs=1e-6
        )
