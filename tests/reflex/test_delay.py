"""Delayed reflex: Padé coefficients, exact delay margins of textbook loops, root counting, critical gains."""

from __future__ import annotations

from fractions import Fraction

import control as ct
import numpy as np
import pytest

from spinectl import reflex
from spinectl.errors import ParameterError
from spinectl.model.params import Reflex
from spinectl.reflex.loops import closed_loop

# A lumbar segment without co-contraction: S = m g r for m = 40 kg, r = 0.254 m (L3L4 of
# the default model at E = Lambda = 0), theta = m r^2, no muscle damping.
S0, D0, THETA0 = 40 * 9.81 * 0.254, 0.0, 40 * 0.254**2


def _rightmost_pole(s, d, theta, kp, kd, delay, order=12):
    """Largest real part of the python-control closed loop with a Padé delay (an independent route)."""
    return closed_loop(s, d, theta, kp, kd, delay, order).poles().real.max()


# --- Padé ---------------------------------------------------------------------------------------


def test_pade_coefficients_match_the_published_table():
    """[n/n] Padé of exp(-x), e.g. Abramowitz-Stegun style tables: 1 + x/2; 1 + x/2 + x^2/12;
    1 + x/2 + x^2/10 + x^3/120."""
    table = {
        1: [1, Fraction(1, 2)],
        2: [1, Fraction(1, 2), Fraction(1, 12)],
        3: [1, Fraction(1, 2), Fraction(1, 10), Fraction(1, 120)],
    }
    for n, coeffs in table.items():
        np.testing.assert_allclose(reflex.pade_coefficients(n), [float(c) for c in coeffs], rtol=1e-15)


@pytest.mark.parametrize("order", range(1, 13))
def test_pade_coefficients_match_python_control(order):
    """python-control's pade(T, n) gives den(s) with leading 1; in x = s T it is our q(x) up to scale."""
    tau = 0.37
    num, den = ct.pade(tau, order)
    # den[i] multiplies s^(n - i) = (x / tau)^(n - i)
    in_x = np.asarray(den)[::-1] / tau ** np.arange(order + 1)
    np.testing.assert_allclose(in_x / in_x[0], reflex.pade_coefficients(order), rtol=1e-9)
    signs = (-1.0) ** np.arange(order + 1)
    np.testing.assert_allclose(np.asarray(num)[::-1] / den[-1], signs * np.asarray(den)[::-1] / den[-1], rtol=1e-9)


def test_pade_phase_lag_first_order_closed_form():
    """n = 1: (1 - x/2)/(1 + x/2) has lag 2 atan(y/2); its inverse is y = 2 tan(phi/2)."""
    y = np.linspace(0, 50, 11)
    np.testing.assert_allclose(reflex.pade_phase_lag(y, 1), 2 * np.arctan(y / 2), atol=1e-14)
    phi = np.array([0.1, 1.0, 3.0])
    np.testing.assert_allclose(reflex.pade_inverse_lag(phi, 1), 2 * np.tan(phi / 2), rtol=1e-12)
    assert reflex.pade_inverse_lag(np.pi, 1) == np.inf  # a first-order Padé never lags by pi


def test_pade_phase_lag_equals_angle_of_python_control_pade():
    tau, order = 0.2, 6
    w = np.linspace(0.1, 40, 30)
    num, den = ct.pade(tau, order)
    response = np.polyval(num, 1j * w) / np.polyval(den, 1j * w)
    np.testing.assert_allclose(np.abs(response), 1.0, rtol=1e-12)  # all-pass
    lag = -np.unwrap(np.angle(response))
    np.testing.assert_allclose(reflex.pade_phase_lag(w * tau, order), lag, atol=1e-9)


# --- exact delay margins of loops with a closed form --------------------------------------------


@pytest.mark.parametrize(("gain", "time_constant"), [(2.0, 1.0), (5.0, 0.3), (1.2, 2.0), (30.0, 0.05)])
def test_first_order_plus_delay_margin_closed_form(gain, time_constant):
    """L = K exp(-s tau) / (T s + 1): w_c = sqrt(K^2 - 1)/T, PM = pi - atan(w_c T), tau_m = PM / w_c.

    In the segment's terms P(s) = theta s^2 - D s - S with theta = 0, D = -T, S = -1, kp = K, kd = 0.
    """
    w_c = np.sqrt(gain**2 - 1) / time_constant
    expected = (np.pi - np.arctan(w_c * time_constant)) / w_c
    result = reflex.delay_margin(-1.0, -time_constant, 0.0, gain, 0.0)
    assert result.status_names == "finite"
    assert abs(result.margin - expected) < 1e-6 * expected
    assert result.frequency == pytest.approx(w_c, rel=1e-12)


