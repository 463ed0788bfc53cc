"""spinectl.loop_delay_margin(loop): the exact delay margin of any SISO loop, against a published value,
closed forms and the segment's own closed form."""

from __future__ import annotations

import re

import control as ct
import numpy as np
import pytest

import spinectl
from spinectl import reflex
from spinectl.errors import ParameterError


def test_published_example():
    """MATLAB's allmargin documentation example: L = 25/(s^3 + 10 s^2 + 10 s + 10) has a delay margin of
    0.2847 s. Independently here: |D(jw)| = 25 solved by a scalar bisection, tau = arg(-L(jw))/w, and
    python-control's order-10 Padé closed loop turning unstable there."""
    result = spinectl.loop_delay_margin(ct.tf([25], [1, 10, 10, 10]))
    assert result.status == "finite" and result.margin == pytest.approx(0.2847, abs=5e-5)

    def den(w):
        return (1j * w) ** 3 + 10 * (1j * w) ** 2 + 10j * w + 10

    lo, hi = 0.1, 10.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if abs(den(mid)) < 25 else (lo, mid)
    w = 0.5 * (lo + hi)
    tau = np.mod(np.angle(-25 / den(w)), 2 * np.pi) / w
    assert result.margin == pytest.approx(tau, rel=1e-12) and result.frequency == pytest.approx(w, rel=1e-12)
    for f, sign in ((0.999, -1), (1.001, 1)):
        closed = ct.feedback(ct.tf([25], [1, 10, 10, 10]) * ct.tf(*ct.pade(f * tau, 10)))
        assert np.sign(closed.poles().real.max()) == sign


def test_state_space_is_the_same_loop():
    loop = ct.tf([25], [1, 10, 10, 10])
    assert spinectl.loop_delay_margin(ct.ss(loop)).margin == pytest.approx(
        spinectl.loop_delay_margin(loop).margin, rel=1e-12
    )


def test_agrees_with_the_segments_closed_form(rng):
    """Random segments, with and without the activation lag, as L = (kd s + kp)/((T_a s + 1)(theta s^2 - D s - S)):
    the general margin and the segment's closed form agree to 1e-9, status for status."""
    for _ in range(60):
        s, d, theta = rng.uniform(-50, 150), -rng.uniform(0, 30), rng.uniform(0.5, 5)
        lag = rng.choice([0.0, rng.uniform(0.01, 0.2)])
        kp, kd = reflex.default_gains(s, d, theta, rng.uniform(1.1, 3), rng.uniform(0.3, 2))
        segment = reflex.delay_margin(s, d, theta, kp, kd, lag)
        general = spinectl.loop_delay_margin(ct.tf([float(kd), float(kp)], np.polymul([lag, 1], [theta, -d, -s])))
        assert general.status == reflex.STATUS[int(segment.status)]
        if np.isfinite(general.margin) and general.margin > 0:
            assert general.margin == pytest.approx(float(segment.margin), rel=1e-9)
        else:
            assert general.margin == segment.margin


def test_integrator_and_its_critical_delays():
    """L = 1/s: s + e^{-s tau} = 0 crosses at w = 1 for tau = pi/2 + 2 pi k, always destabilising."""
    result = spinectl.loop_delay_margin(ct.tf([1], [1, 0]))
    assert result.margin == pytest.approx(np.pi / 2, rel=1e-12) and result.frequency == pytest.approx(1.0)
    delays = result.critical_delays(10.0)
    np.testing.assert_allclose([t for t, _, _ in delays], [np.pi / 2, 5 * np.pi / 2], rtol=1e-12)
    assert [d for _, _, d in delays] == [1, 1]
    text = str(result)
    assert text.startswith("delay margin 1.5708 s at 1 rad/s (finite)") and "destabilising" in text


