"""The exact delay margin of the chain under the diagonal delayed reflex (docs/chain.md, "The delayed reflex")."""

from __future__ import annotations

import dataclasses

import control as ct
import numpy as np
import pytest

from spinectl import load_preset, reflex
from spinectl.errors import ParameterError
from spinectl.reflex.chain_system import chain_disk_margins, chain_loop
from spinectl.reflex.gains import chain_gains, default_gains
from spinectl.reflex.mimo import chain_delay_margin, delay_free_poles, pade_margin
from spinectl.reflex.simulate import ChainPlant, simulate_chain

# five uncoupled segments: S, D, theta and gains of mixed kinds (self-stable, unstable, no kp)
S = np.array([-30.0, 10.0, 25.0, -5.0, 40.0])
D = np.array([-1.0, -2.0, -0.5, -1.5, -3.0])
THETA = np.array([2.0, 1.5, 1.0, 0.8, 2.5])
KP = np.array([20.0, 30.0, 50.0, 0.0, 80.0])
KD = np.array([5.0, 6.0, 4.0, 3.0, 10.0])


def _coupled(seed=3, n=3):
    """A non-diagonal chain: M positive definite, K with an unstable mode, D negative semidefinite."""
    rng = np.random.default_rng(seed)
    a, b, c = (rng.normal(size=(n, n)) for _ in range(3))
    mass = a @ a.T + 0.5 * np.eye(n)
    stiffness = 5.0 * (b + b.T) + np.diag(np.linspace(20.0, 10.0, n))
    damping = -0.3 * c @ c.T
    kp = np.full(n, 1.5 * np.linalg.eigvalsh(stiffness)[-1])
    return mass, stiffness, damping, kp, np.full(n, 15.0)


@pytest.mark.parametrize("lag", [0.0, 0.05])
def test_diagonal_chain_is_the_smallest_segment_margin(lag):
    """Diagonal M, K, D: det factorises into the segments' quasi-polynomials, so the chain's margin is
    the smallest of reflex.delay_margin's closed forms (docs/reflex.md), to rounding."""
    exact = chain_delay_margin(np.diag(THETA), np.diag(S), np.diag(D), KP, KD, lag)
    segments = reflex.delay_margin(S, D, THETA, KP, KD, lag)
    assert exact.status == "finite"
    np.testing.assert_allclose(exact.margin, np.min(segments.margin), rtol=1e-10)
    # every segment's destabilising first crossing is found, at its own frequency
    finite = np.isfinite(segments.margin) & (segments.margin > 0)
    first = sorted(t for t, _, d in exact.critical_delays(1.0) if d > 0)
    for tau in segments.margin[finite]:
        assert min(abs(np.array(first) - tau)) <= 1e-10 * tau


def test_delay_free_poles_solve_the_characteristic_equation():
    """Each root s of the lagged closed loop makes det((T_a s + 1)(M s^2 - D s - K) + K_p + K_d s) vanish."""
    mass, stiffness, damping, kp, kd = _coupled()
    for s in delay_free_poles(mass, stiffness, damping, kp, kd, 0.05):
        t = (0.05 * s + 1) * (mass * s**2 - damping * s - stiffness) + np.diag(kp + kd * s)
        singular = np.linalg.svd(t, compute_uv=False)
        assert singular[-1] <= 1e-9 * singular[0]


@pytest.mark.parametrize("lag", [0.0, 0.05])
def test_crossing_is_a_root_on_the_axis(lag):
    """At tau = margin, s = j w_c is a root: det(P(j w) + Q(j w) e^{-j w tau}) = 0 (smallest singular value)."""
    mass, stiffness, damping, kp, kd = _coupled()
    exact = chain_delay_margin(mass, stiffness, damping, kp, kd, lag)
    s = 1j * exact.frequency
    t = (lag * s + 1) * (mass * s**2 - damping * s - stiffness) + np.diag(kp + kd * s) * np.exp(-s * exact.margin)
    singular = np.linalg.svd(t, compute_uv=False)
    assert singular[-1] <= 1e-10 * singular[0]


