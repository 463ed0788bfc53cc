"""The design question (spinectl.reflex.design): the least co-contraction and local stiffness for a delay."""

from __future__ import annotations

import numpy as np
import pytest

from spinectl.model import chain, config
from spinectl.model.checks import checked_coefficients
from spinectl.model.operating_point import OperatingPoint, chain_at
from spinectl.reflex import design as dz
from spinectl.reflex import margins
from spinectl.reflex.chain_margins import stable_at
from spinectl.reflex.delay import delay_text
from spinectl.reflex.design import roots
from spinectl.reflex.mimo import chain_delay_margin

SUBJECT = {"body.mass": 35.0, "passive.stiffness": 10.0, "reflex.delay": 0.12}
"""A 35 kg subject with K = 10 N m/rad and a 120 ms reflex delay, at E = 3 cm, Lambda = 4 cm."""


def _subject(**extra):
    return config.set_parameters(config.load_preset("wagner2012"), SUBJECT | extra)


def test_the_least_activation_meets_the_delay_and_a_little_less_does_not():
    """Joint by joint, checked through margins.margins_report (the operating point re-solved, the rule's gains, the
    exact margins): at the returned activation every segment's margin is >= 120 ms; 1e-4 below it L1L2's is not. About
    31 % of the minimum PCSA, 13.7 cm^2 (19 %, 8.3 cm^2, under the former rule that cancelled the lag, as found by
    looping over ``margins --activation`` by hand)."""
    model = _subject()
    activation, segments, optimum, status, _, method = dz.joint_design(model, 0.03, 0.04)
    assert status == "ok" and method.startswith("bisection")
    at = margins.margins_report(config.set_parameters(model, {"reflex.activation": activation}), 0.03, 0.04)
    assert all(s.delay_margin >= 0.12 for s in at.segments) and at.all_stable_at_delay
    below = margins.margins_report(config.set_parameters(model, {"reflex.activation": activation - 1e-4}), 0.03, 0.04)
    assert min(s.delay_margin for s in below.segments) < 0.12
    assert activation == pytest.approx(max(s.activation for s in segments))  # monotone: the slowest segment's
    assert activation == pytest.approx(0.3145, abs=1e-3)
    assert 1e4 * activation * optimum.sum() == pytest.approx(13.74, abs=0.01)


def test_a_segment_at_its_least_activation_has_the_closed_form_margin_equal_to_the_delay():
    """Without the lag (T_a = 0) a segment's loop theta s^2 - D s - S + (kp + kd s) e^{-s tau} crosses where
    theta^2 w^4 + (2 theta S + D^2 - kd^2) w^2 + S^2 - kp^2 = 0 (|P(jw)| = |Q(jw)|), at tau = arg(-Q/P)... /w:
    at the returned activation this closed-form margin equals the delay (the search stops on the boundary)."""
    model = _subject(**{"reflex.activation_time_constant": 0.0})
    _, segments, optimum, _, _, _ = dz.joint_design(model, 0.03, 0.04)
    coefficients = checked_coefficients(model, 0.03, 0.04)
    k = 0  # L1L2
    pcsa = segments[k].activation * optimum
    s, d, theta = coefficients.stiffness(pcsa)[k], coefficients.damping(pcsa)[k], coefficients.inertia[k]
    r = model.reflex
    kp = r.gain_factor * max(s, 0.0)
    kd = max(0.0, 2 * r.damping_ratio * np.sqrt(theta * max(kp - s, 0.0)) + d)
    w2 = np.roots([theta**2, 2 * theta * s + d**2 - kd**2, s**2 - kp**2])
    w = np.sqrt(np.max(w2.real[(np.abs(w2.imag) < 1e-12) & (w2.real > 0)]))
    p = -theta * w**2 - 1j * d * w - s  # P(jw) of theta s^2 - D s - S
    q = kp + 1j * kd * w
    tau = np.mod(-np.angle(-p / q), 2 * np.pi) / w  # e^{-j w tau} = -P/Q
    assert tau == pytest.approx(0.12, rel=1e-6)


