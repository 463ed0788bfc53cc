"""Segments and reflex loops as python-control loops."""

from __future__ import annotations

import warnings

import control as ct
import numpy as np
import pytest

from spinectl import reflex
from spinectl.model.stability import eigenvalues
from spinectl.reflex import loops


def test_segment_poles_are_the_jacobian_eigenvalues(rng):
    """Poles of the StateSpace = the closed-form eigenvalues of paper eq. (1)."""
    for _ in range(10):
        s, d, theta = rng.normal(0, 60), -rng.uniform(0, 30), rng.uniform(0.5, 5)
        sys = loops.segment_system(s, d, theta, name="L3L4")
        np.testing.assert_allclose(np.sort_complex(sys.poles()), np.sort_complex(eigenvalues(s, d, theta)), atol=1e-9)
        assert sys.state_labels == ["alpha", "omega"] and sys.input_labels == ["torque"]
        assert sys.output_labels == ["alpha"]


def test_loop_plant_is_the_state_space_segment():
    """G(s) = 1/(theta s^2 - D s - S) written out equals the StateSpace's frequency response."""
    s, d, theta = 25.0, -7.0, 2.2
    w = np.logspace(-1, 2, 13)
    loop = loops.loop_transfer(s, d, theta, 1.0, 0.0, 0.0, 1)  # C = 1, no delay: L = G
    np.testing.assert_allclose(loop(1j * w), loops.segment_system(s, d, theta)(1j * w), rtol=1e-12)


def test_closed_loop_without_delay_has_the_pd_poles():
    """tau = 0: poles are the roots of theta s^2 + (kd - D) s + (kp - S)."""
    s, d, theta, kp, kd = 40.0, -5.0, 2.0, 70.0, 9.0
    poles = loops.closed_loop(s, d, theta, kp, kd, 0.0, 5).poles()
    np.testing.assert_allclose(np.sort_complex(poles), np.sort_complex(np.roots([theta, kd - d, kp - s])), atol=1e-9)


def test_closed_loop_response_is_the_feedback_formula():
    """alpha / torque = G / (1 + C Pade G), from python-control's own algebra on transfer functions."""
    s, d, theta, kp, kd, tau, n = 40.0, -5.0, 2.0, 70.0, 9.0, 0.05, 4
    plant = ct.tf([1], [theta, -d, -s])
    reference = plant / (1 + ct.tf([kd, kp], [1]) * ct.tf(*ct.pade(tau, n)) * plant)
    w = np.logspace(-1, 2, 9)
    np.testing.assert_allclose(loops.closed_loop(s, d, theta, kp, kd, tau, n)(1j * w), reference(1j * w), rtol=1e-8)


def test_high_order_pade_poles_cross_at_the_exact_delay_margin():
    """A segment below self-stability with the default reflex: python-control's order-10 Padé closed
    loop, bisected on its rightmost pole, turns unstable at the exact margin of the quasi-polynomial."""
    s, d, theta = 49.8, -14.75, 2.58  # L3L4 at E = 3 cm, Lambda = 4 cm, half the minimum PCSA
    kp, kd = (float(x) for x in reflex.default_gains(s, d, theta, 1.5, 1.0))
    exact = float(reflex.delay_margin(s, d, theta, kp, kd).margin)
    lo, hi = 0.5 * exact, 1.5 * exact
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        unstable = loops.closed_loop(s, d, theta, kp, kd, mid, 10).poles().real.max() > 0
        lo, hi = (lo, mid) if unstable else (mid, hi)
    assert 0.5 * (lo + hi) == pytest.approx(exact, rel=1e-6)


