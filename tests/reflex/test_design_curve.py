"""The design curve (spinectl.reflex.design.curve.delay_curve): both criteria's required design against the delay."""

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
    """spinectl.reflex.design.curve.design at each delay is the curve's search at that delay alone (one product
    algorithm): the joint activations (each segment's and the common one) and the chain's least local stiffness,
    its exact margin and k* are the curve's exactly (before, the single design had its own scan and bisection and
    stopped at other certified points: 0.76223392 against the curve's 0.76223388 at 120 ms). The chain's search
    judges only fractions on the grid of 2^-20, so where the fractions that meet a delay form an interval its
    answer is that interval's least grid point, whatever the other delays of the curve; 200 ms is answered last
    on the curve, after six shorter delays, and first (alone) by the design. The curve's margin is at least each
    delay (the certificate)."""
    model = _subject()
    delays = [0.0, 0.04, 0.08, 0.1, 0.12, 0.16, 0.2]
    curve = dz.delay_curve(model, 0.03, 0.04, delays)
    for j, d in enumerate(delays):
        single = dz.design(config.set_parameters(model, {"reflex.delay": d}), 0.03, 0.04)
        assert curve.activation[0, j] == single.activation
        assert curve.segment_activation[0, j].tolist() == [s.activation for s in single.segments]
        assert curve.local_fraction[0, j] == single.chain.fraction
        assert curve.chain_margin[0, j] == single.chain.delay_margin >= d
        assert curve.local_stiffness[0, j].tolist() == single.chain.local_stiffness.tolist()


def test_one_delay_of_the_cli_equals_the_curve_of_one_delay(capsys):
    """``design --delay 0.12`` and ``design --delays 0.12:0.12:1`` (the issue's pair, which disagreed in the chain's
    fraction at 1e-6) print the same activation and local stiffness fraction."""
    import json

    from spinectl.cli import main

    where = ["--E", "0.03", "--Lambda", "0.04", "--json"]
    assert main(["design", "--delay", "0.12", *where]) == 0
    single = json.loads(capsys.readouterr().out)
    assert main(["design", "--delays", "0.12:0.12:1", *where]) == 0
    curve = json.loads(capsys.readouterr().out)["curves"][0]
    assert [single["activation"]] == curve["joint"]["activation"]
    assert [single["chain"]["local_stiffness_fraction"]] == curve["chain"]["local_stiffness_fraction"]
    assert [single["chain"]["delay_margin_s"]] == curve["chain"]["delay_margin_s"]


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


def test_the_curve_names_its_reflex_global_pcsa_boundary_and_zero_row():
    """The issue's ``--delays 0:0.2:5`` (table, JSON, figure titles): the header no longer reads 'joint by joint:
    joint by joint', names the reflex rule and the global PCSA (0.5 x the minimum stabilising PCSA, recomputed here
    from solve_point), says each value is a boundary, that tau_m is the chain's, and explains the 0 ms row."""
    from spinectl.optimise.reference import solve_point
    from spinectl.reflex.design_plots import delay_figure

    model = config.load_preset("wagner2012")
    curve = dz.delay_curve(model, 0.0, 0.0, np.linspace(0.0, 0.2, 5))
    expected = 0.5 * float(np.sum(solve_point(model, 0.0, 0.0).pcsa)) * 1e4
    assert curve.to_dict()["global_pcsa_cm2"] == pytest.approx(expected, rel=1e-12)
    table = curve.table()
    assert "joint by joint: joint by joint" not in table
    assert f"(global PCSA {expected:.2f} cm^2" in table and "reflex assumed: the reflex rule" in table
    assert "a stability boundary" in table and "chain tau_m[ms]" in table and "0 ms: the reflex acting" in table
    document = curve.to_dict()
    assert document["reflex"].startswith("the reflex rule") and "stability boundary" in document["reading"]
    fig = delay_figure(curve)
    titles = " ".join([fig._suptitle.get_text()] + [ax.get_title() for ax in fig.axes])
    assert "the reflex rule" in titles and f"{expected:.2f} cm²" in titles and "stability boundary" in titles


def test_the_curve_with_given_gains_says_so_and_has_no_zero_row_note():
    """A variant: explicit gains (k_p 40, k_d 4) and no 0 ms delay: the reflex is the gains given, no 0 ms note."""
    curve = dz.delay_curve(_subject(), 0.03, 0.04, [0.02, 0.04], kp=40.0, kd=4.0)
    table = curve.table()
    assert "reflex assumed: the given gains kp, kd at every joint" in table and "0 ms:" not in table