@pytest.mark.parametrize("local_damping", [1.0, 0.0])
def test_the_chain_design_has_its_certificate_and_a_little_less_fails(local_damping):
    """The chain at activation 0.5: the returned local stiffness f k* gives an exact multivariable margin >= the
    delay and a rightmost root in the left half-plane (recomputed here); one grid step below it (2^-BISECTIONS of
    the search's range [0, 1]) the exact margin falls short of the delay, and just past that margin the rightmost
    root (a second method) lies on the right. With the local muscles' damping (local.damping = 1) the design is
    f = 0.734 and the loop loses stability at its first crossing, 12.2 rad/s. Stiffness only (0), f = 0.9997, and
    the loop one step below is stable at the delay itself but not on all of [0, delay]: delay systems switch
    stability, and a narrow crossing band at about 217 rad/s opens unstable windows well below the delay (near
    5-10 ms and 34-39 ms). The rule's reflex vanishes at f = 1, so f <= 1."""
    model = _subject(**{"reflex.activation": 0.5, "local.damping": local_damping})
    optimum = margins.solve_point(model, 0.03, 0.04).pcsa
    result = dz.chain_design(model, 0.03, 0.04, 0.5 * optimum, 0.5)
    assert 0 < result.fraction <= 1 and result.delay_margin >= 0.12 and result.max_root_real < 0
    assert result.fraction < 0.75 if local_damping else result.fraction > 0.999  # the damping lets the reflex help
    linear = chain_at(OperatingPoint(model, 0.03, 0.04, 0.5 * optimum, slip_check=False))
    mass = linear.mass_matrix

    def loop(f):
        return dz.chain_loop_at(model, linear, result.least_static, f)

    k, d, kp, kd = loop(result.fraction)
    exact = chain_delay_margin(mass, k, d, kp, kd, 0.05)
    assert stable_at(exact, 0.12) and exact.margin >= 0.12
    assert dz.rightmost_root(mass, k, d, kp, kd, 0.12, 0.05, dz.SPECTRAL_NODES).real < 0
    step = 1.0 / 2**dz.BISECTIONS
    k, d, kp, kd = loop(result.fraction - step)
    less = chain_delay_margin(mass, k, d, kp, kd, 0.05)
    assert less.margin < 0.12
    assert dz.rightmost_root(mass, k, d, kp, kd, less.margin * 1.02, 0.05, dz.SPECTRAL_NODES).real > 0


def test_the_chains_loop_carries_the_local_muscles_damping():
    """chain_loop_at at local stiffness f k*: the stiffness K - f diag(k*) and the damping D - c_loc f diag(k*),
    c_loc = (1 + a) / (q hill_b (vmax_slow + vmax_fast_gain FT) l_opt/l) by hand (docs/chain.md); the rule's
    gains do not depend on the local damping (they are set at f = 0). With local.damping = 0 the damping is the
    global muscles' D bit for bit, the stiffness-only model (c_loc is the chain's: the chain of each model)."""
    on = _subject(**{"reflex.activation": 0.5})
    off = _subject(**{"reflex.activation": 0.5, "local.damping": 0.0})
    optimum = margins.solve_point(on, 0.03, 0.04).pcsa
    linear = chain_at(OperatingPoint(on, 0.03, 0.04, 0.5 * optimum, slip_check=False))
    stiffness, damping = linear.stiffness_offset, linear.damping_offset
    least, f = np.array([60.0, 90.0, 95.0, 66.0, 19.0]), 0.7
    fibre = on.fibre
    b = fibre.hill_b * (fibre.vmax_slow + fibre.vmax_fast_gain * fibre.fast_twitch) * fibre.optimal_length_ratio
    c_loc = (1.0 + fibre.hill_a) / b / on.local.stiffness_gain
    k, d, kp, kd = dz.chain_loop_at(on, linear, least, f)
    np.testing.assert_array_equal(k, stiffness - f * np.diag(least))
    np.testing.assert_allclose(d, damping - c_loc * f * np.diag(least), rtol=1e-12, atol=1e-12)
    k0, d0, kp0, kd0 = dz.chain_loop_at(off, chain_at(OperatingPoint(off, 0.03, 0.04, 0.5 * optimum)), least, f)
    np.testing.assert_array_equal(d0, damping)
    np.testing.assert_array_equal(k0, k)
    np.testing.assert_array_equal(kp0, kp)
    np.testing.assert_array_equal(kd0, kd)


def test_the_rightmost_root_is_a_root_and_agrees_with_the_exact_margin_on_one_joint():
    """One joint (theta = 1, S = 2, D = -0.5, kp = 6, kd = 1.5, T_a = 0.05): the returned s makes
    (T_a s + 1)(theta s^2 - D s - S) + (kp + kd s) e^{-s tau} vanish, and its real part changes sign at the
    exact delay margin of reflex.delay (the quasi-polynomial, a second method)."""
    from spinectl.reflex.delay import delay_margin

    m, k, d, kp, kd, lag = np.eye(1), 2.0 * np.eye(1), -0.5 * np.eye(1), [6.0], [1.5], 0.05
    tau_m = float(delay_margin(2.0, -0.5, 1.0, 6.0, 1.5, lag).margin)
    for tau, sign in ((0.98 * tau_m, -1), (1.02 * tau_m, 1)):
        s = dz.rightmost_root(m, k, d, kp, kd, tau, lag, dz.SPECTRAL_NODES)
        residual = (lag * s + 1) * (s**2 + 0.5 * s - 2.0) + (6.0 + 1.5 * s) * np.exp(-s * tau)
        assert abs(residual) < 1e-9 and np.sign(s.real) == sign


