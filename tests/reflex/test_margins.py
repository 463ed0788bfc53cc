"""Per-segment reflex margins at one configuration: activation levels, explicit gains, infeasibility."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from spinectl import reflex
from spinectl.model.mechanics import segment_coefficients
from spinectl.model.params import Optimisation
from spinectl.reflex import margins

E, LAMBDA = 0.03, 0.04


def _with_reflex(model, **changes):
    return model.replace(reflex=dataclasses.replace(model.reflex, **changes))


def test_activation_one_is_self_stable_and_needs_no_reflex(model):
    """At the minimum stabilising PCSA every segment has S <= -margin < 0: the rule gives kp = 0, and
    the muscles' own damping exceeds the rule's target, so kd = 0 too: any delay is tolerated."""
    report = margins.analyse(_with_reflex(model, activation=1.0), E, LAMBDA)
    assert report.point.status == "optimal"
    for seg in report.segments:
        assert seg.self_stable and seg.kp == 0 and seg.kd == 0
        assert seg.delay_margin == np.inf and seg.delay_margin_status == "delay_independent"
        assert seg.stable_at_delay and seg.gain_margin_lower == 0 and seg.gain_margin == np.inf


def test_activation_zero_is_reflex_only(model):
    """No co-contraction: S = m g r_y (gravity alone) and D = 0 at every segment; the optimiser is skipped."""
    report = margins.analyse(_with_reflex(model, activation=0.0), E, LAMBDA)
    assert report.point.status == margins.SKIPPED and not report.point.pcsa.any()
    coeffs = segment_coefficients(model, E, LAMBDA)
    np.testing.assert_allclose([s.stiffness for s in report.segments], coeffs.gravity_stiffness)
    for seg in report.segments:
        assert not seg.self_stable and 0 < seg.delay_margin < np.inf
        assert seg.stable_at_delay == (model.reflex.delay < seg.delay_margin)
        assert seg.delay_margin_pade == pytest.approx(seg.delay_margin, rel=1e-6)  # order 5, w tau < 1
        # a segment that needs its reflex is open-loop unstable: the gain may fall to S / kp only
        assert seg.gain_margin_lower == pytest.approx(seg.stiffness / seg.kp)


def test_explicit_gains_replace_the_rule(model):
    report = margins.analyse(_with_reflex(model, activation=0.0), E, LAMBDA, kp=200.0)
    assert all(s.kp == 200.0 for s in report.segments)
    s = report.segments[2]
    assert s.kd == pytest.approx(float(reflex.default_gains(s.stiffness, 0.0, s.inertia, 1.5, 1.0)[1]))
    configured = margins.analyse(_with_reflex(model, activation=0.0, gains="explicit", kp=150.0, kd=20.0), E, LAMBDA)
    assert all((s.kp, s.kd) == (150.0, 20.0) for s in configured.segments)


def test_infeasible_optimum_is_an_answer_not_an_exception(model):
    """A PCSA bound far below what stability needs: solve_point is infeasible; every value is NaN."""
    tiny = model.replace(optimisation=Optimisation(pcsa_max=1e-8))
    report = margins.analyse(_with_reflex(tiny, activation=0.5), E, LAMBDA)
    assert report.point.status == "infeasible" and not report.point.ok
    for seg in report.segments:
        assert np.isnan(seg.stiffness) and np.isnan(seg.delay_margin) and seg.delay_margin_status == "undefined"
        assert not seg.stable_at_delay and seg.python_control is None


def test_python_control_overflow_leaves_the_exact_margins(model):
    """Padé order 10 at a 1 us delay: python-control's polynomial margins overflow (coefficients
    ~ (1/tau)^10); its reading is dropped (None, NaN gain margins), the exact analysis stands."""
    report = margins.analyse(_with_reflex(model, activation=0.0, delay=1e-6, pade_order=10), E, LAMBDA)
    for seg in report.segments:
        assert seg.python_control is None and np.isnan(seg.gain_margin)
        assert 0.1 < seg.delay_margin < 0.2 and seg.stable_at_delay