def test_first_order_plus_delay_with_small_gain_is_delay_independent():
    """K < 1: |L| < 1 at every frequency, no crossover, stable for any delay."""
    result = reflex.delay_margin(-1.0, -0.5, 0.0, 0.8, 0.0)
    assert result.margin == np.inf and result.status_names == "delay_independent"


@pytest.mark.parametrize(("theta", "kp", "kd"), [(1.0, 1.0, 1.0), (2.5, 40.0, 3.0), (0.3, 5.0, 10.0)])
def test_double_integrator_with_delayed_pd_closed_form(theta, kp, kd):
    """theta s^2 + (kp + kd s) exp(-s tau): theta^2 w^4 = kp^2 + kd^2 w^2 and tau_m = atan(kd w / kp) / w."""
    w = np.sqrt((kd**2 + np.sqrt(kd**4 + 4 * theta**2 * kp**2)) / (2 * theta**2))
    expected = np.arctan(kd * w / kp) / w
    assert abs(reflex.delay_margin(0.0, 0.0, theta, kp, kd).margin - expected) < 1e-9 * expected


def test_stepan_bound_on_the_delay_of_a_balanced_inverted_pendulum():
    """Delayed PD balances theta phi'' = S phi only for tau < sqrt(2 theta / S) (Stépán 1989, Retarded
    Dynamical Systems; Stépán and Kollár 2000, Math Comput Model 31:199): no gains exceed it,
    and the best gains (kp -> S+, kd -> sqrt(2 theta S)) approach it."""
    bound = np.sqrt(2 * THETA0 / S0)
    kp = S0 * (1 + np.logspace(-5, 0, 120))[:, None]
    kd = np.linspace(0.1, 5, 400)[None, :] * np.sqrt(2 * THETA0 * S0)
    margins = reflex.delay_margin(S0, D0, THETA0, kp, kd).margin
    assert margins.max() < bound
    assert margins.max() > 0.99 * bound


def test_statuses_inf_zero_nan():
    s = np.array([-20.0, 50.0, 50.0, np.nan])
    d = np.array([-10.0, -5.0, -5.0, -5.0])
    kp = np.array([0.0, 40.0, 80.0, 80.0])  # kp < S: unstable at zero delay
    kd = np.array([0.0, 5.0, 5.0, 5.0])
    result = reflex.delay_margin(s, d, 2.0, kp, kd)
    assert list(result.status_names) == ["delay_independent", "unstable_without_delay", "finite", "undefined"]
    assert result.margin[0] == np.inf and result.margin[1] == 0.0 and np.isnan(result.margin[3])
    assert 0 < result.margin[2] < np.inf


def test_margin_is_where_python_control_poles_cross(rng):
    """Random unstable segments with the default reflex: at 0.99 and 1.01 of the exact margin the
    rightmost pole of the order-12 Padé closed loop (python-control) is left, then right of the axis."""
    for _ in range(6):
        s, d, theta = rng.uniform(10, 150), -rng.uniform(0, 30), rng.uniform(1, 5)
        kp, kd = reflex.default_gains(s, d, theta, 1.5, 1.0)
        margin = float(reflex.delay_margin(s, d, theta, kp, kd).margin)
        assert (
            _rightmost_pole(s, d, theta, kp, kd, 0.99 * margin)
            < 0
            < _rightmost_pole(s, d, theta, kp, kd, 1.01 * margin)
        )


def test_root_count_through_stability_switches():
    """A stiff, lightly damped, self-stable segment with a strong delayed P reflex has two crossing
    frequencies (F(x) = x^2 - 199 x + 7500 for S = -100, D = -1, theta = 1, kp = 50) and loses and
    regains stability as the delay grows. The exact count agrees with the python-control Padé poles."""
    s, d, theta, kp, kd = -100.0, -1.0, 1.0, 50.0, 0.0
    np.testing.assert_allclose(
        reflex.crossings(s, d, theta, kp, kd).frequency[:2] ** 2,
        (199 + np.array([1, -1]) * np.sqrt(9601)) / 2,
        rtol=1e-12,
    )
    assert np.isnan(reflex.crossings(s, d, theta, kp, kd).frequency[2])  # F is quadratic without the lag
    delays = np.linspace(0.0, 0.6, 61)[1:]
    exact = reflex.stable_at_delay(s, d, theta, kp, kd, delays)
    pade = np.array([_rightmost_pole(s, d, theta, kp, kd, tau, order=16) < 0 for tau in delays])
    near = np.min(np.abs(delays[:, None] - _critical_delays(s, d, theta, kp, kd)[None, :]), axis=1) < 2e-3
    assert np.array_equal(exact[~near], pade[~near])
    assert exact.any() and not exact.all()  # at least one switch each way within 0.6 s
    assert np.diff(exact.astype(int)).clip(min=0).sum() >= 1  # regains stability