def test_a_fast_seed_does_not_overflow_the_rightmost_root(monkeypatch):
    """One joint with a fast and a slow pole (theta = 1e-3, S = -1, D = -10: about -1e4 and -0.1 1/s, as the local
    muscles' damping gives the light modes), kp = 0.5, a 0.1 s delay, under numpy's raise-on-overflow (the models'
    arithmetic guard): e^{-s tau} of the fast seed would overflow (e^1000). The rightmost root is the slow one, a
    root of (theta s^2 - D s - S) + kp e^{-s tau} (residual < 1e-9), left of the axis; without the bound on the
    exponent (MAX_EXPONENT = inf) the same call raises."""
    m, k, d, kp, kd = 1e-3 * np.eye(1), -np.eye(1), -10.0 * np.eye(1), [0.5], [0.0]
    with np.errstate(over="raise", invalid="raise", divide="raise"):
        s = dz.rightmost_root(m, k, d, kp, kd, 0.1)
        assert abs(1e-3 * s**2 + 10.0 * s + 1.0 + 0.5 * np.exp(-0.1 * s)) < 1e-9 and s.real < 0
        monkeypatch.setattr(roots, "MAX_EXPONENT", np.inf)
        with pytest.raises(FloatingPointError):
            dz.rightmost_root(m, k, d, kp, kd, 0.1)


def test_a_delay_no_activation_meets_is_an_answer():
    """Explicit gains too strong for a 50 ms delay (kp = 300 N m/rad, kd = 0) at every activation: status
    'infeasible', NaN activation, and the largest delay met on the scan, which is below 50 ms."""
    model = _subject(**{"reflex.delay": 0.05})
    activation, segments, _, status, largest, _ = dz.joint_design(model, 0.0, 0.0, kp=300.0, kd=0.0)
    assert status == "infeasible" and np.isnan(activation) and 0 < largest < 0.05
    scan = np.linspace(0, 1, dz.SCAN)
    at = [
        margins.margins_report(config.set_parameters(model, {"reflex.activation": a}), 0.0, 0.0, kp=300.0, kd=0.0)
        for a in scan[::10]
    ]
    assert max(min(s.delay_margin for s in r.segments) for r in at) <= largest + 1e-12


def test_a_delay_prints_with_its_unit_or_unbounded_without_one():
    """The table's delays: 120 ms in ms, 329.8 s (the plain case's chain margin, stiffness only) in s, an infinite
    margin as 'unbounded (delay-independent)' with no unit (not 'unbounded ms'), NaN as 'none'; and so in the
    certificate of a Design's table."""
    assert delay_text(0.12) == "120 ms" and delay_text(329.847) == "329.8 s" and delay_text(np.nan) == "none"
    assert delay_text(np.inf) == "unbounded (delay-independent)"
    n = 5
    chain = dz.ChainDesign(0.5, 0.9, np.ones(n), np.ones(n), np.inf, -1.0, np.inf, "test")
    seg = tuple(dz.SegmentDesign(f"S{i}", 0.1, 1e-4, 0.2, True) for i in range(n))
    d = dz.Design(0.0, 0.0, 0.12, 0.05, 0.1, 5e-4, seg, chain, "ok", np.inf, "test", {"header": "h"})
    certificate = next(line for line in d.table().splitlines() if line.startswith("certificate"))
    assert "exact delay margin unbounded (delay-independent) >= 120 ms" in certificate
    assert "unbounded ms" not in d.table()


def test_the_chains_largest_delay_met_is_the_largest_any_tried_design_meets():
    """chain.largest_delay_met_s means what the top-level (joint-by-joint) one means: the largest delay met by any
    design tried, not the margin of the least design. Under the rule's gains the scan reaches f = 1, which has no
    reflex and is stable at every delay, so it is unbounded (inf); the least design's own margin is finite. The
    second method: each scanned fraction's exact margin recomputed here (0 where unstable without delay), whose
    largest is inf too."""
    model = config.set_parameters(config.load_preset("wagner2012"), {"reflex.delay": 0.12})
    optimum = margins.solve_point(model, 0.03, 0.04).pcsa
    result = dz.chain_design(model, 0.03, 0.04, 0.5 * optimum, 0.5)
    linear = chain_at(OperatingPoint(model, 0.03, 0.04, 0.5 * optimum, slip_check=False))
    mass = linear.mass_matrix
    lag = model.reflex.activation_time_constant

    def margin(f):
        k, d, kp, kd = dz.chain_loop_at(model, linear, result.least_static, f)
        if not (np.any(kp) or np.any(kd)):  # no reflex: every delay, where the chain holds itself
            return np.inf if chain.coupled_margin(k) > 0 else 0.0
        exact = chain_delay_margin(mass, k, d, kp, kd, lag)
        return float(exact.margin) if exact.stable_without_delay else 0.0

    scanned = [margin(f) for f in np.linspace(0.0, 1.0, dz.CHAIN_SCAN)]
    assert np.isfinite(result.delay_margin) and result.delay_margin >= 0.12
    assert result.largest_delay == max(scanned) == np.inf
    assert result.to_dict()["largest_delay_met_s"] == np.inf