def test_pade_margins_converge_and_python_control_agrees():
    """The Padé margin approaches the exact one with the order (error 3e-2, 2e-4, 5e-7, <1e-11 at orders
    1, 2, 3, 5 here), and python-control's closed loop of chain_loop at that delay has a pole at j w_c:
    a second computation of the same crossing."""
    mass, stiffness, damping, kp, kd = _coupled()
    exact = chain_delay_margin(mass, stiffness, damping, kp, kd, 0.05)
    errors = []
    for order in (1, 2, 3, 5):
        tau = pade_margin(exact, order)
        errors.append(abs(tau - exact.margin) / exact.margin)
        loop = chain_loop(mass, stiffness, damping, kp, kd, tau, order, 0.05, ["a", "b", "c"])
        poles = ct.feedback(loop, ct.ss([], [], [], np.eye(3))).poles()
        assert np.min(np.abs(poles - 1j * exact.frequency)) <= 1e-6 * exact.frequency
    assert all(np.diff(errors) < 0) and errors[-1] < 1e-9


def test_simulation_with_the_true_delay_turns_unstable_at_the_margin():
    """The linear chain integrated with the true delay (RK4 and Hermite history of reflex.simulate):
    stable 1 % below the exact margin, unstable 1 % above; a batched bisection bracket around it."""
    mass, stiffness, damping, kp, kd = _coupled()
    exact = chain_delay_margin(mass, stiffness, damping, kp, kd, 0.05)
    settings = dataclasses.replace(
        load_preset("default").reflex, sim_duration=3.0, sim_time_step=0.002, activation_time_constant=0.05
    )
    delays = exact.margin * np.array([0.9, 0.99, 1.01, 1.1])
    _, stable = simulate_chain(ChainPlant(mass, stiffness, damping), kp, kd, delays, settings, [0.01, -0.02, 0.015])
    assert stable.tolist() == [True, True, False, False]


def test_chain_rule_is_the_segment_rule_on_a_diagonal_chain():
    """With k = max(S, 0), the segment's deficit, chain_gains gives default_gains of every segment."""
    kp, kd = chain_gains(np.diag(THETA), np.diag(S), np.diag(D), np.maximum(S, 0.0), 1.5, 1.0)
    kp0, kd0 = default_gains(S, D, THETA, 1.5, 1.0)
    np.testing.assert_allclose(kp, kp0, rtol=1e-15)
    np.testing.assert_allclose(kd, kd0, rtol=1e-15)


def test_disk_margins_of_one_joint_are_the_siso_margin():
    """n = 1: multiloop and loop-at-a-time disk margins are the SISO balanced disk margin,
    1 / max_w abs(S(jw) - 1/2) with S = 1 / (1 + L) (Seiler et al. 2020, eq. for skew 0), computed here
    from the loop's frequency response."""
    loop = chain_loop([[2.0]], [[-30.0]], [[-1.5]], [10.0], [2.0], 0.02, 4, 0.0, ["L3L4"])
    omega = np.logspace(-2, 3, 2000)
    margins = chain_disk_margins(loop, omega)
    response = loop(1j * omega).ravel()
    alpha = 1.0 / np.max(np.abs(1.0 / (1.0 + response) - 0.5))
    np.testing.assert_allclose([margins.disk_margin, margins.loop_at_a_time[0, 0]], alpha, rtol=1e-6)
    np.testing.assert_allclose(margins.gain_margin, (1 + alpha / 2) / (1 - alpha / 2), rtol=1e-6)


def test_bad_shapes_name_the_argument():
    with pytest.raises(ParameterError, match="kp"):
        chain_delay_margin(np.eye(2), np.eye(2), np.eye(2), [1.0, 2.0, 3.0], [1.0, 1.0])
    with pytest.raises(ParameterError, match="stiffness"):
        chain_delay_margin(np.eye(2), np.eye(3), np.eye(2), 1.0, 1.0)


def test_nan_is_undefined_and_unstable_without_delay_is_zero():
    nan = chain_delay_margin(np.eye(2), np.full((2, 2), np.nan), np.eye(2), 1.0, 1.0)
    assert nan.status == "undefined" and np.isnan(nan.margin)
    # K_p - K not positive definite: a static root in the right half-plane at tau = 0
    weak = chain_delay_margin(np.eye(2), np.diag([10.0, 10.0]), -np.eye(2), [5.0, 20.0], [1.0, 1.0])
    assert weak.status == "unstable_without_delay" and weak.margin == 0.0