def _critical_delays(s, d, theta, kp, kd, count=10):
    cr = reflex.crossings(s, d, theta, kp, kd)
    k = np.arange(count)[:, None]
    delays = cr.first_delay[None, :] + 2 * np.pi * k / cr.frequency[None, :]
    return delays[np.isfinite(delays)]


# --- Padé estimate -------------------------------------------------------------------------------


def test_pade_margin_converges_and_is_the_padé_models_crossing():
    """The vectorised Padé estimate for order n is where python-control's order-n closed loop crosses."""
    kp, kd = reflex.default_gains(S0, D0, THETA0, 1.5, 1.0)
    orders = list(range(1, 9))
    margins, errors = reflex.pade_convergence(S0, D0, THETA0, kp, kd, orders)
    assert np.all(np.diff(np.abs(errors[:6])) < 0)  # orders 1-6, above rounding (1e-15 s)
    assert np.all(errors[:6] > 0)  # the Padé phase lags less than the delay: it overestimates
    assert np.all(np.abs(errors[5:]) < 1e-13)
    for n, tau in zip(orders[:5], margins[:5], strict=True):
        lo, hi = (closed_loop(S0, D0, THETA0, kp, kd, f * tau, n).poles().real.max() for f in (1 - 1e-6, 1 + 1e-6))
        assert lo < 0 < hi


# --- phase margin, critical gains, default rule ------------------------------------------------


@pytest.mark.parametrize("delay", [0.0, 0.05])
def test_phase_margin_matches_python_control(delay):
    """At tau = 0 the loop is rational and python-control's margins are exact; at 50 ms use Padé 12."""
    s, d, theta = 30.0, -8.0, 2.0
    kp, kd = reflex.default_gains(s, d, theta, 1.5, 1.0)
    loop = ct.tf([kd, kp], [1]) * ct.tf(*ct.pade(delay, 12)) * ct.tf([1], [theta, -d, -s])
    _, pm, _, _, wgc, _ = ct.stability_margins(loop)
    ours, w_c = reflex.phase_margin(s, d, theta, kp, kd, delay)
    assert np.degrees(ours) == pytest.approx(pm, abs=1e-6)
    assert w_c == pytest.approx(wgc, rel=1e-9)


def test_critical_gains_against_a_scan_and_python_control():
    kp, kd = reflex.default_gains(S0, D0, THETA0, 1.5, 1.0)
    lo, hi = reflex.critical_gains(S0, D0, THETA0, kd, 0.08)
    assert lo == pytest.approx(S0)  # below kp = S a real root sits in Re s > 0 for every delay
    grid = np.linspace(0.5 * S0, 5 * S0, 20001)
    stable = grid[reflex.stable_at_delay(S0, D0, THETA0, grid, kd, 0.08)]
    step = grid[1] - grid[0]
    assert stable.min() == pytest.approx(lo, abs=step) and stable.max() == pytest.approx(hi, abs=step)
    assert (
        _rightmost_pole(S0, D0, THETA0, 0.999 * hi, kd, 0.08)
        < 0
        < _rightmost_pole(S0, D0, THETA0, 1.001 * hi, kd, 0.08)
    )


def test_critical_gains_edge_cases():
    # without delay any kp > S does (kd > D); delayed P alone cannot hold an undamped pendulum
    assert reflex.critical_gains(S0, D0, THETA0, 10.0, 0.0) == (pytest.approx(S0), np.inf)
    assert np.isnan(reflex.critical_gains(S0, D0, THETA0, 0.0, 0.05)).all()


def test_default_gains_give_the_damping_ratio_without_delay():
    """The delay-free closed loop theta s^2 + (kd - D) s + (kp - S) has zeta = (kd - D) / (2 sqrt(theta (kp - S)))."""
    s, d, theta = np.array([50.0, 50.0, -30.0]), np.array([0.0, -40.0, -2.0]), 2.0
    kp, kd = reflex.default_gains(s, d, theta, 1.5, 0.8)
    np.testing.assert_allclose(kp, [75.0, 75.0, 0.0])  # 1.5 x the deficit max(S, 0)
    zeta = (kd - d) / (2 * np.sqrt(theta * (kp - s)))
    np.testing.assert_allclose(zeta[[0, 2]], 0.8)
    assert kd[1] == 0.0 and zeta[1] > 0.8  # the muscles damp enough on their own


