"""The force-generation lag 1/(T_a s + 1) after the delay: T_a = 0 is today's loop bit for bit; the lagged
margin against a closed form derived here, python-control's Padé loops and the vectorised maps."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from spinectl import reflex
from spinectl.model import config
from spinectl.model.params import Reflex
from spinectl.reflex import loops, simulate

BEFORE = Path(__file__).parent / "data" / "pure_delay_31bf040.npz"
"""Outputs of the reflex functions at commit 31bf040, before the lag existed, on the inputs of
:func:`_pure_delay_outputs` (written by that commit's code with the same calls)."""

# A Stépán-type segment (inverted pendulum, no muscle damping) in units where theta = S = 1:
# the gains kp = 1.5, kd = 1.2 give the margins 0.687 s without and 0.589 s with a 0.1 s lag.
STEPAN = dict(stiffness=1.0, damping=0.0, inertia=1.0, kp=1.5, kd=1.2)


def _pure_delay_outputs() -> dict:
    rng = np.random.default_rng(20240613)
    n = 300
    s, d, th = rng.uniform(-80, 150, n), -rng.uniform(0, 30, n), rng.uniform(0.5, 5, n)
    kp, kd, tau = rng.uniform(0, 250, n), rng.uniform(0, 40, n), rng.uniform(0, 0.4, n)
    out = {}
    cr = reflex.crossings(s, d, th, kp, kd, 0.0)
    out["cr_frequency"], out["cr_phase"], out["cr_direction"] = (
        x[..., :2] for x in (cr.frequency, cr.phase, cr.direction)
    )
    m = reflex.delay_margin(s, d, th, kp, kd, 0.0)
    out["dm_margin"], out["dm_frequency"], out["dm_status"] = m.margin, m.frequency, m.status
    for order in (1, 3, 5):
        out[f"pade{order}"] = reflex.pade_delay_margin(s, d, th, kp, kd, order, 0.0).margin
    out["pm"], out["pm_w"] = reflex.phase_margin(s, d, th, kp, kd, tau, 0.0)
    out["rhp"] = reflex.right_half_plane_roots(s, d, th, kp, kd, tau, 0.0)
    out["stable"] = reflex.stable_at_delay(s, d, th, kp, kd, tau, 0.0)
    out["cg_lo"], out["cg_hi"] = reflex.critical_gains(s[:40], d[:40], th[:40], kd[:40], tau[:40], lag=0.0)
    out["rule_kp"], out["rule_kd"] = reflex.default_gains(s, d, th, 1.5, 1.0)
    grid = reflex.landscape(s, d, th, Reflex(activation_time_constant=0.0))
    for f in ("kp", "kd", "delay_margin", "delay_margin_status", "crossing_frequency", "delay_margin_pade"):
        out["land_" + f] = getattr(grid, f)
    out["land_stable_at_delay"] = grid.stable_at_delay
    lt = loops.loop_transfer(50.0, -15.0, 2.6, 75.0, 1.3, 0.1, 5, 0.0)
    out["lt_num"], out["lt_den"] = np.asarray(lt.num[0][0]), np.asarray(lt.den[0][0])
    out["cl_A"] = loops.closed_loop(50.0, -15.0, 2.6, 75.0, 1.3, 0.1, 5, lag=0.0).A
    plant = simulate.segment_plant(
        config.load_preset("default"), 0.03, 0.04, 2, np.array([15, 15, 0, 0, 0.2, 0.2]) * 1e-4
    )
    run = simulate.simulate(
        plant, [75.0, 0.0], [1.3, 0.0], [0.1, 0.05], Reflex(sim_duration=0.5, activation_time_constant=0.0)
    )
    out["sim_alpha"], out["sim_u"] = run.alpha, run.reflex_torque
    return out


REALISATION_DEPENDENT = ("cl_A",)
"""Outputs compared through their eigenvalues: state matrices of a realisation python-control may choose."""

SPINE_LINE_DEPENDENT = ("sim_alpha", "sim_u")
"""Outputs of a model's simulation, compared to 1e-12: the spine line is now computed in closed form, equal
to scipy's CubicSpline (before) to rounding (tests/model/test_mechanics.py), so the model's coefficients differ
in their last bits (seen: 8e-14 relative)."""

NEWTON_DEPENDENT = ("pade1", "pade3", "pade5", "land_delay_margin_pade")
"""Padé margins, compared to 1e-12: the inverse of the Padé lag is found by Newton's method, which ends on the
root to rounding where the bisection before ended on a neighbouring float of u = (2/pi) atan(y)
(tests/reflex/test_fast_roots.py; seen: 2e-15 relative)."""


def test_without_the_lag_every_result_is_bit_identical_to_before():
    """T_a = 0: crossings, margins (exact and Padé), phase margins, root counts, verdicts, critical gains, the
    rule, the landscape, the python-control loops and the simulation equal, bit for bit (NaN as NaN), what the
    code returned before the lag existed (commit 31bf040, stored in :data:`BEFORE`); the closed loop's state matrix
    through its poles, to 1e-9; the simulation and the Padé margins to 1e-12."""
    before = np.load(BEFORE)
    now = _pure_delay_outputs()
    assert set(now) == set(before.files)
    for name, value in now.items():
        assert value.shape == before[name].shape, name
        if name in REALISATION_DEPENDENT:
            continue
        if name in SPINE_LINE_DEPENDENT + NEWTON_DEPENDENT:
            np.testing.assert_allclose(value, before[name], rtol=1e-12, atol=0, err_msg=name)
            continue
        assert np.array_equal(value, before[name], equal_nan=True), name
    # A state-space realisation is not unique: python-control builds another one when slycot is installed
    # (its tf2ss then calls SLICOT's TD04AD). The closed loop's poles are what the realisation must keep.
    for name in REALISATION_DEPENDENT:
        poles_now = np.sort_complex(np.linalg.eigvals(now[name]))
        poles_before = np.sort_complex(np.linalg.eigvals(before[name]))
        np.testing.assert_allclose(poles_now, poles_before, rtol=1e-9, atol=1e-9, err_msg=name)


def _crossing_by_bisection(s, d, theta, kp, kd, lag):
    """The destabilising crossover of the lagged segment from |P(jw)| = |Q(jw)| by a scalar bisection in plain
    complex arithmetic (|P| - |Q| changes sign once on (0.1, 10) for these gains), and its first delay."""

    def p(w):
        return (1 + 1j * w * lag) * (-theta * w * w - 1j * d * w - s)

    def q(w):
        return kp + 1j * kd * w

    lo, hi = 0.1, 10.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if abs(p(mid)) < abs(q(mid)) else (lo, mid)
    w = 0.5 * (lo + hi)
    phase = np.mod(np.angle(-q(w) / p(w)), 2 * np.pi)
    return phase / w, w


@pytest.mark.parametrize(("lag", "expected"), [(0.0, 0.687), (0.1, 0.589)])
def test_lag_shortens_the_margin_of_a_stepan_segment(lag, expected):
    """theta = S = 1, D = 0, kp = 1.5, kd = 1.2: 0.687 s without the lag, 0.589 s with T_a = 0.1 s; the exact
    margin equals the scalar bisection of the crossing condition to 1e-12, and python-control's order-10 Padé
    closed loop (with the lag as a state) turns unstable between 0.999 and 1.001 of it."""
    margin = reflex.delay_margin(**STEPAN, lag=lag)
    tau, w = _crossing_by_bisection(1.0, 0.0, 1.0, 1.5, 1.2, lag)
    assert margin.margin == pytest.approx(tau, rel=1e-12) and margin.frequency == pytest.approx(w, rel=1e-12)
    assert round(float(margin.margin), 3) == expected
    poles = [
        loops.closed_loop(1.0, 0.0, 1.0, 1.5, 1.2, f * tau, 10, lag=lag).poles().real.max() for f in (0.999, 1.001)
    ]
    assert poles[0] < 0 < poles[1]


def test_pade_margins_with_the_lag_converge_from_above_to_the_exact_one():
    """The Padé estimate of the lagged loop is where python-control's order-n closed loop crosses, it
    overestimates (the Padé phase lags less than the delay) and its error falls with the order."""
    lag = 0.1
    margins, errors = reflex.pade_convergence(**STEPAN, orders=[1, 2, 3, 4, 5], lag=lag)
    assert np.all(errors > 0) and np.all(np.diff(errors) < 0) and errors[-1] < 1e-6
    for n, tau in zip([1, 2, 3], margins[:3], strict=True):
        poles = [
            loops.closed_loop(1.0, 0.0, 1.0, 1.5, 1.2, f * tau, n, lag=lag).poles().real.max() for f in (0.9999, 1.0001)
        ]
        assert poles[0] < 0 < poles[1]


def test_root_count_with_the_lag_against_pade_poles(rng):
    """Random segments with the lag: the exact count of roots in Re s > 0 at random delays equals that of the
    order-14 Padé closed loop (python-control), away from the critical delays."""
    for _ in range(12):
        s, d, theta = rng.uniform(-60, 120), -rng.uniform(0, 20), rng.uniform(1, 4)
        kp, kd, lag, tau = rng.uniform(0, 200), rng.uniform(0, 30), rng.uniform(0.01, 0.15), rng.uniform(0.01, 0.3)
        exact = reflex.right_half_plane_roots(s, d, theta, kp, kd, tau, lag)
        poles = loops.closed_loop(s, d, theta, kp, kd, tau, 14, lag=lag).poles()
        if np.min(np.abs(poles.real)) > 1e-3:  # no pole on the axis: the Padé count is reliable
            assert exact == np.sum(poles.real > 0)


def test_critical_gains_with_the_lag():
    """The stabilising kp range at tau = 0.3 s with T_a = 0.1 s: a scan of the exact verdict gives the same
    ends, and python-control's Padé poles cross at the upper one."""
    lag, tau, kd = 0.1, 0.3, 1.2
    lo, hi = reflex.critical_gains(1.0, 0.0, 1.0, kd, tau, lag=lag)
    grid = np.linspace(0.5, 4.0, 7001)
    stable = grid[reflex.stable_at_delay(1.0, 0.0, 1.0, grid, kd, tau, lag)]
    assert stable.min() == pytest.approx(lo, abs=1e-3) and stable.max() == pytest.approx(hi, abs=1e-3)
    assert lo == pytest.approx(1.0)  # kp = S: a root at s = 0 whatever the delay and lag
    poles = [loops.closed_loop(1.0, 0.0, 1.0, f * hi, kd, tau, 12, lag=lag).poles().real.max() for f in (0.999, 1.001)]
    assert poles[0] < 0 < poles[1]


def test_the_rule_does_not_cancel_the_lag():
    """The rule's gains are the lag-free segment's whatever T_a (the lag acts after the reflex); before, kd gained
    kp T_a, and where the damping part was 0 the reflex kp (T_a s + 1) cancelled the lag exactly."""
    s, d, theta = 50.0, -20.0, 2.0  # 2 sqrt(theta (kp - S)) = 14.1 < |D|: the rule's damping part is 0
    kp0, kd0 = reflex.default_gains(s, d, theta, 1.5, 1.0)
    assert kp0 == 75.0 and kd0 == 0.0
    for lag in (0.05, 0.1):  # the landscape resolves the rule's gains beside the lag: the same gains
        grid = reflex.landscape(s, d, theta, Reflex(activation_time_constant=lag))
        assert grid.kp == kp0 and grid.kd == kd0


def test_the_margins_at_the_default_operating_point_change_with_the_lag():
    """``spinectl margins`` at its defaults (wagner2012, (0, 0), activation 0.5): L1L2's margin falls as T_a grows
    (identical for T_a = 0, 0.05, 0.1 s before), and equals the first delay of the crossing found by a scalar
    bisection of |P(jw)| = |Q(jw)| (a second method) with the lagged plant."""
    from spinectl.model import config
    from spinectl.reflex import margins

    found = []
    for lag in (0.0, 0.05, 0.1):
        model = config.set_parameters(config.load_preset("wagner2012"), {"reflex.activation_time_constant": lag})
        seg = margins.margins_report(model, 0.0, 0.0).segments[0]
        tau, _ = _crossing_by_bisection(seg.stiffness, seg.damping, seg.inertia, seg.kp, seg.kd, lag)
        assert seg.delay_margin == pytest.approx(tau, rel=1e-9)
        found.append(seg.delay_margin)
    assert found[0] > found[1] > found[2]


def test_landscape_with_the_lag_is_the_pointwise_answer(rng):
    shape = (4, 5)
    s, d, theta = rng.uniform(-40, 120, shape), -rng.uniform(0, 30, shape), rng.uniform(1, 4, shape)
    settings = Reflex(activation_time_constant=0.08)
    grid = reflex.landscape(s, d, theta, settings)
    kp, kd = reflex.default_gains(s, d, theta, 1.5, 1.0)
    exact = reflex.delay_margin(s, d, theta, kp, kd, 0.08)
    assert np.array_equal(grid.delay_margin, exact.margin) and np.array_equal(grid.kd, kd)
    assert np.array_equal(grid.stable_at_delay, reflex.stable_at_delay(s, d, theta, kp, kd, settings.delay, 0.08))
    lag_free = reflex.landscape(s, d, theta, Reflex(activation_time_constant=0.0))
    needs_reflex = np.isfinite(lag_free.delay_margin) & (lag_free.delay_margin > 0)
    same_gains = reflex.delay_margin(s, d, theta, lag_free.kp, lag_free.kd, 0.08).margin
    assert np.all(same_gains[needs_reflex] < lag_free.delay_margin[needs_reflex])  # the lag costs delay


def test_critical_gains_without_delay_are_the_hurwitz_range_of_the_lagged_cubic():
    """tau = 0 with T_a = 0.05 s (the default lag): the delay-free loop's characteristic polynomial
    T_a theta s^3 + (theta - T_a D) s^2 + (kd - D - T_a S) s + (kp - S) is stable for kp in
    (S, S + (theta - T_a D)(kd - D - T_a S) / (T_a theta)) (Routh-Hurwitz, closed form), about 381 N m/rad
    for L4L5 of ``spinectl margins --E 0.03 --Lambda 0.04`` (S, D, theta, kd as that table prints them);
    numpy's roots of the cubic cross the axis there (a second method). Before, the search ran at a
    stand-in delay of 1 s and returned its range, [9.8, 15.0]."""
    s, d, theta, kd, lag = 9.79, -13.65, 2.038, 0.73, 0.05
    high = s + (theta - lag * d) * (kd - d - lag * s) / (lag * theta)
    lo, hi = reflex.critical_gains(s, d, theta, kd, 0.0, lag=lag)
    assert lo == pytest.approx(s, rel=1e-12) and hi == pytest.approx(high, rel=1e-12) and 380 < hi < 382

    def largest_real_part(kp):
        return np.roots([lag * theta, theta - lag * d, kd - d - lag * s, kp - s]).real.max()

    assert largest_real_part(0.999 * hi) < 0 < largest_real_part(1.001 * hi)
    assert largest_real_part(s + 0.01) < 0 < largest_real_part(s - 0.01)


def test_critical_gains_without_delay_and_without_a_stabilising_gain_are_nan():
    """tau = 0, T_a = 0.05 s and kd - D - T_a S <= 0: the coefficient of s in the cubic is not positive for any kp,
    so no kp stabilises (Routh-Hurwitz): NaN, NaN, as the exact root count says at a few gains."""
    s, d, theta, lag = 100.0, -1.0, 1.0, 0.05
    kd = 3.0  # kd - D - T_a S = 3 + 1 - 5 < 0
    assert np.isnan(reflex.critical_gains(s, d, theta, kd, 0.0, lag=lag)).all()
    assert not reflex.stable_at_delay(s, d, theta, np.array([101.0, 150.0, 1e3]), kd, 0.0, lag).any()