def test_statuses():
    """|L| < 1 everywhere: any delay; an unstable closed loop without delay: 0; a zero loop: the plant alone."""
    assert spinectl.loop_delay_margin(ct.tf([0.5], [1, 1])).status == "delay_independent"
    unstable = spinectl.loop_delay_margin(ct.tf([0.5], [1, -1]))  # s - 1 + 0.5: a root at 0.5
    assert unstable.margin == 0.0 and unstable.status == "unstable_without_delay"
    assert spinectl.loop_delay_margin(ct.tf([0], [1, 1])).margin == np.inf
    doc = spinectl.loop_delay_margin(ct.tf([2], [1, 1])).to_dict()  # w_c = sqrt(3), margin (pi - atan(sqrt 3))/sqrt 3
    assert doc["delay_margin_s"] == pytest.approx((np.pi - np.arctan(np.sqrt(3))) / np.sqrt(3), rel=1e-12)
    assert doc["crossovers"][0]["direction"] == 1


def test_biproper_loop_with_a_small_high_frequency_gain():
    """L = 0.5 (s + 4)/(s + 1): neutral type with |L(inf)| = 0.5 < 1, covered. |L(jw)| = 1 where
    0.25 (w^2 + 16) = w^2 + 1, i.e. w = 2; the margin is arg(-L(2j))/2."""
    result = spinectl.loop_delay_margin(ct.tf([0.5, 2.0], [1, 1]))
    w = 2.0
    expected = np.mod(np.angle(-0.5 * (1j * w + 4) / (1j * w + 1)), 2 * np.pi) / w
    assert result.margin == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize(
    "loop",
    [
        ct.tf([1, 0, 0], [1, 1]),  # improper
        ct.tf([2, 1], [1, 1]),  # biproper, |L(inf)| = 2
        ct.tf([1], [1, 1], dt=0.1),  # discrete-time
        ct.tf([[[1], [1]]], [[[1, 1], [1, 2]]]),  # two inputs
        "1/(s+1)",
    ],
)
def test_what_the_theory_does_not_cover_is_refused_naming_the_loop(loop):
    with pytest.raises(ParameterError) as info:
        spinectl.loop_delay_margin(loop)
    assert info.value.field == "loop" and "\n" not in str(info.value)


def test_uniformly_huge_coefficients_are_scaled_and_computed():
    """L = 2e300 / (1e300 (s^2 + s + 1)) is L = 2 / (s^2 + s + 1): the same margin, not a LinAlgError.

    Closed form for k / (s^2 + s + 1), k = 2: abs(D(jw)) = k gives w^4 - w^2 - 3 = 0, w^2 = (1 + sqrt 13) / 2;
    the margin is arg(-L(jw)) / w with arg(-L) = pi - arg(1 - w^2 + j w).
    """

    w = np.sqrt((1.0 + np.sqrt(13.0)) / 2.0)
    expected = (np.pi - np.angle(1.0 - w**2 + 1j * w)) / w
    huge = spinectl.loop_delay_margin(ct.tf([2e300], [1e300, 1e300, 1e300]))
    assert huge.status == "finite" and huge.margin == pytest.approx(expected, rel=1e-12)
    assert huge.frequency == pytest.approx(w, rel=1e-12)


@pytest.mark.parametrize(
    ("num", "den", "needle"),
    [
        ([1e300], [1.0, 1e300, 1e300], "a span over 1e+100"),  # before: LinAlgError (F overflowed)
        ([1e200], [1.0, 1.0, 1.0], "a span over 1e+100"),  # before: LinAlgError
        ([1.0], [1e300, 2.0, 3.0], "a span over 1e+100"),  # before: "unstable_without_delay" for a stable loop
        ([1.0 + 1.0j], [1.0, 2.0, 3.0], "must have real coefficients"),  # before: TypeError or a wrong margin
    ],
)
def test_absurd_or_complex_coefficients_are_one_parameter_error(num, den, needle):

    loop = ct.tf([1.0], den)
    loop.num_array[0][0] = np.asarray(num)  # python-control's tf() refuses complex: as a computed loop may hold
    with pytest.raises(ParameterError, match=re.escape(needle)) as info:
        spinectl.loop_delay_margin(loop)
    assert isinstance(info.value, ValueError) and info.value.field == "loop" and "\n" not in str(info.value)
