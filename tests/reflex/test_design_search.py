"""The chain's search (spinectl.reflex.design.chain: chain_curve, _bracket_root): the least local stiffness per
delay by a safeguarded inverse interpolation of the exact margins on the bisection's grid, against a plain bisection
(the test oracle)."""

from __future__ import annotations

import numpy as np

from spinectl.model import config
from spinectl.model.operating_point import OperatingPoint, chain_at
from spinectl.optimise.coupled import least_local_stiffness_stacked
from spinectl.reflex import design as dz
from spinectl.reflex.chain_margins import stable_at
from spinectl.reflex.design import chain as dc
from spinectl.reflex.mimo import chain_delay_margin
from spinectl.reflex.siso import from_crossings

SUBJECT = {"body.mass": 35.0, "passive.stiffness": 10.0}
"""The 35 kg subject with K = 10 N m/rad of docs/reflex.md, "The design question", at E = 3 cm, Lambda = 4 cm."""
WIDTH = 1.0 / 2**dz.BISECTIONS
"""The chain search's precision with the reflex rule (fractions in [0, 1])."""


def _subject():
    return config.set_parameters(config.load_preset("wagner2012"), SUBJECT)


def _bisect(meets, lo=0.0, hi=1.0):
    """A plain bisection of [lo, hi] (lo fails, hi meets) to WIDTH: the meeting end."""
    while hi - lo > WIDTH:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if meets(mid) else (mid, hi)
    return hi


def test_the_chain_curve_equals_a_plain_bisection_and_is_certified():
    """A second method: at 40, 120 and 200 ms, a plain bisection of the local-stiffness fraction on [0, 1] written
    here (its own verdict: the exact multivariable margin at least the delay, no critical delay crossed below it,
    the rightmost root in the left half-plane) gives the curve's fraction exactly (both judge only fractions on the
    grid of 2^-20, and the fractions that meet form an interval here, so both end at its least grid point); and the
    curve's fraction is certified by the same verdict: it meets the delay, 2^-20 less does not."""
    model = _subject()
    linear = chain_at(OperatingPoint(model, 0.03, 0.04, model.reflex.activation * _optimum(model), slip_check=False))
    mass = linear.mass_matrix
    _, least = least_local_stiffness_stacked(linear.stiffness_offset[None], model.optimisation.stability_margin)
    lag = model.reflex.activation_time_constant

    def meets(f, d):
        k, dl, p, dd = dz.chain_loop_at(model, linear, least[0], f)
        exact = chain_delay_margin(mass, k, dl, p, dd, lag)
        if not (stable_at(exact, d) and exact.margin >= d):
            return False
        return dz.rightmost_root(mass, k, dl, p, dd, d, lag).real < 0

    delays = [0.04, 0.12, 0.2]
    curve = dz.delay_curve(model, 0.03, 0.04, delays)
    for j, d in enumerate(delays):
        f = curve.local_fraction[0, j]
        assert f == _bisect(lambda x, d=d: meets(x, d))
        assert meets(f, d) and not meets(f - WIDTH, d)


def test_the_chain_curve_needs_less_than_half_the_exact_margins_of_a_bisection(monkeypatch):
    """The cost, counted (not timed): on 9 delays 0 to 200 ms each delay after the first needs a new fraction
    (the answer rises by more than 2^-4 of [0, 1] between delays 25 ms apart up to 100 ms, by 0.005-0.05 after,
    see the curve), which a bisection to 2^-20 of a bracket of at least 2^-8 finds in at least 12 exact margins:
    at least 96 for the 8. The interpolation must need at most half of that (it needs 45; the bisection 131)."""
    calls = []
    margin = dc.chain_delay_margin
    monkeypatch.setattr(dc, "chain_delay_margin", lambda *a: calls.append(1) or margin(*a))
    dz.delay_curve(_subject(), 0.03, 0.04, np.linspace(0.0, 0.2, 9))
    assert len(calls) <= 48


def _tau(f):
    """A margin [s] monotone in the fraction that jumps (at 0.4) and has an infinite slope (at 0.7)."""
    return 0.12 * f + 0.06 * (f >= 0.4) + 0.04 * np.sqrt(max(0.0, f - 0.7))


def test_the_search_is_certified_where_the_margin_jumps_and_bends(monkeypatch):
    """The chain's margin replaced by _tau (monkeypatched: the loop carries the fraction, the margin is _tau's one
    destabilising crossing at 1 rad/s, the root's sign follows it): at 21 delays 0 to 200 ms, across the jump and
    the kink, the curve's fraction meets the delay and 2^-20 less does not (read from _tau itself: a margin equal to
    the delay is a root on the axis, which does not meet it, as stable_at says), and it equals a plain bisection of
    _tau > d exactly (both on the grid of 2^-20; at 30 ms the change falls on a grid point, f = 0.25)."""
    monkeypatch.setattr(dc, "chain_loop_at", lambda *a: (np.array([a[3]]), None, np.array([1.0 - a[3]]), np.ones(1)))
    monkeypatch.setattr(dc, "chain_delay_margin", lambda m, k, *a: from_crossings([1.0], [_tau(k[0])], [1.0], True))
    monkeypatch.setattr(dc, "rightmost_root", lambda m, k, dl, p, dd, d, lag, *_: complex(1.0 - 2.0 * (_tau(k[0]) > d)))
    delays = np.linspace(0.0, 0.2, 21)
    curve = dz.delay_curve(_subject(), 0.03, 0.04, delays)
    for d, f in zip(delays[1:], curve.local_fraction[0, 1:], strict=True):
        assert _tau(f) > d >= _tau(f - WIDTH)
        assert f == _bisect(lambda x, d=d: _tau(x) > d)


def test_a_stalling_estimate_falls_back_to_bisection():
    """_bracket_root with an estimate that always points just above the last failing fraction (each step would
    gain only 0.45 of the width: some 700 000 steps to cross [0, 1]): the safeguard (a midpoint whenever three steps
    did not halve the bracket) ends within four steps per halving, 4 x 21, at a certified bracket around the
    change; an estimate outside the bracket, or none, gives the plain bisection's 20 steps."""
    change = 1 / np.pi
    judged = [0.0]

    def meets(x):
        judged.append(x)
        assert len(judged) < 1000, "no fallback: the search crawls at 0.45 of the width per step"
        return x >= change

    def stalling():
        return max([x for x in judged if x < change]) + 1e-12

    f = dc._bracket_root(meets, stalling, 0.0, 1.0, WIDTH)
    assert f >= change > f - WIDTH
    assert len(judged) - 1 <= 4 * 21
    for estimate in (lambda: None, lambda: 2.0):
        judged[:] = [0.0]
        assert dc._bracket_root(meets, estimate, 0.0, 1.0, WIDTH) == _bisect(lambda x: x >= change)
        assert len(judged) - 1 == dz.BISECTIONS


def _optimum(model):
    from spinectl.optimise.reference import solve_point

    return np.asarray(solve_point(model, 0.03, 0.04).pcsa, float)
