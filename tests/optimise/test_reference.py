"""The per-point reference optimiser: stabilising, minimal, and the paper's symmetries."""

from __future__ import annotations

import dataclasses

import cvxpy as cp
import numpy as np
import pytest

from spinectl import optimise
from spinectl.model import geometry
from spinectl.model.mechanics import segment_coefficients
from spinectl.model.stability import segment_stability

POINTS = [(0.0, 0.0), (0.08, 0.0), (0.08, 0.08), (0.0, 0.08), (0.03, 0.04)]
"""Positions A, B, C, D of the paper's figures and its optimum (E, Lambda) [m]."""


def _with(model, **settings):
    return model.replace(optimisation=dataclasses.replace(model.optimisation, **settings))


@pytest.mark.parametrize(("E", "L"), POINTS)
def test_chosen_activation_is_self_stable(model, E, L):
    """Every segment's eigenvalues have negative real part (paper, eq. 1) at the optimum."""
    opt = optimise.solve_point(model, E, L)
    assert opt.ok
    result = segment_stability(model, E, L, opt.pcsa)
    assert result.all_self_stable
    assert np.all(result.eigenvalues.real < 0)


@pytest.mark.parametrize(("E", "L"), POINTS)
def test_minimum_is_minimal(model, E, L):
    """Lowering any positive PCSA of the LP optimum by 1 % breaks a stability constraint.

    If it did not, the lowered vector would be feasible with a smaller total: the
    LP optimum would not be optimal. A 2 % smaller chosen activation has less
    than the minimum total, so some segment must lose self-stability: the
    margin (0.1 N m/rad) is far below 2 % of the muscular stiffness (~100 N m/rad).
    """
    data = optimise.problem_data(model, segment_coefficients(model, E, L))
    status, x = optimise.min_pcsa_lp(data)
    assert status == "optimal"
    for j in np.flatnonzero(x > 1e-6 * x.max()):
        lowered = x.copy()
        lowered[j] *= 0.99
        assert np.any(data.stability @ lowered > data.stability_bound)
    opt = optimise.solve_point(model, E, L)
    assert not segment_stability(model, E, L, 0.98 * opt.pcsa).all_self_stable


def test_chosen_activation_is_within_the_tolerance_band(model):
    opt = optimise.solve_point(model, 0.03, 0.04)
    assert opt.min_pcsa <= opt.total_pcsa <= opt.min_pcsa * (1 + model.optimisation.ct_tolerance) * (1 + 1e-9)


def test_min_pcsa_is_proportional_to_mass(model):
    """With K = 0 and no margin, b = -(gravity stiffness) is proportional to m and S x <= b
    is homogeneous: doubling m doubles the minimum PCSA exactly (LP scaling)."""
    base = _with(model, stability_margin=0.0)
    heavy = base.replace(body=dataclasses.replace(base.body, mass=2 * base.body.mass))
    for E, L in POINTS[1:3]:
        one = optimise.solve_point(base, E, L).min_pcsa
        two = optimise.solve_point(heavy, E, L).min_pcsa
        assert two == pytest.approx(2 * one, rel=1e-9)


def test_counter_torque_is_zero_at_A_with_paired_activation(model):
    """At A the model is mirror-symmetric: each pair's torque and gravity's vanish (paper, Discussion)."""
    opt = optimise.solve_point(model, 0.0, 0.0)
    assert opt.ok
    np.testing.assert_allclose(opt.counter_torque, 0.0, atol=1e-9)


def test_paired_counter_torque_is_proportional_to_the_cor_offsets(model):
    """A mirror-symmetric force system has no moment about the axis and a vertical resultant,
    so CT_k = x_k * s with one scalar s for all CoRs (module docstring of optimise)."""
    E, L = 0.03, 0.05
    opt = optimise.solve_point(model, E, L)
    x_cor = geometry.cor_positions(E, L, model.geometry)[:, 0]
    ratio = opt.counter_torque / x_cor
    np.testing.assert_allclose(ratio, ratio[0], rtol=1e-9)


def test_margin_and_bounds_are_honoured(model):
    strict = _with(model, stability_margin=5.0, pcsa_max=25e-4)
    opt = optimise.solve_point(strict, 0.03, 0.04)
    assert opt.ok
    stiffness = segment_coefficients(strict, 0.03, 0.04).stiffness(opt.pcsa)
    assert np.all(stiffness <= -5.0 + 1e-6)
    assert np.all(opt.pcsa <= 25e-4 * (1 + 1e-9))