def test_margins_of_a_rational_loop_agree_with_ours():
    """No delay: python-control computes the margins of the rational loop directly. Its phase margin
    and crossover are the quasi-polynomial's; the lower gain margin of this open-loop unstable
    segment is S / kp (at w = 0, L(0) = -kp / S), and the upper one is infinite for a PD loop."""
    s, d, theta, kp, kd = 30.0, -6.0, 2.0, 45.0, 4.0
    loop = loops.loop_transfer(s, d, theta, kp, kd, 0.0, 5)
    margins = loops.loop_margins(loop, stable=True)
    pm, w_c = reflex.phase_margin(s, d, theta, kp, kd, 0.0)
    assert margins.phase_margin_deg == pytest.approx(np.degrees(pm), abs=1e-9)
    assert margins.crossover_rad_s == pytest.approx(w_c, rel=1e-12)
    assert margins.gain_margin_lower == pytest.approx(s / kp) and margins.gain_margin_upper == np.inf
    assert margins.gain_margin == pytest.approx(s / kp)  # python-control picks the one nearer 1


def test_gain_margins_bound_the_exactly_stable_gain_factors():
    """With a delay the stable range of a common factor k on (kp, kd) is (lower, upper): checked
    with the exact root count of the quasi-polynomial just inside and outside both ends."""
    s, d, theta, tau = 49.8, -14.75, 2.58, 0.1
    kp, kd = (float(x) for x in reflex.default_gains(s, d, theta, 1.5, 1.0))
    margins = loops.loop_margins(loops.loop_transfer(s, d, theta, kp, kd, tau, 10), stable=True)
    lower, upper = margins.gain_margin_lower, margins.gain_margin_upper
    assert 0 < lower < 1 < upper < np.inf
    factors = np.array([0.999 * lower, 1.001 * lower, 0.999 * upper, 1.001 * upper])
    stable = reflex.stable_at_delay(s, d, theta, factors * kp, factors * kd, tau)
    assert stable.tolist() == [False, True, True, False]


def test_loop_margins_of_an_unstable_loop_are_nan():
    loop = loops.loop_transfer(50.0, -5.0, 2.0, 40.0, 5.0, 0.1, 5)  # kp < S
    margins = loops.loop_margins(loop, stable=False)
    assert np.isnan(margins.gain_margin_lower) and np.isnan(margins.gain_margin_upper)


def test_zero_reflex_has_no_crossover():
    margins = loops.loop_margins(loops.loop_transfer(-20.0, -5.0, 2.0, 0.0, 0.0, 0.1, 5), stable=True)
    assert margins.phase_margin_deg == np.inf and np.isnan(margins.crossover_rad_s)
    assert margins.gain_margin_lower == 0.0 and margins.gain_margin_upper == np.inf


def test_subnormal_coefficients_give_the_margins_of_zero_without_warnings():
    """A damping of 1e-308 N m s/rad (e.g. an activation of 1e-308) is subnormal: python-control's
    evaluation under np.errstate(all="warn") warned "underflow". The margins must be those of
    D = 0 exactly (the term is below any double's resolution of the others), and silent."""
    s, theta, kp, kd, tau = 71.0, 1.31, 106.5, 13.6, 0.0
    exact = loops.loop_margins(loops.loop_transfer(s, 0.0, theta, kp, kd, tau, 5), stable=True)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tiny = loops.loop_margins(loops.loop_transfer(s, -1.1e-308, theta, kp, kd, tau, 5), stable=True)
    assert tiny == exact


@pytest.mark.parametrize(
    "segment",
    [(30.0, -6.0, 2.0, 45.0, 4.0, 0.0), (49.8, -14.75, 2.58, 74.7, 22.1, 0.1), (-20.0, -5.0, 2.0, 0.0, 0.0, 0.1)],
    ids=["rational", "delayed", "no-reflex"],
)
def test_loop_margins_pick_the_margins_python_control_picks(segment):
    """One ``stability_margins(returnall=True)`` call gives the gain and phase margins (and their
    frequencies) that python-control's own ``stability_margins(loop)`` returns (the second method)."""
    s, d, theta, kp, kd, tau = segment
    loop = loops.loop_transfer(s, d, theta, kp, kd, tau, 5)
    gm, pm, _, wpc, wgc, _ = ct.stability_margins(loop)
    margins = loops.loop_margins(loop, stable=True)
    got = (margins.gain_margin, margins.phase_margin_deg, margins.phase_crossover_rad_s, margins.crossover_rad_s)
    np.testing.assert_array_equal(got, (gm, pm, wpc, wgc))
