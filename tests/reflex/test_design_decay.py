"""A least decay rate as the design's requirement (spinectl.reflex.design.decay, design --decay-rate)."""

from __future__ import annotations

import numpy as np
import pytest

from spinectl.model import config
from spinectl.model.operating_point import OperatingPoint, chain_at
from spinectl.reflex import design as dz
from spinectl.reflex import margins
from spinectl.reflex.design.decay import checked_decay_rate, shifted_loop

SUBJECT = {"body.mass": 35.0, "passive.stiffness": 10.0, "reflex.delay": 0.12, "reflex.activation": 0.5}
"""tests/reflex/test_design.py's subject: 35 kg, K = 10 N m/rad, a 120 ms delay, at E = 3 cm, Lambda = 4 cm."""


def _determinant(m, k, d, kp, kd, tau, lag, s):
    """det((T_a s + 1)(M s^2 - D s - K) + (K_p + K_d s) e^{-s tau}), written out here (docs/reflex.md)."""
    return np.linalg.det((lag * s + 1) * (m * s**2 - d * s - k) + np.diag(kp + kd * s) * np.exp(-s * tau))


def test_the_shifted_loop_is_the_characteristic_equation_at_s_minus_sigma():
    """The shifted loop's characteristic determinant at z is (1 - sigma T_a)^-n times the chain's at z - sigma, at
    any complex z (the algebra of the module, checked on a random 3-joint chain): so its roots are the chain's moved
    right by sigma, and its stability at the delay is every root of the chain at Re s < -sigma."""
    rng = np.random.default_rng(3)
    a = rng.normal(size=(3, 3))
    m, k, d = a @ a.T + 3 * np.eye(3), rng.normal(size=(3, 3)) * 20, -np.eye(3) - 0.1 * a
    kp, kd, tau, lag, sigma = rng.uniform(10, 50, 3), rng.uniform(1, 5, 3), 0.08, 0.05, 3.0
    k2, d2, kp2, kd2, lag2 = shifted_loop(m, k, d, kp, kd, lag, tau, sigma)
    for z in (0.3 + 2j, -1.5 - 7j, 4.0 + 0j):
        scale = (1 - sigma * lag) ** -3
        assert _determinant(m, k2, d2, kp2, kd2, tau, lag2, z) == pytest.approx(
            scale * _determinant(m, k, d, kp, kd, tau, lag, z - sigma), rel=1e-10
        )


def test_a_decay_rate_design_has_every_root_beyond_minus_sigma_and_a_little_less_does_not():
    """The chain's design at decay rate 0.1 1/s: the rightmost root at the returned f k*, recomputed here on the
    chain itself (no shift; Newton from 96 Chebyshev nodes' eigenvalues, a second method), is at Re s <= -0.1, and
    1e-3 k* less it is right of -0.1; it costs more than the design for stability alone. The rule leaves no reflex
    at f = 1 and a slow mode there (Re s -> 0), so the fractions that meet 0.1 1/s form a window below 1."""
    model = config.set_parameters(config.load_preset("wagner2012"), SUBJECT)
    pcsa = 0.5 * margins.solve_point(model, 0.03, 0.04).pcsa
    plain = dz.chain_design(model, 0.03, 0.04, pcsa, 0.5)
    result = dz.chain_design(model, 0.03, 0.04, pcsa, 0.5, decay=0.1)
    assert plain.fraction < result.fraction < 1
    linear = chain_at(OperatingPoint(model, 0.03, 0.04, pcsa, slip_check=False))

    def rightmost(f):
        k, d, kp, kd = dz.chain_loop_at(model, linear, result.least_static, f)
        return dz.rightmost_root(linear.mass_matrix, k, d, kp, kd, 0.12, 0.05, 96).real

    assert rightmost(result.fraction) <= -0.1 + 1e-9 and rightmost(result.fraction) == pytest.approx(-0.1, abs=1e-4)
    assert rightmost(result.fraction - 1e-3) > -0.1
    assert result.max_root_real == pytest.approx(rightmost(result.fraction), abs=1e-9)
    assert rightmost(1.0) > -0.1  # the top fails: the window


@pytest.mark.parametrize(("sigma", "lag", "needle"), [(-1.0, 0.05, "must be"), (20.0, 0.05, "1/T_a = 20 1/s"),
                                                      (400.0, 0.0, "30/tau = 300 1/s")])  # fmt: skip
def test_a_decay_rate_at_or_beyond_its_bound_is_refused_naming_it(sigma, lag, needle):
    """sigma >= 1/T_a (the shift's c = 1 - sigma T_a would vanish) or sigma tau > 30 (without a lag), or a negative
    sigma: one ParameterError naming the bound."""
    with pytest.raises(Exception, match="--decay-rate") as caught:
        checked_decay_rate("--decay-rate", sigma, 0.1, lag)
    assert needle in str(caught.value)


def test_joint_by_joint_each_segment_at_the_decay_rates_activation_has_its_roots_beyond_minus_sigma():
    """Joint by joint at 0.1 1/s (wagner2012 at E = 3 cm, Lambda = 4 cm, 100 ms): at the common least activation
    every segment's loop under the rule (theta s^2 - D s - S with the lag and the delayed PD, one joint), solved
    here by Newton from 96 Chebyshev nodes (a second method), has its rightmost root at Re s <= -0.1; 1e-3 below it,
    the binding segment's is right of -0.1; it needs more than stability alone. The margins reported are the
    segments' own (>= the delay), and there is no 'largest delay met' (the shifted loops hold one delay)."""
    from spinectl.model.checks import checked_coefficients
    from spinectl.reflex import gains

    model = config.load_preset("wagner2012")
    plain = dz.joint_design(model, 0.03, 0.04)[0]
    activation, segments, optimum, status, largest, _ = dz.joint_design(model, 0.03, 0.04, decay=0.1)
    assert status == "ok" and activation > plain and np.isnan(largest)
    assert all(s.delay_margin >= 0.1 for s in segments)
    coefficients = checked_coefficients(model, 0.03, 0.04)

    def rightmost(a):
        pcsa = a * np.asarray(optimum)
        s, d = coefficients.stiffness(pcsa), coefficients.damping(pcsa)
        theta = np.broadcast_to(coefficients.inertia, s.shape)
        kp, kd = gains.resolve_gains(s, d, theta, model.reflex)
        return [
            dz.rightmost_root([[theta[k]]], [[s[k]]], [[d[k]]], [kp[k]], [kd[k]], 0.1, 0.05, 96).real
            for k in range(s.size)
        ]

    assert max(rightmost(activation)) <= -0.1 + 1e-6
    assert max(rightmost(activation - 1e-3)) > -0.1