def test_infeasible_point_is_nan_with_a_status(model):
    """With at most 1 cm^2 per muscle no activation can hold the upright body (gravity ~ 100 N m/rad)."""
    opt = optimise.solve_point(_with(model, pcsa_max=1e-4), 0.0, 0.0)
    assert opt.status in optimise.INFEASIBLE_STATUSES and not opt.ok
    assert np.isnan(opt.min_pcsa) and np.isnan(opt.pcsa).all() and np.isnan(opt.counter_torque_norm)


def test_solver_errors_fall_back_then_report(model, monkeypatch):
    calls = []

    def failing_solve(self, solver=None, **kwargs):
        calls.append(solver)
        raise cp.error.SolverError("simulated")

    monkeypatch.setattr(cp.Problem, "solve", failing_solve)
    opt = optimise.solve_point(model, 0.03, 0.04)
    assert calls == list(optimise.SOLVERS)
    assert opt.status == optimise.SOLVER_ERROR and np.isnan(opt.min_pcsa)


def test_minimum_norm_activation_and_counter_torque_front(model):
    """The front runs from the chosen activation's end (budget = minimum PCSA) to the
    minimum-norm activation, non-increasing in between (a convex trade-off)."""
    E, L = 0.08, 0.0
    far = optimise.min_norm_activation(model, E, L)
    near = optimise.solve_point(model, E, L)
    front = optimise.counter_torque_front(model, E, L, n_points=6)
    assert far.ok and near.ok and all(s == "optimal" for s in front.status)
    assert far.counter_torque_norm <= near.counter_torque_norm
    assert far.total_pcsa >= near.min_pcsa
    assert np.all(np.diff(front.counter_torque_norm) <= 1e-9 * front.counter_torque_norm[0])
    assert front.total_pcsa[0] == pytest.approx(near.min_pcsa, rel=1e-9)
    assert front.total_pcsa[-1] == pytest.approx(far.total_pcsa, rel=1e-9)
    assert front.counter_torque_norm[-1] == pytest.approx(far.counter_torque_norm, rel=1e-9)


def test_independent_activation_needs_no_more_pcsa_than_paired(model):
    """Paired activations are a subset of the independent ones, so the minimum cannot rise."""
    independent = _with(model, activation="independent")
    for E, L in POINTS:
        assert optimise.solve_point(independent, E, L).min_pcsa <= optimise.solve_point(model, E, L).min_pcsa * (
            1 + 1e-9
        )


def test_passive_stiffness_alone_still_needs_muscle_damping(model):
    """K = 500 N m/rad exceeds gravity at every CoR (m g r <= 40 * 9.81 * 0.321 = 126 N m/rad),
    so S_k < 0 with no muscle; but then D_k = 0 and eq. 1 gives an undamped centre (+-j w).
    The damping rows (D_k <= -damping_margin) make the optimum a small PCSA with D_k < 0
    at every CoR, hence truly self-stable."""
    stiff = model.replace(passive=dataclasses.replace(model.passive, stiffness=500.0))
    opt = optimise.solve_point(stiff, 0.03, 0.04)
    assert opt.ok and 0 < opt.min_pcsa < 1e-4  # under 1 cm^2
    result = segment_stability(stiff, 0.03, 0.04, opt.pcsa)
    assert np.all(result.damping <= -stiff.optimisation.damping_margin * (1 - 1e-6))
    assert result.self_stable.all()


@pytest.mark.parametrize("activation", ["paired", "independent"])
def test_a_large_model_keeps_the_statuses(activation):
    """A problem of minimum PCSA ~1e5 cm^2 (1000 kg, 30 m/s^2, mass 1 m up, 5e4 N/m^2) is the smaller one
    scaled by m g / sigma (zero margins: linear, paper eq. 2), so statuses are equal and the minimum scales
    exactly. At 1e4 N/m^2 (~5e5 cm^2) both solvers call some of these points infeasible: a documented
    limit (docs/robustness.md, "large models")."""
    from spinectl.model import config
    from spinectl.optimise import active_set

    base = config.load_preset("wagner2012")
    opt = dataclasses.replace(base.optimisation, stability_margin=0.0, damping_margin=0.0, activation=activation)
    base = base.replace(optimisation=opt, body=dataclasses.replace(base.body, mass_height=1.0))
    corner = base.replace(
        body=dataclasses.replace(base.body, mass=1000.0, gravity=30.0),
        fibre=dataclasses.replace(base.fibre, specific_tension=5e4),
    )
    scale = (1000.0 / base.body.mass) * (30.0 / base.body.gravity) * (base.fibre.specific_tension / 5e4)
    for e, lam in ((0.0, 0.0), (0.0, 0.06), (0.04, 0.04), (0.08, 0.08)):
        small, large = active_set.solve_point(base, e, lam), active_set.solve_point(corner, e, lam)
        assert small.status == large.status == "optimal"
        assert large.min_pcsa == pytest.approx(scale * small.min_pcsa, rel=1e-6)
