"""Nonlinear simulation of the chain with the true delay (docs/chain.md, "Nonlinear simulation")."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from spinectl import load_preset, optimise
from spinectl.model import chain, geometry
from spinectl.model.config import set_parameters
from spinectl.model.mechanics import gravity_sign
from spinectl.optimise.coupled import least_local_stiffness
from spinectl.reflex.mimo import chain_delay_margin
from spinectl.reflex.simulate import nonlinear_chain_plant, simulated_chain_delay_margin

N = 5
STEP = 1e-6


def _central_difference(func, step=STEP):
    """d func / d z_k by central differences, one column per joint."""
    eye = np.eye(N)
    return np.stack([(func(step * eye[k]) - func(-step * eye[k])) / (2 * step) for k in range(N)], axis=-1)


@pytest.mark.parametrize("preset", ["default", "wagner2012"])
def test_torques_linearise_to_the_chains_k_and_d(rng, preset):
    """Central differences of the plant's nonlinear torques at upright are the linear chain's K - diag(k)
    and D - c_loc diag(k) (chain_coefficients), with local stiffness k and its damping; upright is an
    equilibrium (counter torques)."""
    model = load_preset(preset)
    E, L = rng.uniform(-0.06, 0.06, 2)
    pcsa = optimise.solve_point(model, E, L).pcsa
    k = rng.uniform(0.0, 50.0, N)
    plant = nonlinear_chain_plant(model, E, L, pcsa, k)
    zero = np.zeros(N)
    coefficients = chain.chain_coefficients(model, E, L)
    stiffness, damping = coefficients.stiffness(pcsa, k), coefficients.damping(pcsa, k)
    np.testing.assert_allclose(
        _central_difference(lambda dq: plant.torque(dq, zero)), stiffness, atol=1e-7 * np.abs(stiffness).max()
    )
    np.testing.assert_allclose(
        _central_difference(lambda dw: plant.torque(zero, dw)), damping, atol=1e-5 * np.abs(damping).max()
    )
    np.testing.assert_allclose(plant.torque(zero, zero), 0.0, atol=1e-12 * np.abs(plant.counter_torque).max())
    # at rest upright, q'' = M^-1 u with the upright mass matrix
    u = rng.normal(size=N)
    mass = chain.mass_matrix(model, plant.cor)
    np.testing.assert_allclose(plant.acceleration(zero, zero, u), np.linalg.solve(mass, u), rtol=1e-10)


def _energy(plant, x):
    """T + V in closed form: 1/2 q' M(q) q' + m g y_m(q) (times the gravity sign) + 1/2 sum (K_pas + k) q^2
    - CT . q (the constant counter torques are conservative too)."""
    model, q, qdot = plant.model, x[:N], x[N:]
    height = chain.carried_points(geometry.mass_position(model)[None, :], q, plant.cor)[0, 1]
    potential = gravity_sign(model) * model.body.mass * model.body.gravity * height + 0.5 * plant.stiffness @ q**2
    potential = potential - plant.counter_torque @ q
    return 0.5 * qdot @ chain.mass_matrix(model, plant.cor, q) @ qdot + potential


def _swing(plant, velocity_torque=True):
    """Energy drift and kinetic-energy swing of a large free motion (0.3 s, no muscles: no damping)."""

    def rates(_, x):
        return np.concatenate([x[N:], plant.acceleration(x[:N], x[N:], np.zeros(N))])

    start = np.array([0.15, -0.2, 0.1, 0.05, -0.1, 1.0, -2.0, 0.5, 1.5, -1.0])
    states = solve_ivp(rates, (0.0, 0.3), start, method="DOP853", rtol=1e-11, atol=1e-12).y.T
    energy = np.array([_energy(plant, x) for x in states])
    kinetic = np.array([0.5 * x[N:] @ chain.mass_matrix(plant.model, plant.cor, x[:N]) @ x[N:] for x in states])
    return np.ptp(energy), np.ptp(kinetic)


def test_energy_is_conserved_without_muscles(monkeypatch):
    """Gravity, passive and local springs only (conservative; the local muscles' damping off,
    local.damping = 0): T + V is constant along a large motion to the integrator's tolerance, while the
    kinetic energy swings by tens of joules. Dropping the Coriolis and centripetal terms c(q, q') breaks
    it: the check can fail."""
    model = set_parameters(load_preset("wagner2012"), {"local.damping": 0.0})
    plant = nonlinear_chain_plant(model, 0.02, 0.03, np.zeros(len(model.muscle_names)), np.full(N, 40.0))
    drift, swing = _swing(plant)
    assert swing > 1.0 and drift < 1e-9 * swing
    monkeypatch.setattr(chain, "velocity_torque", lambda model, cor, q, qdot: np.zeros(np.shape(q)))
    drift, swing = _swing(plant)
    assert drift > 1e-3 * swing


def test_the_local_muscles_damping_dissipates_what_it_should():
    """With the local muscles' damping on (no global muscles, local springs of 40 N m/rad and their damping
    c_loc k per joint), the energy T + V of the motion of the conservative test falls, and by exactly the
    work of the dampers: E(0) - E(t) = integral of sum_j c_loc k_j q'_j^2 dt, integrated here as an extra
    state beside the motion (a second route to the same number), to 1e-6 of the loss."""
    model = load_preset("wagner2012")
    k = np.full(N, 40.0)
    plant = nonlinear_chain_plant(model, 0.02, 0.03, np.zeros(len(model.muscle_names)), k)
    d = chain.local_damping_per_stiffness(model) * k

    def rates(_, x):
        return np.concatenate(
            [x[N : 2 * N], plant.acceleration(x[:N], x[N : 2 * N], np.zeros(N)), [d @ x[N : 2 * N] ** 2]]
        )

    start = np.array([0.15, -0.2, 0.1, 0.05, -0.1, 1.0, -2.0, 0.5, 1.5, -1.0, 0.0])
    end = solve_ivp(rates, (0.0, 0.3), start, method="DOP853", rtol=1e-11, atol=1e-12).y[:, -1]
    loss = _energy(plant, start[: 2 * N]) - _energy(plant, end[: 2 * N])
    assert loss > 0.1 and loss == pytest.approx(end[-1], rel=1e-6)


def test_small_motions_turn_unstable_at_the_exact_coupled_delay_margin():
    """A statically stable chain (wagner2012 at the per-segment optimum plus 30 N m/rad more than the least
    local stiffness; heavy levels, 10 kg and rho = 0.5 m, so that its modes are slow and its margin of
    79 ms is cheap to simulate) under kp = 20 N m/rad, kd = 10 N m s/rad and the 50 ms activation lag; the
    local muscles damp the joints (c_loc k, in the plant and in D).
    A bisection of 4 delays by 2 rounds on the nonlinear simulation (1e-4 rad) brackets reflex.mimo's
    exact delay margin within 1 %."""
    model = load_preset("wagner2012")
    model = model.replace(levels=dataclasses.replace(model.levels, mass=10.0, radius_of_gyration=0.5))
    pcsa = optimise.solve_point(model, 0.0, 0.0).pcsa
    k = least_local_stiffness(model, 0.0, 0.0, pcsa).local_stiffness + 30.0
    plant = nonlinear_chain_plant(model, 0.0, 0.0, pcsa, k)
    coefficients = chain.chain_coefficients(model, 0.0, 0.0)
    kp, kd, lag = np.full(N, 20.0), np.full(N, 10.0), 0.05
    mass, stiffness = chain.mass_matrix(model, plant.cor), coefficients.stiffness(pcsa, k)
    exact = chain_delay_margin(mass, stiffness, coefficients.damping(pcsa, k), kp, kd, lag).margin
    settings = dataclasses.replace(model.reflex, sim_duration=6.0, sim_time_step=0.005, activation_time_constant=lag)
    perturbation = 1e-4 * np.array([1.0, -2.0, 1.5, 0.5, -1.0])
    low, high = simulated_chain_delay_margin(plant, kp, kd, settings, perturbation, 0.9 * exact, 1.1 * exact, 4, 2)
    assert 0.99 * exact <= low <= exact <= high <= 1.01 * exact