def test_the_delay_margin_of_a_chain_built_by_hand_is_that_of_its_modes():
    """A LinearChain written down (two joints, three controls, tests/optimise/test_coupled_sdp.py):
    K(u) = g 1 1' - diag(u_1, u_2) - u_3 1 1', D = -beta I, M = m I, with equal gains on both joints.
    Then M, D and K_p, K_d commute with K, and in K's eigenbasis every mode j (eigenvalue lambda_j) is
    the segment m s^2 + beta s - lambda_j + (k_p + k_d s) exp(-s tau) = 0. On s = j w the moduli of
    both parts agree where m^2 w^4 + (2 m lambda + beta^2 - k_d^2) w^2 + lambda^2 - k_p^2 = 0: with
    k_p > |lambda| one root w^2 > 0, a destabilising crossing at tau = (-arg(-P/Q) mod 2 pi) / w. The
    chain's margin is the smallest of the two modes' (u = (1, 2, 0.5), g = 3: lambda = 1 +- sqrt(6.5))."""
    from spinectl.model.linear_chain import LinearChain
    from spinectl.reflex.chain_system import linear_chain_system
    from spinectl.reflex.mimo import linear_chain_delay_margin

    g, m, beta, kp, kd = 3.0, 2.0, 0.5, 10.0, 2.0
    e1, e2, one = np.diag([1.0, 0.0]), np.diag([0.0, 1.0]), np.ones((2, 2))
    chain = LinearChain(
        joints=("top", "bottom"),
        controls=("local_top", "local_bottom", "global"),
        control_class=("local", "local", "global"),
        stiffness_per_control=np.stack([-e1, -e2, -one], axis=-1),
        damping_per_control=np.zeros((2, 2, 3)),
        stiffness_offset=g * one,
        damping_offset=-beta * np.eye(2),
        mass_matrix=m * np.eye(2),
        lower=np.zeros(3),
        upper=np.full(3, np.inf),
    )
    u = np.array([1.0, 2.0, 0.5])
    taus = []
    for lam in (1.0 + np.sqrt(6.5), 1.0 - np.sqrt(6.5)):
        b = 2 * m * lam + beta**2 - kd**2
        w = np.sqrt((-b + np.sqrt(b * b - 4 * m**2 * (lam**2 - kp**2))) / (2 * m**2))
        p, q = -m * w**2 + 1j * beta * w - lam, kp + 1j * kd * w
        taus.append(np.mod(-np.angle(-p / q), 2 * np.pi) / w)
    exact = linear_chain_delay_margin(chain, np.full(2, kp), np.full(2, kd), 0.0, u)
    assert exact.status == "finite" and exact.stable_without_delay
    np.testing.assert_allclose(exact.margin, min(taus), rtol=1e-9)
    # the same on the chain fixed at u (no controls), and its state-space poles are eq. 1's of each mode
    assert linear_chain_delay_margin(chain.at(u), np.full(2, kp), np.full(2, kd)).margin == exact.margin
    poles = np.sort_complex(linear_chain_system(chain, u).poles())
    modes = np.sort_complex(
        np.concatenate([np.roots([m, beta, -lam]) for lam in np.linalg.eigvalsh(chain.stiffness(u))])
    )
    np.testing.assert_allclose(poles, modes, rtol=1e-9)


def _narrow_band(epsilon=1e-9):
    """One joint whose crossing band is 4.5e-5 wide in w, beside a joint without reflex.

    Joint 1 (T_a = 0, k_d = 0): abs(P(jw))^2 = abs(Q(jw))^2 is theta^2 w^4 + b w^2 + S^2 - k_p^2 = 0 with
    b = 2 theta S + beta^2 (tests above); b = -2 theta sqrt(S^2 - k_p^2) (1 + epsilon) puts its two
    roots w^2 = 86.6 (1 +- 1.41 sqrt(epsilon)) next to each other: 9.30584 and 9.30626 rad/s, 30
    times narrower than a 0.15 % step. S = -100 < 0 < k_p: stable without delay. Joint 2 holds
    itself (S < 0, D < 0) and has no reflex, so no crossing."""
    theta, stiffness, kp = 1.0, -100.0, 50.0
    b = -2.0 * theta * np.sqrt(stiffness**2 - kp**2) * (1.0 + epsilon)
    beta = np.sqrt(b - 2.0 * theta * stiffness)
    chain = (np.diag([theta, 2.0]), np.diag([stiffness, -10.0]), np.diag([-beta, -1.0]), [kp, 0.0], [0.0, 0.0])
    return chain, (np.array([stiffness]), np.array([-beta]), np.array([theta]), np.array([kp]), np.array([0.0]))