def test_landscape_is_pointwise_and_keeps_inf_for_self_stable_segments(rng):
    shape = (3, 4, 5)
    s = rng.uniform(-40, 120, shape)
    d = -rng.uniform(0, 30, shape)
    theta = rng.uniform(1, 4, shape)
    s[0, 0, 0] = np.nan
    settings = Reflex()
    grid = reflex.landscape(s, d, theta, settings)
    assert grid.delay_margin.shape == shape
    for idx in [(0, 0, 1), (1, 2, 3), (2, 3, 4)]:
        one = reflex.landscape(s[idx], d[idx], theta[idx], settings)
        assert one.delay_margin == grid.delay_margin[idx] and one.kp == grid.kp[idx]
    assert np.isnan(grid.delay_margin[0, 0, 0]) and reflex.STATUS[grid.delay_margin_status[0, 0, 0]] == "undefined"
    idle = (s < 0) & (grid.kp == 0) & (grid.kd == 0)
    assert idle.any() and np.all(grid.delay_margin[idle] == np.inf)  # self-stable, no reflex: any delay
    finite = np.isfinite(grid.delay_margin) & (grid.delay_margin > 0)
    assert np.all(grid.stable_at_delay[finite] == (grid.delay_margin[finite] > settings.delay))


def test_critical_gains_for_a_tiny_delay():
    """tau = 1 us: the upper gain sits at w tau << 1, below the first grid point of the search
    unless the grid starts at w = 0; the exact root count confirms both ends."""
    kd = float(reflex.default_gains(S0, D0, THETA0, 1.5, 1.0)[1])
    lo, hi = reflex.critical_gains(S0, D0, THETA0, kd, 1e-6)
    assert lo == pytest.approx(S0) and 1e6 * S0 > hi > 1e3 * S0
    inside_outside = reflex.stable_at_delay(S0, D0, THETA0, np.array([0.999, 1.001]) * hi, kd, 1e-6)
    assert inside_outside.tolist() == [True, False]


# --- boundary cases ------------------------------------------------------------------------------


def _rightmost_root(s, d, theta, kp, kd, tau, guess):
    """A root of theta s^2 - D s - S + (kp + kd s) e^{-s tau}, by Newton from ``guess`` (an independent route)."""
    z = complex(guess)
    for _ in range(50):
        e = np.exp(-z * tau)
        f = theta * z * z - d * z - s + (kp + kd * z) * e
        df = 2 * theta * z - d + kd * e - tau * (kp + kd * z) * e
        z -= f / df
    return z


def test_axis_pair_at_zero_delay_that_moves_left():
    """S = -1, D = 0, theta = 1, kp = -0.5, kd = 0 (kd = D): s^2 + 0.5 = 0 puts +-0.707j on the axis at tau = 0,
    and sign F'(0.5) = -1 sends them left. At tau = 1 no root is in Re s > 0: the rightmost pair is
    -0.306 +- 0.782j (Newton on the quasi-polynomial; python-control's order-16 Padé loop agrees)."""
    assert reflex.right_half_plane_roots(-1, 0, 1, -0.5, 0, 1.0) == 0
    assert reflex.stable_at_delay(-1, 0, 1, -0.5, 0, 1.0)
    assert not reflex.stable_at_delay(-1, 0, 1, -0.5, 0, 0.0)  # on the axis at tau = 0
    root = _rightmost_root(-1, 0, 1, -0.5, 0, 1.0, -0.3 + 0.78j)
    assert root.real == pytest.approx(-0.306, abs=1e-3) and abs(root.imag) == pytest.approx(0.782, abs=1e-3)
    assert _rightmost_pole(-1, 0, 1, -0.5, 0, 1.0, order=16) == pytest.approx(root.real, abs=1e-6)


@pytest.mark.parametrize(("kp", "count"), [(0.5, 2), (-2.0, 1)])
def test_axis_boundary_for_the_other_signs_of_kp(kp, count):
    """kd = D = 0, S = -1: kp = 0.5 > S puts the pair on the axis with sign F' = +1, so it moves right (two
    roots in Re s > 0 for every small delay, as python-control's Padé poles say); kp = -2 < S gives the real
    pair +-1 of s^2 - 1, one in the right half plane at tau = 0 and after."""
    for tau in (0.05, 0.3):
        assert reflex.right_half_plane_roots(-1, 0, 1, kp, 0, tau) == count
        assert not reflex.stable_at_delay(-1, 0, 1, kp, 0, tau)
        poles = closed_loop(-1, 0, 1, kp, 0, tau, 12).poles()
        assert np.sum(poles.real > 1e-9) == count


