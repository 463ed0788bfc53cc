"""Nonlinear one-segment simulation with the true delay, against the linear verdicts."""

from __future__ import annotations

import numpy as np
import pytest

from spinectl import reflex
from spinectl.errors import ParameterError
from spinectl.model import mechanics
from spinectl.model.params import Passive, Reflex
from spinectl.reflex import simulate

E, LAMBDA, L3L4 = 0.03, 0.04, 2
HALF = np.array([15.0, 15.0, 0.0, 0.0, 0.2, 0.2]) * 1e-4
"""About half the minimum stabilising PCSA at (E, Lambda) [m^2]: L3L4 is not self-stable."""
SELF_STABLE = np.array([32.0, 32.0, 0.0, 0.0, 0.5, 0.5]) * 1e-4
"""Above the minimum stabilising PCSA [m^2]: every segment self-stable."""
FAST = Reflex(sim_duration=8.0, sim_time_step=0.005, activation_time_constant=0.0)
"""Shorter runs for the tests, the pure delay; the slowest oscillation here has a period below 3 s."""
LAGGED = Reflex(sim_duration=8.0, sim_time_step=0.005, activation_time_constant=0.1)
"""The same with a 100 ms force-generation lag, the top of the paper's 50-100 ms."""


def _linear(model, pcsa, k):
    coeffs = mechanics.segment_coefficients(model, E, LAMBDA)
    return coeffs.stiffness(pcsa)[k], coeffs.damping(pcsa)[k], coeffs.inertia[k]


def test_plant_torque_is_the_paper_equation_and_zero_upright(model):
    """sum_i M_i + M_ext + CT - K alpha from the mechanics functions; CT makes upright an equilibrium."""
    plant = simulate.segment_plant(model, E, LAMBDA, "L3L4", HALF)
    alpha, omega = np.array([0.01, -0.02, 0.0]), np.array([0.3, -0.1, 0.0])
    expected = (
        mechanics.muscle_torque_per_pcsa(model, plant.cor, alpha, omega) @ HALF
        + mechanics.gravity_torque(alpha, plant.cor, model)
        - plant.passive_stiffness * alpha
        + plant.counter_torque
    )
    np.testing.assert_allclose(plant.torque(alpha, omega), expected, atol=1e-12)
    assert plant.torque(0.0, 0.0) == 0.0
    ct = mechanics.segment_coefficients(model, E, LAMBDA).counter_torque(HALF)[L3L4]
    assert plant.counter_torque == pytest.approx(ct, rel=1e-12)


def test_plant_linearisation_is_the_segment_stiffness_and_damping(model):
    """Central differences of the nonlinear torque give S and D of segment_coefficients (with K = 15 N m/rad)."""
    model = model.replace(passive=Passive(stiffness=15.0))
    plant = simulate.segment_plant(model, E, LAMBDA, L3L4, HALF)
    s, d, _ = _linear(model, HALF, L3L4)
    h = 1e-6
    assert (plant.torque(h, 0.0) - plant.torque(-h, 0.0)) / (2 * h) == pytest.approx(s, rel=1e-6)
    assert (plant.torque(0.0, h) - plant.torque(0.0, -h)) / (2 * h) == pytest.approx(d, rel=1e-6)


def test_without_reflex_self_stable_decays_at_the_slow_eigenvalue(model):
    """No reflex, self-stable L1L2: |alpha| falls at the slower eigenvalue of paper eq. (1)."""
    plant = simulate.segment_plant(model, E, LAMBDA, 0, SELF_STABLE)
    s, d, theta = _linear(model, SELF_STABLE, 0)
    slow = np.roots([theta, -d, -s]).real.max()
    assert slow < 0
    run = simulate.simulate(plant, 0.0, 0.0, 0.0, FAST)
    assert run.stable[0] and run.growth_rate[0] == pytest.approx(slow, rel=0.02)


def test_without_reflex_an_unstable_segment_diverges_and_stops(model):
    plant = simulate.segment_plant(model, E, LAMBDA, L3L4, HALF)
    run = simulate.simulate(plant, 0.0, 0.0, 0.1, FAST)
    assert run.diverged[0] and not run.stable[0] and run.growth_rate[0] == np.inf
    assert np.abs(run.alpha).max() <= FAST.sim_divergence * 1.5  # stopped near the threshold


def test_reflex_without_delay_stabilises(model):
    plant = simulate.segment_plant(model, E, LAMBDA, L3L4, HALF)
    kp, kd = reflex.default_gains(*_linear(model, HALF, L3L4), 1.5, 1.0)
    assert simulate.simulate(plant, kp, kd, 0.0, FAST).stable[0]


