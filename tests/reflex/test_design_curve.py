"""The design curve (spinectl.reflex.design.delay_curve): both criteria's required design against the delay."""

from __future__ import annotations

import numpy as np
import pytest

from spinectl.errors import ParameterError
from spinectl.model import config
from spinectl.reflex import design as dz

SUBJECT = {"body.mass": 35.0, "passive.stiffness": 10.0}
"""The 35 kg subject with K = 10 N m/rad of docs/reflex.md, "The design question", at E = 3 cm, Lambda = 4 cm."""


def _subject():
    return config.set_parameters(config.load_preset("wagner2012"), SUBJECT)


def test_the_curve_equals_the_single_design_at_each_delay():
    """A second method: spinectl.reflex.design.design (its own scan and bisection, no warm start) at each delay gives
    the curve's joint activations (each segment's and the common one) and the chain's least local stiffness, to the
    bisections' precision joint by joint (1e-5) and to 1e-4 of k* for the chain, whose set of designs that meet a
    delay is not an interval at the 1e-5 scale near k* (nearly undamped modes' narrow crossing bands), so two
    bisection paths may stop at different certified points; the curve's chain margin is at least each delay (the
    certificate)."""
    model = _subject()
    delays = [0.0, 0.04, 0.12]
    curve = dz.delay_curve(model, 0.03, 0.04, delays)
    for j, d in enumerate(delays):
        single = dz.design(config.set_parameters(model, {"reflex.delay": d}), 0.03, 0.04)
        assert curve.activation[0, j] == pytest.approx(single.activation, abs=1e-5)
        assert curve.segment_activation[0, j] == pytest.approx([s.activation for s in single.segments], abs=1e-5)
        assert curve.local_fraction[0, j] == pytest.approx(single.chain.fraction, abs=1e-4)
        assert curve.chain_margin[0, j] >= d


def test_the_required_design_does_not_fall_with_the_delay_and_rises_with_the_lag():
    """A design that meets a delay meets every shorter one, so both requirements are nondecreasing in the delay;
    a longer force-generation lag adds phase lag, so at 120 ms the joint-by-joint activation rises with T_a
    (0, 50, 100 ms), as the reflex default rule (no lag compensation) must let it."""
    curve = dz.delay_curve(_subject(), 0.03, 0.04, np.linspace(0.0, 0.2, 9), lags=[0.0, 0.05, 0.1])
    assert np.all(np.diff(curve.activation, axis=1) >= -1e-9)
    assert np.all(np.diff(curve.local_fraction, axis=1) >= -1e-9)
    at_120 = curve.activation[:, 4]
    assert at_120[0] < at_120[1] < at_120[2]


def test_a_delay_below_the_least_meets_it_and_the_activation_just_below_does_not():
    """At the curve's common activation every segment's exact margin (segment_margins_at, the joint criterion) is at
    least the delay, and 1e-4 less activation leaves one segment short: the answer is the least."""
    from spinectl.model.checks import checked_coefficients
    from spinectl.optimise.reference import solve_point

    model = _subject()
    curve = dz.delay_curve(model, 0.03, 0.04, [0.1])
    a = curve.activation[0, 0]
    coefficients = checked_coefficients(model, 0.03, 0.04)
    p = solve_point(model, 0.03, 0.04).pcsa
    assert np.all(dz.segment_margins_at(model, coefficients, p, [a])[0] >= 0.1)
    assert np.min(dz.segment_margins_at(model, coefficients, p, [a - 1e-4])[0]) < 0.1


@pytest.mark.parametrize(("delays", "lags", "field"), [([-0.1], None, "--delays"), ([0.1], [-1.0], "--lags")])
def test_a_negative_delay_or_lag_is_refused(delays, lags, field):
    """A delay or lag below 0: ParameterError naming the option."""
    with pytest.raises(ParameterError, match=field):
        dz.delay_curve(_subject(), 0.03, 0.04, delays, lags)