def test_tangent_axis_pair_follows_the_second_order():
    """kp = 0, kd = D = -0.5, S = -1, theta = 1: F = (x - 1)^2 touches 0 at w = 1 (no first-order motion). The
    second order of Delta(s(tau), tau) = 0 gives Re s'' = D w^2 / (4 theta) < 0: the pair leaves to the left,
    as the order-16 Padé poles show at tau = 0.2."""
    assert reflex.right_half_plane_roots(-1, -0.5, 1, 0, -0.5, 0.2) == 0
    assert reflex.stable_at_delay(-1, -0.5, 1, 0, -0.5, 0.2)
    assert _rightmost_pole(-1, -0.5, 1, 0, -0.5, 0.2, order=16) < 0


def test_undamped_segment_without_reflex_is_never_asymptotically_stable():
    """S < 0, D = 0, kp = kd = 0: Delta = theta s^2 - S has the pair +-j sqrt(-S/theta) for every delay."""
    delays = np.array([0.0, 0.1, 1.0, 10.0])
    assert not reflex.stable_at_delay(-4.0, 0.0, 1.0, 0.0, 0.0, delays).any()
    assert np.all(reflex.right_half_plane_roots(-4.0, 0.0, 1.0, 0.0, 0.0, delays) == 0)
    assert reflex.delay_margin(-4.0, 0.0, 1.0, 0.0, 0.0).status_names == "unstable_without_delay"


def test_root_at_zero_with_a_root_on_the_right():
    """kp = S, kd < D: theta s^2 + (kd - D) s has the roots 0 and (D - kd)/theta > 0: one in Re s > 0, not two."""
    assert reflex.right_half_plane_roots(10.0, 0.0, 1.0, 10.0, -1.0, 0.0) == 1


def test_first_order_loop_does_not_depend_on_the_sign_convention():
    """theta = 0: (S, D, kp) = (0, 1, -1) and (0, -1, 1) are the same loop s + e^{-s tau} = 0, stable for
    tau < pi/2 (the classical result: the root pair crosses at w = 1, where w tau = pi/2)."""
    for args in ((0.0, 1.0, 0.0, -1.0, 0.0), (0.0, -1.0, 0.0, 1.0, 0.0)):
        result = reflex.delay_margin(*args)
        assert result.status_names == "finite" and result.margin == pytest.approx(np.pi / 2, rel=1e-12)
        assert reflex.stable_at_delay(*args, 1.5) and not reflex.stable_at_delay(*args, 1.6)


def test_pure_gain_with_delay_has_its_closed_form():
    """theta = D = kd = 0: -S + kp e^{-s tau} = 0, i.e. 1 + K e^{-s tau} with K = -kp/S, has the roots
    s = (ln|K| + j(2k + 1) pi) / tau (K > 0): stable for every delay if |K| < 1, for none > 0 if |K| > 1."""
    small, large = reflex.delay_margin(-2.0, 0.0, 0.0, 1.0, 0.0), reflex.delay_margin(-1.0, 0.0, 0.0, 2.0, 0.0)
    assert small.margin == np.inf and small.status_names == "delay_independent"
    assert large.margin == 0.0 and large.status_names == "finite"  # stable at tau = 0 (no root), not after
    tau = 0.7
    root = (np.log(2.0) + 1j * np.pi) / tau
    assert abs(1.0 + 2.0 * np.exp(-root * tau)) < 1e-12 and root.real > 0
    assert reflex.right_half_plane_roots(-1.0, 0.0, 0.0, 2.0, 0.0, tau) == np.inf
    assert reflex.stable_at_delay(-2.0, 0.0, 0.0, 1.0, 0.0, tau) and not reflex.stable_at_delay(
        -1.0, 0.0, 0.0, 2.0, 0.0, tau
    )
    assert reflex.pade_delay_margin(-1.0, 0.0, 0.0, 2.0, 0.0, 5).margin == 0.0


@pytest.mark.parametrize("args", [(0.0, -1.0, 0.0, 1.0, 0.5), (-1.0, 0.0, 0.0, 1.0, 0.2)])
def test_neutral_loops_are_refused_naming_kd(args):
    """theta = 0 with kd != 0: deg Q = deg P (neutral type) or more; not covered, a one-line ParameterError."""
    with pytest.raises(ParameterError, match="kd") as info:
        reflex.delay_margin(*args)
    assert info.value.field == "kd" and "\n" not in str(info.value)