def test_stable_just_below_and_unstable_just_above_the_delay_margin(model):
    """The brief's check: a segment below self-stability with the default reflex, 3 % either side."""
    s, d, theta = _linear(model, HALF, L3L4)
    assert s > 0  # below self-stability
    kp, kd = reflex.default_gains(s, d, theta, 1.5, 1.0)
    margin = float(reflex.delay_margin(s, d, theta, kp, kd).margin)
    plant = simulate.segment_plant(model, E, LAMBDA, L3L4, HALF)
    run = simulate.simulate(plant, kp, kd, [0.97 * margin, 1.03 * margin], FAST)
    assert run.stable.tolist() == [True, False]
    assert not run.diverged.any()  # both stay small: the linear verdict applies


def test_bisection_on_the_simulation_finds_the_exact_margin(model):
    """Batched bisection (4 delays a round, 3 rounds) brackets where the nonlinear closed loop turns
    unstable; the exact margin of the quasi-polynomial lies within 1 % of that bracket."""
    s, d, theta = _linear(model, HALF, L3L4)
    kp, kd = reflex.default_gains(s, d, theta, 1.5, 1.0)
    margin = float(reflex.delay_margin(s, d, theta, kp, kd).margin)
    plant = simulate.segment_plant(model, E, LAMBDA, L3L4, HALF)
    low, high = simulate.simulated_delay_margin(plant, kp, kd, FAST, 0.8 * margin, 1.2 * margin, batch=4, rounds=3)
    assert 0.99 * low < margin < 1.01 * high
    assert high - low < 0.01 * margin


def test_reflex_only_spine_near_its_margin(model):
    """No co-contraction at all (PCSA 0, D = 0): the faster oscillation (about 8 rad/s) of the
    reflex-only loop turns unstable at the exact margin too."""
    zero = np.zeros(6)
    s, d, theta = _linear(model, zero, L3L4)
    kp, kd = reflex.default_gains(s, d, theta, 1.5, 1.0)
    margin = float(reflex.delay_margin(s, d, theta, kp, kd).margin)
    plant = simulate.segment_plant(model, E, LAMBDA, L3L4, zero)
    settings = Reflex(sim_duration=6.0, activation_time_constant=0.0)
    run = simulate.simulate(plant, kp, kd, [0.98 * margin, 1.02 * margin], settings)
    assert run.stable.tolist() == [True, False]


def test_bisection_on_the_lagged_simulation_finds_the_exact_lagged_margin(model):
    """With the force-generation lag 1/(T_a s + 1), T_a = 0.1 s, in the simulation (the torque integrated
    as T_a u' + u = command) and in the quasi-polynomial (T_a s + 1)(theta s^2 - D s - S) + Q e^{-s tau}: the
    bracket of the simulated loss of stability holds the exact margin within 1 %, and the lag has
    shortened it (the same gains without the lag tolerate more)."""
    s, d, theta = _linear(model, HALF, L3L4)
    lag = LAGGED.activation_time_constant
    kp, kd = reflex.default_gains(s, d, theta, 1.5, 1.0)
    margin = float(reflex.delay_margin(s, d, theta, kp, kd, lag).margin)
    assert margin < float(reflex.delay_margin(s, d, theta, kp, kd).margin)
    plant = simulate.segment_plant(model, E, LAMBDA, L3L4, HALF)
    low, high = simulate.simulated_delay_margin(plant, kp, kd, LAGGED, 0.8 * margin, 1.2 * margin, batch=4, rounds=3)
    assert 0.99 * low < margin < 1.01 * high
    assert high - low < 0.01 * margin


def test_lagged_simulation_starts_with_the_held_reflex_torque(model):
    """The lag starts at rest on the held history: u(0) = -kp alpha(0); with kd = 0 and no delay the torque
    then follows T_a u' + u = -kp alpha, checked by a finite difference of the recorded torque."""
    plant = simulate.segment_plant(model, E, LAMBDA, L3L4, HALF)
    run = simulate.simulate(plant, 80.0, 0.0, 0.0, Reflex(sim_duration=0.5, activation_time_constant=0.1))
    u, alpha, t = run.reflex_torque[0], run.alpha[0], run.time
    assert u[0] == -80.0 * alpha[0]
    derivative = np.gradient(u, t)[5:-5]
    np.testing.assert_allclose(0.1 * derivative + u[5:-5], -80.0 * alpha[5:-5], atol=1e-4 * abs(u[0]))


def test_simulation_is_deterministic_and_validates_the_delay(model):
    plant = simulate.segment_plant(model, E, LAMBDA, L3L4, HALF)
    short = Reflex(sim_duration=0.5)
    first, second = (simulate.simulate(plant, 80.0, 3.0, 0.1, short) for _ in range(2))
    assert np.array_equal(first.alpha, second.alpha)
    with pytest.raises(ParameterError, match="delay"):
        simulate.simulate(plant, 80.0, 3.0, -0.1, short)
    with pytest.raises(ParameterError, match="segment"):
        simulate.segment_plant(model, E, LAMBDA, "L9L10", HALF)


def test_too_many_steps_are_refused(model):
    plant = simulate.segment_plant(model, E, LAMBDA, L3L4, HALF)
    with pytest.raises(ParameterError, match="steps"):
        simulate.simulate(plant, 80.0, 3.0, 1e-9, FAST)
