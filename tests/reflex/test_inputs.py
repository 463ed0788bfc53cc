"""The public reflex functions refuse nonsense by name, and still answer NaN for NaN."""

from __future__ import annotations

import numpy as np
import pytest

from spinectl import reflex
from spinectl.errors import ParameterError
from spinectl.reflex import loops
from spinectl.reflex.inputs import MAX_MAGNITUDE, guarded

S, D, THETA, KP, KD = 5.0, -10.0, 0.5, 20.0, 3.0
"""An unstable segment with a stabilising reflex (kp > S, kd > D): a finite delay margin."""


@pytest.mark.parametrize(
    ("call", "field"),
    [
        (lambda: reflex.delay_margin(S, D, -0.5, KP, KD), "inertia"),
        (lambda: reflex.delay_margin(S, D, 0.0, KP, KD), "kd"),  # theta = 0 with kd != 0 and no lag: neutral type
        (lambda: reflex.critical_gains(S, D, [0.5, -1.0], KD, 0.1), "inertia"),
        (lambda: reflex.delay_margin(S, D, THETA, 1e200, KD), "kp"),  # kp^2 overflows in F(w^2)
        (lambda: reflex.phase_margin(S, D, THETA, KP, np.inf, 0.1), "kd"),
        (lambda: reflex.default_gains(S, D, -1.0, 1.5, 1.0), "inertia"),
        (lambda: reflex.landscape(S, D, 0.0, None), "inertia"),
        (lambda: reflex.pade_delay_margin(S, D, THETA, KP, KD, 0), "order"),
        (lambda: reflex.pade_delay_margin(S, D, THETA, KP, KD, -2), "order"),
        (lambda: reflex.pade_convergence(S, D, THETA, KP, KD, [1, 0]), "orders"),
        (lambda: loops.closed_loop(S, D, THETA, KP, KD, 0.1, 0), "order"),
        (lambda: reflex.stable_at_delay(S, D, THETA, KP, KD, -0.1), "delay"),
        (lambda: reflex.phase_margin(S, D, THETA, KP, KD, -0.1), "delay"),
        (lambda: loops.pade_delay(-0.1, 3), "delay"),
        (lambda: reflex.delay_margin("a", D, THETA, KP, KD), "stiffness"),
        # a bool or a text where a number belongs: numpy would read True as 1 and '200' as 200
        (lambda: reflex.delay_margin(S, D, THETA, True, KD), "kp"),
        (lambda: reflex.delay_margin(S, D, THETA, "200", KD), "kp"),
        (lambda: reflex.delay_margin(S, D, THETA, KP, [3.0, "1"]), "kd"),
        (lambda: reflex.critical_gains(S, D, THETA, np.bool_(True), 0.1), "kd"),
        (lambda: reflex.delay_margin(S, D, THETA, 1 + 2j, KD), "kp"),  # complex: numpy drops the imaginary part
        (lambda: reflex.delay_margin(S, D, THETA, None, KD), "kp"),  # None: read as NaN, a silent "undefined"
        (lambda: reflex.stable_at_delay(S, D, THETA, KP, KD, "0.1"), "delay"),
    ],
)
def test_nonsense_is_refused_by_name(call, field):
    """Before: every call above returned a confident margin (e.g. 1.117 s for theta = -0.5, inf for kp = 1e200)."""
    with pytest.raises(ParameterError) as info:
        call()
    assert info.value.field == field and "\n" not in str(info.value)


def test_limits_and_nan_stay_answers():
    """NaN inputs (an infeasible point) give status 'undefined'; theta = 0 with kd = 0 is the first-order
    loop of the textbooks (tests/reflex/test_delay.py); magnitudes up to float_max ** 0.25 are accepted."""
    assert reflex.STATUS[int(reflex.delay_margin(np.nan, D, THETA, KP, KD).status)] == "undefined"
    assert np.isfinite(reflex.delay_margin(-1.0, -1.0, 0.0, 2.0, 0.0).margin)
    assert MAX_MAGNITUDE == pytest.approx(1.157920892373162e77)  # (2 - 2^-52) 2^1023, fourth root
    reflex.delay_margin(S, D, THETA, MAX_MAGNITUDE, KD)
    kp_min, _ = reflex.critical_gains(-100.0, -1.0, 1.0, 0.0, 0.1)  # probes kp = inf inside: not refused
    assert np.isfinite(kp_min)


def test_library_callers_under_their_own_guard_are_not_checked_again():
    """A sweep's reflex columns run under arithmetic_guard (its message names the grid); inside
    ``guarded()`` a magnitude beyond MAX_MAGNITUDE reaches the arithmetic, as it did before."""
    with guarded():
        reflex.delay_margin(S, D, THETA, 1e100, KD)
    with pytest.raises(ParameterError):
        reflex.delay_margin(S, D, THETA, 1e100, KD)


@pytest.mark.parametrize(
    ("gains", "field"),
    [({"kp": -3.0}, "reflex.kp"), ({"kd": -0.5}, "reflex.kd"), ({"kp": True}, "reflex.kp"), ({"kd": "2"}, "reflex.kd")],
)
def test_margins_report_refuses_negative_or_non_numeric_gains_itself(gains, field):
    """The library's ``margins_report`` checks the gains it is given as the model's ``reflex.kp``/``kd`` are
    checked (before: only the CLI did, through a discarded ``set_parameter``; the library gave margins)."""
    from spinectl.model.config import load_config
    from spinectl.reflex.margins import margins_report

    with pytest.raises(ParameterError) as info:
        margins_report(load_config(None, preset="wagner2012"), 0.0, 0.0, **gains)
    assert info.value.field == field
