"""The closed-form roots of the crossing cubic and the Newton inverse of the Padé lag against the forms they
replaced (the companion matrix's eigenvalues, a 60-step bisection), on the paper's grid, on random inputs and
at the degenerate points; and against roots and lags known in closed form."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from spinectl import reflex
from spinectl.model import config
from spinectl.model.checks import checked_coefficients
from spinectl.optimise import active_set
from spinectl.optimise.problem import problem_data
from spinectl.reflex import delay, pade
from spinectl.reflex.gains import resolve_gains

EPS = np.finfo(float).eps


@pytest.fixture(scope="module")
def grid_segments():
    """S, D, theta, kp, kd and T_a of every segment of the default model's 21 x 21 grid (E, Lambda in
    [0, 8] cm) at the reflex's activation of the chosen optimum: what the sweep's reflex columns see."""
    model = config.load_preset(config.DEFAULT_PRESET)
    axis = np.linspace(0.0, 0.08, 21)
    e, lam = (x.ravel() for x in np.meshgrid(axis, axis, indexing="ij"))
    coeffs = checked_coefficients(model, e, lam)
    optimum = active_set.solve_block(problem_data(model, coeffs), model.optimisation.ct_tolerance)
    active = model.reflex.activation * optimum.pcsa
    s, d, theta = delay.as_arrays(coeffs.stiffness(active), coeffs.damping(active), coeffs.inertia)
    kp, kd = resolve_gains(s, d, theta, model.reflex)
    return s, d, theta, kp, kd, np.full(s.shape, model.reflex.activation_time_constant), model.reflex


def _sorted(x):
    return np.sort(np.where(np.isnan(x), np.inf, x), axis=-1)


def _rounding(x, f):
    """What rounding allows a root x of a backward-stable finder: 16 eps ||f|| sum |x|^k / |F'(x)|, with ||f||
    the largest coefficient (the companion matrix's eigenvalues are stable in that norm); 0 for an exact root at
    0 of a cubic without f1 and f0, inf at a double root (the flags are compared there)."""
    f3, f2, f1, f0 = (c[..., None] for c in f)
    norm = np.maximum(np.maximum(abs(f3), abs(f2)), np.maximum(abs(f1), abs(f0)))
    scale = norm * (((abs(x) + 1) * abs(x) + 1) * abs(x) + 1)
    slope = abs((3 * f3 * x + 2 * f2) * x + f1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.nan_to_num(16 * EPS * scale / slope, nan=0.0, posinf=np.inf)


def _assert_same_roots(new, old, f, rtol=1e-12):
    """Same real roots (as sets), same double-root flags; values to ``rtol`` relative, or to the rounding of
    any backward-stable root finder (:func:`_rounding`) where the root is ill-conditioned."""
    (x_new, twin_new), (x_old, twin_old) = new, old
    a, b = _sorted(x_new), _sorted(x_old)
    assert np.array_equal(np.isfinite(a), np.isfinite(b))
    assert np.array_equal(np.sort(twin_new, axis=-1), np.sort(twin_old, axis=-1))
    x = np.where(np.isfinite(b), b, 0.0)
    with np.errstate(invalid="ignore"):
        assert np.all(np.where(np.isfinite(b), abs(a - b) <= rtol * abs(x) + _rounding(x, f), True))


# --- the cubic ------------------------------------------------------------------------------------------


def test_cubic_roots_on_the_papers_grid_equal_the_companion_matrix(grid_segments):
    """Every crossing polynomial of the grid (one cubic per segment and point): the same real roots to 1e-12."""
    s, d, theta, kp, kd, lag, _ = grid_segments
    f = delay.crossing_polynomial(s, d, theta, kp, kd, lag)
    assert np.all(f[0] != 0)
    new, old = delay._cubic_roots(*f), delay._cubic_roots_companion(*f)
    _assert_same_roots(new, old, f, rtol=1e-12)
    a, b = _sorted(new[0]), _sorted(old[0])
    finite = np.isfinite(b)
    assert finite.sum() > s.size  # not a test of empty slots: more than a root per segment
    np.testing.assert_allclose(a[finite], b[finite], rtol=1e-12)  # and no rounding allowance needed


def _resolved(low, high):
    """Floats in [low, high] that are 0 or at least 1e-6 in modulus: the companion matrix resolves roots only to
    eps times its norm (it merged a root at -3e-242 with 0 for D = 1e-121), so tinier inputs test the reference."""
    return st.floats(low, high).filter(lambda v: v == 0 or abs(v) >= 1e-6)


segment = st.tuples(
    _resolved(-500, 500),  # S [N m/rad]
    _resolved(-60, 0),  # D [N m s/rad]
    st.floats(1e-3, 10),  # theta [kg m^2]
    _resolved(0, 1000),  # kp [N m/rad]
    _resolved(0, 100),  # kd [N m s/rad]
    st.floats(1e-4, 0.5),  # T_a [s]
)


def _separated(f, by=1e-4):
    """Whether the three roots (complex) are at least ``by`` apart relative to the larger: away from a double
    root, where the companion form's polish is a step of noise over a noisy slope (it moved an exact double
    root at -7.307 by 1.8e-7 and one at -0.36356 to -0.36981); double roots are tested against their
    closed form instead."""
    re, im = delay._cubic_candidates(*f)
    z = re + 1j * im
    apart = np.abs(z[..., :, None] - z[..., None, :])
    larger = np.maximum(np.abs(z[..., :, None]), np.abs(z[..., None, :]))
    gap = np.divide(apart, larger, out=np.zeros_like(apart), where=larger > 0)  # two roots at 0: not apart (was 0/0)
    return bool(np.all(gap[..., [0, 0, 1], [1, 2, 2]] >= by))


@settings(max_examples=300, deadline=None)
@given(segment)
@example((73.0, 0.0, 1.0, 73.0, 0.0, 0.09375))  # S = kp: f0 = 0, a root at 0 and a complex pair (found in CI)
def test_cubic_roots_of_random_segments_equal_the_companion_matrix(values):
    """Random lagged segments: the same roots, to 1e-12 or to the rounding of an ill-conditioned root."""
    f = delay.crossing_polynomial(*(np.array([v]) for v in values))
    if _separated(f):
        _assert_same_roots(delay._cubic_roots(*f), delay._cubic_roots_companion(*f), f)


@settings(max_examples=100, deadline=None)
@given(_resolved(-500, 500).filter(lambda v: v != 0), st.floats(1e-3, 10), st.floats(1e-4, 0.5))
def test_a_segment_without_damping_or_reflex_has_a_double_root(s, theta, lag):
    """D = kp = kd = 0: F(x) = (1 + T_a^2 x)(theta x + S)^2 (docs/reflex.md, "Crossing frequencies and the
    exact delay margin"), a double root at x = -S / theta: one root there within the tangency threshold
    (1e-7), flagged, and -1 / T_a^2; a tangency (direction 0) where it is positive."""
    f = delay.crossing_polynomial(*(np.array([v]) for v in (s, 0.0, theta, 0.0, 0.0, lag)))
    x, twins = delay._cubic_roots(*f)
    kept = x[0][np.isfinite(x[0])]
    double = kept[np.argmin(abs(kept + s / theta))]
    assert abs(double + s / theta) <= 1e-7 * abs(s / theta)
    assert kept.size == 2 and twins[0].sum() == 2  # the kept root of the pair and its dropped twin
    assert kept[np.argmin(abs(kept + 1 / lag**2))] == pytest.approx(-1 / lag**2, rel=1e-12)
    positive, direction = delay._positive_roots(*f)
    assert np.array_equal(np.isfinite(positive[0]), [s < 0, False, False])
    assert s > 0 or direction[0][0] == 0


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(-1e3, 1e3).filter(lambda v: abs(v) > 1e-3), min_size=4, max_size=4))
def test_cubic_roots_of_random_coefficients_equal_the_companion_matrix(coefficients):
    """Cubics of any signs: the same roots as the companion matrix."""
    f = tuple(np.array([c]) for c in coefficients)
    _assert_same_roots(delay._cubic_roots(*f), delay._cubic_roots_companion(*f), f)


@settings(max_examples=200, deadline=None)
@given(
    st.lists(st.integers(-2000, 2000), min_size=3, max_size=3, unique=True),
    st.integers(1, 64),
    st.integers(-8, 8),
)
def test_cubic_roots_are_the_known_roots(roots, lead, shift):
    """f3 (x - r1)(x - r2)(x - r3) with integer roots scaled by 2^shift: every coefficient is exact in
    floating point, so the roots are known exactly; found to the rounding of evaluating F near them,
    16 eps sum |f_k x^k| / |F'(x)| (two close roots are ill-conditioned even with exact coefficients)."""
    r = np.sort(np.array(roots, float) * 2.0**shift)
    f = tuple(np.array([c]) for c in lead * np.poly(r))
    x, twins = delay._cubic_roots(*f)
    assert not twins.any()
    f3, f2, f1, f0 = (c[0] for c in f)
    scale = ((abs(f3) * abs(r) + abs(f2)) * abs(r) + abs(f1)) * abs(r) + abs(f0)
    slope = abs((3 * f3 * r + 2 * f2) * r + f1)
    assert np.all(abs(np.sort(x[0]) - r) <= 16 * EPS * scale / slope)


@pytest.mark.parametrize(
    ("double", "single"),
    [(3.0, 7.0), (7.0, 3.0), (5.0, -2.0), (0.25, 1024.0), (1024.0, 0.25), (2.0, 0.0)],
)
def test_double_roots_are_one_tangency(double, single):
    """2 (x - r)^2 (x - s), coefficients exact: one root r flagged as a double root (a tangency, direction 0
    in the crossings) and s, by both methods; the closed form puts r within 1e-7 (the tangency threshold)."""
    f = tuple(np.array([c]) for c in 2.0 * np.poly([double, double, single]))
    for x, twins in (delay._cubic_roots(*f), delay._cubic_roots_companion(*f)):
        kept = x[0][np.isfinite(x[0])]
        assert kept.size == 2
        assert np.sum(twins[0] & np.isfinite(x[0])) == 1
        near = kept[np.argmin(abs(kept - double))]
        assert abs(near - double) <= 1e-7 * abs(double)
        assert kept[np.argmin(abs(kept - single))] == pytest.approx(single, abs=1e-12 * abs(double))
    positive, direction = delay._positive_roots(*f)
    assert direction[0][np.isclose(positive[0], double, rtol=1e-7)] == 0


@pytest.mark.parametrize("delta", [0.0, 1e-7, 1e-6])
def test_a_nearly_double_pair_is_one_tangency(delta):
    """((x - 64)^2 + delta^2)(x + 1): a complex pair within 1e-7 of its modulus (and an exact double root) is one
    double root for both methods, at 64 to 1e-7 for the closed form. The companion form's polish moved the
    exact double root of (x - 4)^2 (x + 1) to 4.087 (a step of noise over a noisy slope): its flags only."""
    f = tuple(np.array([c]) for c in np.polymul([1.0, -128.0, 4096.0 + delta**2], [1.0, 1.0]))
    for method in (delay._cubic_roots, delay._cubic_roots_companion):
        x, twins = method(*f)
        kept = np.sort(x[0][np.isfinite(x[0])])
        assert kept.size == 2 and kept[0] == pytest.approx(-1.0, rel=1e-12)
        assert twins[0][np.isfinite(x[0])].sum() == 1
    x, _ = delay._cubic_roots(*f)
    assert np.nanmax(x) == pytest.approx(64.0, rel=1e-7)
    four, _ = delay._cubic_roots(*(np.array([c]) for c in (1.0, -7.0, 8.0, 16.0)))
    assert np.nanmax(four) == pytest.approx(4.0, rel=1e-7)


def test_no_real_positive_root_is_no_crossing():
    """x^3 + x^2 + x + 1 = (x + 1)(x^2 + 1) and F with positive coefficients: no crossing; a strong
    self-stable segment without reflex is delay-independent (margin inf) for both methods."""
    f = tuple(np.array([c]) for c in (1.0, 1.0, 1.0, 1.0))
    x, _ = delay._positive_roots(*f)
    assert np.all(np.isnan(x))
    margin = reflex.delay_margin(-100.0, -10.0, 1.0, 0.0, 0.0, 0.05)
    assert margin.margin == np.inf and margin.status_names == "delay_independent"
    assert reflex.pade_delay_margin(-100.0, -10.0, 1.0, 0.0, 0.0, 5, 0.05).margin == np.inf


def test_a_vanishing_leading_coefficient_tends_to_the_quadratic():
    """T_a -> 0: the cubic's leading coefficient T_a^2 theta^2 vanishes, one root runs to -inf (not a crossing)
    and the positive ones tend to the quadratic's (T_a = 0 exactly) with an error of order T_a^2 x."""
    args = (99.7, -3.0, 2.6, 150.0, 25.0)
    x0, _ = delay._positive_roots(*delay.crossing_polynomial(*args, 0.0))
    for lag in (1e-6, 1e-9, 1e-12):
        f = delay.crossing_polynomial(*args, lag)
        assert 0 < f[0] < 1e-10
        x, _ = delay._positive_roots(*f)
        finite = np.isfinite(x0)
        assert np.array_equal(np.isfinite(x), finite)
        np.testing.assert_allclose(x[finite], x0[finite], rtol=10 * lag**2 * np.nanmax(x0) + 1e-14)


def test_nan_coefficients_give_no_root_and_an_undefined_margin():
    """A NaN anywhere: no root (the companion form returned roots of a zeroed matrix), and every public
    answer is NaN with status 'undefined', as before."""
    for i in range(4):
        f = [np.array([1.0]), np.array([-2.0]), np.array([-5.0]), np.array([6.0])]
        f[i] = np.array([np.nan])
        x, twins = delay._cubic_roots(*f)
        assert np.all(np.isnan(x)) and not twins.any()
    args = [99.7, -3.0, 2.6, 150.0, 25.0, 0.05]
    for i in range(6):
        values = list(args)
        values[i] = np.nan
        m = reflex.delay_margin(*values)
        assert np.isnan(m.margin) and m.status_names == "undefined"
        assert np.isnan(reflex.pade_delay_margin(*values[:5], 5, values[5]).margin)


# --- the Padé lag -----------------------------------------------------------------------------------


def _bisection_resolution(y, order):
    """The bisection's own resolution in y: a float step of u = (2/pi) atan(y) (at most 2^-53), mapped to y,
    plus the rounding of the lag's n arctangents over its slope; 1e-12 relative is asked for beyond it."""
    r = pade._roots(order)
    z = (y[..., None] - r.imag) / -r.real
    slope = 2.0 * np.sum(1.0 / (-r.real * (1.0 + z * z)), axis=-1)
    return 0.5 * np.pi * (1.0 + y * y) * 2.0**-53 + 8 * EPS * np.pi * order / slope


def test_inverse_lag_on_the_papers_grid_equals_the_bisection(grid_segments):
    """The phases of every crossing of the grid, at the default order: Newton = bisection to 1e-12."""
    s, d, theta, kp, kd, lag, settings_ = grid_segments
    phase = reflex.crossings(s, d, theta, kp, kd, lag).phase
    assert np.isfinite(phase).sum() > s.size // 2
    new = reflex.pade_inverse_lag(phase, settings_.pade_order)
    old = pade._inverse_lag_bisection(phase, settings_.pade_order)
    assert np.array_equal(np.isinf(new), np.isinf(old))
    finite = np.isfinite(old)
    np.testing.assert_allclose(new[finite], old[finite], rtol=1e-12)


@settings(max_examples=300, deadline=None)
@given(st.integers(1, 10), st.floats(0, 1, exclude_max=True))
def test_inverse_lag_of_random_phases_equals_the_bisection_and_is_a_root(order, fraction):
    """phase in [0, n pi): Newton = bisection to 1e-12 relative, or to the bisection's resolution where that is
    coarser (y beyond about 1e3, or tiny y); and the lag at Newton's y is the phase to rounding."""
    phase = np.array([fraction * order * np.pi])
    new = reflex.pade_inverse_lag(phase, order)
    old = pade._inverse_lag_bisection(phase, order)
    if np.isinf(old[0]):  # the phase rounds to n pi: out of reach for both
        assert np.isinf(new[0])
        return
    assert abs(new[0] - old[0]) <= 1e-12 * old[0] + _bisection_resolution(old, order)[0]
    assert abs(reflex.pade_phase_lag(new, order)[0] - phase[0]) <= 16 * EPS * order * np.pi


@pytest.mark.parametrize("phase", [1e-6, 0.1, 0.5, 1.0, 2.0, 3.0, np.pi - 1e-6])
def test_inverse_lag_of_order_two_in_closed_form(phase):
    """n = 2: q = 1 + x/2 + x^2/12, so lag(y) = 2 atan2(y/2, 1 - y^2/12) = phi for phi < pi means
    (t / 12) y^2 + y / 2 - t = 0 with t = tan(phi/2): y = 2 t / (1/2 + sqrt(1/4 + t^2 / 3)) (derived here)."""
    t = np.tan(phase / 2)
    expected = 2 * t / (0.5 + np.sqrt(0.25 + t * t / 3))
    assert reflex.pade_inverse_lag(phase, 2) == pytest.approx(expected, rel=1e-13)


def test_inverse_lag_edges():
    """phase 0, and a negative phase (no y >= 0 reaches it): y = 0 exactly (the bisection returned 7e-19);
    phase >= n pi and NaN (an empty slot): inf, as before."""
    phase = np.array([0.0, -0.5, 5 * np.pi, 6 * np.pi, np.nan])
    np.testing.assert_array_equal(reflex.pade_inverse_lag(phase, 5), [0.0, 0.0, np.inf, np.inf, np.inf])
    old = pade._inverse_lag_bisection(phase, 5)
    assert np.all(old[:2] < 1e-18)
    np.testing.assert_array_equal(old[2:], [np.inf, np.inf, np.inf])


# --- the whole reflex landscape ------------------------------------------------------------------


@pytest.fixture
def reference_paths(monkeypatch):
    """Switch the reflex functions to the companion matrix and the bisection."""

    def use():
        monkeypatch.setattr(delay.frequencies, "_cubic_roots", delay._cubic_roots_companion)
        monkeypatch.setattr(pade, "pade_inverse_lag", pade._inverse_lag_bisection)

    return use


def _assert_same_landscape(new, old, frequency):
    """Statuses, gains and verdicts identical; margins and frequencies to 1e-12, the Padé margin y / w also to
    the bisection's resolution in y, the rounding of the lag (8 eps n pi, n = 5), over the slowest crossing
    ``frequency`` of the point: it shows at tiny margins (seen: 1e-11 relative at 2.2e-6 s)."""
    for name in ("kp", "kd", "delay_margin_status", "stable_at_delay"):
        assert np.array_equal(getattr(new, name), getattr(old, name), equal_nan=True), name
    resolution = {"delay_margin_pade": 8 * EPS * 5 * np.pi / frequency}
    for name in ("delay_margin", "crossing_frequency", "delay_margin_pade"):
        a, b = getattr(new, name), getattr(old, name)
        finite = np.isfinite(b)
        assert np.array_equal(np.isfinite(a), finite), name
        assert np.array_equal(a[~finite], b[~finite], equal_nan=True), name
        allowed = 1e-12 * abs(b[finite]) + resolution.get(name, np.zeros(b.shape))[finite]
        assert np.all(abs(a[finite] - b[finite]) <= allowed), name


def test_landscape_on_the_papers_grid_equals_the_reference_paths(grid_segments, reference_paths):
    """maps.landscape, every column: statuses and verdicts identical, margins and frequencies to 1e-12."""
    s, d, theta, kp, kd, lag, settings_ = grid_segments
    new = reflex.landscape(s, d, theta, settings_)
    reference_paths()
    _assert_same_landscape(new, reflex.landscape(s, d, theta, settings_), _slowest(s, d, theta, kp, kd, lag))


def _slowest(*args):
    """The smallest crossing frequency of each point [rad/s] (inf without one)."""
    frequency = reflex.crossings(*args).frequency
    return np.min(np.where(np.isnan(frequency), np.inf, frequency), axis=-1)


GAINS = ({}, {"kp": 0.0, "kd": 0.0}, {"kp": 200.0, "kd": 20.0})
"""The rule's gains, no reflex (every point delay-independent or unstable), and fixed gains."""


def test_landscape_of_random_segments_equals_the_reference_paths(rng, reference_paths):
    """Random segments, lags and gains (with NaN points, gains 0 and a tiny lag): the same answers."""
    n = 2000
    s, d, theta = rng.uniform(-300, 300, n), -rng.uniform(0, 40, n), rng.uniform(0.01, 5, n)
    s[:20] = np.nan
    settings_ = config.load_preset(config.DEFAULT_PRESET).reflex
    cases = [(replace(settings_, activation_time_constant=lag), gains) for lag in (0.05, 0.2, 1e-7) for gains in GAINS]
    new = [reflex.landscape(s, d, theta, r, **gains) for r, gains in cases]
    reference_paths()
    for answer, (r, gains) in zip(new, cases, strict=True):
        slowest = _slowest(s, d, theta, answer.kp, answer.kd, r.activation_time_constant)
        _assert_same_landscape(answer, reflex.landscape(s, d, theta, r, **gains), slowest)