def test_a_crossing_band_narrower_than_any_sweep_step_is_found():
    """The crossings come from Louisell's eigenvalue problem, not a frequency grid: both edges of a
    band 4.5e-5 wide (_narrow_band) are found, and the margin is the segment's closed form
    (reflex.delay_margin, the polynomial roots of abs(P)^2 = abs(Q)^2) to 1e-9. The former
    0.15 % sweep stepped over the band and reported the loop delay-independent."""
    chain, segment = _narrow_band()
    exact = chain_delay_margin(*chain, 0.0)
    closed = reflex.delay_margin(*segment, 0.0)
    assert exact.status == "finite"
    np.testing.assert_allclose(exact.margin, closed.margin[0], rtol=1e-9)
    np.testing.assert_allclose(exact.frequency, closed.frequency[0], rtol=1e-9)
    assert sorted(exact.directions.tolist()) == [-1.0, 1.0]
    assert abs(exact.crossovers[0] - exact.crossovers[1]) < 5e-5 * exact.frequency


def test_the_narrow_band_of_a_lightly_reflexed_paper_chain_is_found():
    """wagner2012 with a 35 kg body and passive stiffness 10 at E = 0.03, Lambda = 0.04, the global
    muscles at 0.189 of the minimum PCSA, local stiffness 0.9999 k* and the chain rule's reflex times
    1 - 0.9999 (the case spinectl design's chain search meets): the crossings lie 0.035 % apart
    near 381 rad/s, and the former sweep called the loop delay-independent. A second method,
    the rightmost root by Newton from a Chebyshev discretisation of the delay equation
    (reflex.design.roots.rightmost_root, Breda et al. 2005), is left of the axis 2 % below the exact
    margin and right of it 2 % above and at 0.12 s."""
    from spinectl.model import chain, geometry
    from spinectl.model.config import set_parameters
    from spinectl.optimise.coupled import least_local_stiffness_stacked
    from spinectl.optimise.reference import solve_point
    from spinectl.reflex.design import rightmost_root

    model = set_parameters(load_preset("wagner2012"), {"body.mass": 35, "passive.stiffness": 10})
    e, lam, f, r = 0.03, 0.04, 0.9999, model.reflex
    pcsa = 0.189 * np.asarray(solve_point(model, e, lam).pcsa, float)
    coefficients = chain.chain_coefficients(model, e, lam)
    mass = chain.mass_matrix(model, geometry.cor_positions(e, lam, model.geometry))
    stiffness, damping = coefficients.stiffness(pcsa), coefficients.damping(pcsa)
    least = least_local_stiffness_stacked(stiffness[None], model.optimisation.stability_margin)[1][0]
    kp, kd = chain_gains(mass, stiffness, damping, least, r.gain_factor, r.damping_ratio)
    k, kp, kd, lag = stiffness - f * np.diag(least), (1 - f) * kp, (1 - f) * kd, r.activation_time_constant
    exact = chain_delay_margin(mass, k, damping, kp, kd, lag)
    assert exact.status == "finite" and 380.0 < exact.frequency < 383.0
    for delay, side in ((0.98 * exact.margin, -1), (1.02 * exact.margin, 1), (0.12, 1)):
        assert np.sign(rightmost_root(mass, k, damping, kp, kd, delay, lag, 40).real) == side


def test_a_tiny_lag_keeps_every_crossing_of_the_lagless_loop():
    """T_a = 1e-7 s puts an eigenvalue -1/T_a = -1e7 1/s beside crossings at 1.6 to 29 rad/s; the
    squared Louisell problem would lose the lowest (relative error eps 1e14 / 2.4 = 1e-2), so the
    pencil is solved by QZ there. Its crossings and margin are the lagless loop's to the lag's
    own effect, a relative 1e-5 (phase lag w T_a <= 3e-6 rad)."""
    chain = _coupled()
    tiny, none = chain_delay_margin(*chain, 1e-7), chain_delay_margin(*chain, 0.0)
    assert len(tiny.crossovers) == len(none.crossovers) == 3
    np.testing.assert_allclose(tiny.crossovers, none.crossovers, rtol=1e-5)
    np.testing.assert_allclose(tiny.margin, none.margin, rtol=1e-5)


def test_a_loop_without_reflex_has_no_crossing_and_is_delay_independent():
    """One joint, M = 1 kg m^2, K = -10 N m/rad, D = -1 N m s/rad, no reflex (kp = kd = 0): the delayed term
    vanishes, so the characteristic equation s^2 + s + 10 = 0 has no root on the imaginary axis (closed form:
    both roots have real part -1/2) and no delay can destabilise it. Louisell's problem then has no candidate
    crossing at all (before: an empty candidate list raised an IndexError)."""
    result = chain_delay_margin(np.array([[1.0]]), np.array([[-10.0]]), np.array([[-1.0]]), np.zeros(1), np.zeros(1))
    assert result.status == "delay_independent" and result.margin == np.inf
