"""Per-segment reflex margins at one configuration: activation levels, explicit gains, infeasibility;
the report as a dict and a table, and the responses its plots show."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from spinectl import reflex
from spinectl.model import source
from spinectl.model.mechanics import segment_coefficients
from spinectl.model.params import Optimisation
from spinectl.reflex import margins

E, LAMBDA = 0.03, 0.04


def _with_reflex(model, **changes):
    return model.replace(reflex=dataclasses.replace(model.reflex, **changes))


def test_activation_one_is_self_stable_and_needs_no_reflex(model):
    """At the minimum stabilising PCSA every segment has S <= -margin < 0: the rule gives kp = 0, and
    the muscles' own damping exceeds the rule's target, so kd = 0 too: any delay is tolerated."""
    report = margins.margins_report(_with_reflex(model, activation=1.0), E, LAMBDA)
    assert report.point.status == "optimal"
    for seg in report.segments:
        assert seg.self_stable and seg.kp == 0 and seg.kd == 0
        assert seg.delay_margin == np.inf and seg.delay_margin_status == "delay_independent"
        assert seg.stable_at_delay and seg.gain_margin_lower == 0 and seg.gain_margin == np.inf


def test_activation_zero_is_reflex_only(model):
    """No co-contraction: S = m g r_y (gravity alone) and D = 0 at every segment; the optimiser is skipped.
    At 50 ms (with the default 50 ms activation lag the reflex-only margins are 63-95 ms) every loop is stable."""
    report = margins.margins_report(_with_reflex(model, activation=0.0, delay=0.05), E, LAMBDA)
    assert report.point.status == margins.SKIPPED and not report.point.pcsa.any()
    coeffs = segment_coefficients(model, E, LAMBDA)
    np.testing.assert_allclose([s.stiffness for s in report.segments], coeffs.gravity_stiffness)
    for seg in report.segments:
        assert not seg.self_stable and 0 < seg.delay_margin < np.inf
        assert seg.stable_at_delay == (report.delay < seg.delay_margin)
        assert seg.delay_margin_pade == pytest.approx(seg.delay_margin, rel=1e-6)  # order 5, w tau < 1
        # a segment that needs its reflex is open-loop unstable: the gain may fall to S / kp only
        assert seg.gain_margin_lower == pytest.approx(seg.stiffness / seg.kp)


def test_explicit_gains_replace_the_rule(model):
    report = margins.margins_report(_with_reflex(model, activation=0.0), E, LAMBDA, kp=200.0)
    assert all(s.kp == 200.0 for s in report.segments)
    s = report.segments[2]
    assert s.kd == pytest.approx(float(reflex.default_gains(s.stiffness, 0.0, s.inertia, 1.5, 1.0)[1]))
    configured = margins.margins_report(
        _with_reflex(model, activation=0.0, gains="explicit", kp=150.0, kd=20.0), E, LAMBDA
    )
    assert all((s.kp, s.kd) == (150.0, 20.0) for s in configured.segments)


def test_infeasible_optimum_is_an_answer_not_an_exception(model):
    """A PCSA bound far below what stability needs: solve_point is infeasible; every value is NaN."""
    tiny = model.replace(optimisation=Optimisation(pcsa_max=1e-8))
    report = margins.margins_report(_with_reflex(tiny, activation=0.5), E, LAMBDA)
    assert report.point.status == "infeasible" and not report.point.ok
    for seg in report.segments:
        assert np.isnan(seg.stiffness) and np.isnan(seg.delay_margin) and seg.delay_margin_status == "undefined"
        assert not seg.stable_at_delay and seg.python_control is None


def test_python_control_overflow_leaves_the_exact_margins(model):
    """Padé order 10 at a 1 us delay: python-control's polynomial margins overflow (coefficients
    ~ (1/tau)^10); its reading is dropped (None, NaN gain margins), the exact analysis stands."""
    model = _with_reflex(model, activation=0.0, delay=1e-6, pade_order=10, activation_time_constant=0.0)
    report = margins.margins_report(model, E, LAMBDA)
    for seg in report.segments:
        assert seg.python_control is None and np.isnan(seg.gain_margin)
        assert 0.1 < seg.delay_margin < 0.2 and seg.stable_at_delay


JSON_KEYS = (
    "name",
    "stiffness_Nm_per_rad",
    "damping_Nms_per_rad",
    "inertia_kgm2",
    "self_stable",
    "slowest_time_constant_s",
    "kp_Nm_per_rad",
    "kd_Nms_per_rad",
    "gain_margin",
    "gain_margin_lower",
    "phase_margin_deg",
    "crossover_rad_s",
    "delay_margin_s",
    "delay_margin_status",
    "delay_margin_pade_s",
    "kp_min_Nm_per_rad",
    "kp_max_Nm_per_rad",
    "stable_at_delay",
    "python_control",
)
"""Every key of a segment in ``spinectl margins --json``: the unit in the name."""


def test_to_dict_schema_and_values(model):
    """The document's numbers are the exact analysis of its own S, D, theta, kp, kd (reflex.delay_margin)."""
    report = margins.margins_report(_with_reflex(model, activation=0.0, delay=0.1, pade_order=3), E, LAMBDA)
    doc = report.to_dict()
    assert doc["E_m"] == E and doc["Lambda_m"] == LAMBDA and doc["activation"] == 0.0
    assert doc["delay_s"] == 0.1 and doc["pade_order"] == 3 and doc["optimum_status"] == "skipped"
    lag = doc["activation_time_constant_s"]
    assert lag == model.reflex.activation_time_constant == 0.05
    assert doc["gains"] == "rule" and doc["pcsa_cm2"] == dict.fromkeys(model.muscle_names, 0.0)
    assert [s["name"] for s in doc["segments"]] == ["L1L2", "L2L3", "L3L4", "L4L5", "L5S1"]
    for seg in doc["segments"]:
        assert tuple(seg) == JSON_KEYS
        exact = reflex.delay_margin(
            seg["stiffness_Nm_per_rad"],
            seg["damping_Nms_per_rad"],
            seg["inertia_kgm2"],
            seg["kp_Nm_per_rad"],
            seg["kd_Nms_per_rad"],
            lag,
        )
        assert seg["delay_margin_s"] == pytest.approx(float(exact.margin), rel=1e-12)
        assert seg["stable_at_delay"] == (0.1 < seg["delay_margin_s"])
        assert set(seg["python_control"]) == {
            "gain_margin",
            "phase_margin_deg",
            "crossover_rad_s",
            "phase_crossover_rad_s",
        }
    assert doc["all_stable_at_delay"] == all(s["stable_at_delay"] for s in doc["segments"])


def test_to_dict_pcsa_in_cm2_by_muscle(model):
    report = margins.margins_report(_with_reflex(model, activation=0.5), E, LAMBDA)
    doc = report.to_dict()
    assert list(doc["pcsa_cm2"]) == list(model.muscle_names)
    np.testing.assert_allclose(list(doc["pcsa_cm2"].values()), report.point.pcsa * 1e4, rtol=1e-12)


def test_self_stable_margins_are_infinite_in_the_dict(model):
    doc = margins.margins_report(_with_reflex(model, activation=1.0), E, LAMBDA).to_dict()
    assert all(
        s["delay_margin_s"] == float("inf") and s["delay_margin_status"] == "delay_independent" for s in doc["segments"]
    )


def test_undefined_python_control_reading_is_none_in_the_dict(model):
    report = margins.margins_report(_with_reflex(model, activation=0.0, delay=1e-6, pade_order=10), E, LAMBDA)
    assert all(s["python_control"] is None for s in report.to_dict()["segments"])


def test_table_names_the_minimum_pcsa_status_only_where_it_was_not_solved(model):
    """A solved minimum PCSA goes without saying (was "(optimum: optimal)"); another status is named."""
    report = margins.margins_report(_with_reflex(model, activation=0.5), E, LAMBDA, kp=150.0, kd=20.0)
    assert report.point.status == "optimal"
    assert "activation 0.5 x minimum PCSA, delay" in report.table().splitlines()[1]


def test_table(model):
    report = margins.margins_report(_with_reflex(model, activation=0.0), E, LAMBDA, kp=150.0, kd=20.0)
    lines = report.table().splitlines()
    assert lines[0] == source.header(model)  # the model's line first (docs/model.md, "The default model")
    assert lines[1].startswith("E = 3.00 cm, Lambda = 4.00 cm, activation 0 x minimum PCSA (minimum PCSA: skipped)")
    assert lines[1].endswith("gains: explicit")  # both gains given
    rows = [line for line in lines if line.split()[:1] in (["L1L2"], ["L2L3"], ["L3L4"], ["L4L5"], ["L5S1"])]
    assert len(rows) == 5 and all(row.split()[6:8] == ["150.00", "20.00"] for row in rows)
    assert all(row.split()[4:6] == ["no", "none"] for row in rows)  # gravity alone: not self-stable
    assert "tau_m: exact delay" in lines[-5] and lines[-3].startswith("S < 0 restores and D < 0 damps")
    assert lines[-1] == report.verdict() and lines[-1].startswith("joint by joint (each CoR alone, the others fixed")


def test_table_writes_inf_and_nan_as_words(model):
    """Self-stable without reflex: delay margins and gain factors are "unbounded", the phase margin and
    crossover "none", and the slowest time constant is -1/max Re lambda of paper eq. (1); no optimum: "n/a"."""
    report = margins.margins_report(_with_reflex(model, activation=1.0), E, LAMBDA)
    table = report.table()
    assert " unbounded " in table and " none " in table and "inf" not in table and "nan" not in table
    seg = report.segments[0]
    slow = -1.0 / np.roots([seg.inertia, -seg.damping, -seg.stiffness]).real.max()
    row = next(line for line in table.splitlines() if line.startswith(seg.name)).split()
    assert row[4] == "yes" and float(row[5]) == pytest.approx(slow, abs=1e-3)
    infeasible = model.replace(optimisation=Optimisation(pcsa_max=1e-8))
    table = margins.margins_report(_with_reflex(infeasible, activation=0.5), E, LAMBDA).table()
    assert " n/a " in table and "nan" not in table


def test_report_responses_of_a_reflex_only_report(model):
    """Activation 0: every segment has a loop (the Pade loop of its own gains) and a simulation."""
    model = _with_reflex(model, activation=0.0, sim_duration=0.3)
    report = margins.margins_report(model, E, LAMBDA)
    responses = margins.report_responses(model, report)
    names = [s.name for s in report.segments]
    assert list(responses.loops) == names and list(responses.simulations) == names
    s = report.segments[2]
    w = np.array([0.5, 5.0, 50.0])
    lag = 1.0 / (1.0 + report.activation_time_constant * 1j * w)  # force generation 1/(T_a s + 1)
    expected = lag * (s.kp + s.kd * 1j * w) / (s.inertia * (1j * w) ** 2 - s.damping * 1j * w - s.stiffness)
    pade = reflex.pade_coefficients(report.pade_order)  # e^{-x} ~ q(-x)/q(x), x = s tau
    x = 1j * w * report.delay
    q = sum(c * x**k for k, c in enumerate(pade))
    q_minus = sum(c * (-x) ** k for k, c in enumerate(pade))
    np.testing.assert_allclose(responses.loops[s.name](1j * w), expected * q_minus / q, rtol=1e-9)
    run = responses.simulations[s.name]
    assert list(run.kp) == [s.kp, 0.0] and list(run.kd) == [s.kd, 0.0]  # with the reflex, then without


def test_report_responses_without_reflex_or_optimum(model):
    """Self-stable segments (kp = kd = 0) have no loop but a simulation; an infeasible optimum has neither."""
    stable = _with_reflex(model, activation=1.0, sim_duration=0.3)
    responses = margins.report_responses(stable, margins.margins_report(stable, E, LAMBDA))
    assert responses.loops == {} and len(responses.simulations) == 5
    tiny = _with_reflex(model.replace(optimisation=Optimisation(pcsa_max=1e-8)), activation=0.5)
    empty = margins.ReportResponses({}, {}, divergence=tiny.reflex.sim_divergence)  # the limit: the model's
    assert margins.report_responses(tiny, margins.margins_report(tiny, E, LAMBDA)) == empty


@pytest.mark.parametrize(
    ("kp", "kd", "label"),
    [
        (None, None, "rule"),
        (150.0, 20.0, "explicit"),
        (150.0, None, "explicit kp, rule kd"),
        (None, 5.0, "rule kp, explicit kd"),
    ],
)
def test_gains_say_how_they_were_chosen(model, kp, kd, label):
    """Gains given to margins_report are explicit in the report, also where the model's setting is 'rule'."""
    report = margins.margins_report(_with_reflex(model, activation=0.0), E, LAMBDA, kp=kp, kd=kd)
    assert report.gains == label and report.to_dict()["gains"] == label


def test_kp_range_without_delay_is_the_hurwitz_range_with_the_lag(model):
    """``spinectl margins --delay 0`` with the default lag (T_a = 0.05 s): each segment's kp range is that of the
    delay-free cubic T_a theta s^3 + (theta - T_a D) s^2 + (kd - D - T_a S) s + (kp - S) (Routh-Hurwitz, from the
    segment's own S, D, theta and kd), and the verdict at kp = 100 agrees with it (before: the range of a 1 s delay,
    L4L5 [9.8, 15.0], printed beside "stable: yes")."""
    lagged = _with_reflex(model, delay=0.0)
    lag = lagged.reflex.activation_time_constant
    assert lag > 0
    for kp in (None, 100.0):
        for seg in margins.margins_report(lagged, E, LAMBDA, kp=kp).segments:
            s, d, theta, kd = seg.stiffness, seg.damping, seg.inertia, seg.kd
            high = s + (theta - lag * d) * (kd - d - lag * s) / (lag * theta)
            assert seg.kp_min == pytest.approx(s) and seg.kp_max == pytest.approx(high, rel=1e-12)
            assert seg.stable_at_delay == (s < seg.kp < high)


@pytest.mark.parametrize("activation", [0.5, 0.4, 0.2])
def test_a_rule_kd_of_zero_says_the_rules_formula_once(activation):
    """``margins`` at wagner2012 (3, 4) cm printed "kd 0.00" at every segment at activation 0.5 (the issue's case)
    while the chain's design has k_d 1.2-1.8: both are the rule's max(0, ...), which the table did not say. One
    line now gives the formula (gains.KD_RULE) and names exactly the segments whose kd is 0, recomputed by
    gains.default_gains from each segment's S, D and theta; at 0.4 and 0.2 (variants) fewer or none are 0, and
    with no zero kd, or explicit gains, there is no such line."""
    from spinectl import load_preset
    from spinectl.reflex import gains

    model = _with_reflex(load_preset("wagner2012"), activation=activation, delay=0.1)
    report = margins.margins_report(model, 0.03, 0.04)
    s, d, theta = (np.array([getattr(x, k) for x in report.segments]) for k in ("stiffness", "damping", "inertia"))
    _, kd = gains.default_gains(s, d, theta, model.reflex.gain_factor, model.reflex.damping_ratio)
    zero = [x.name for x, k in zip(report.segments, kd, strict=True) if k == 0.0]
    notes = [line for line in report.table().splitlines() if line.startswith("kd: the rule's")]
    if zero:
        assert len(notes) == 1 and f"{gains.KD_RULE} = 0 here at {', '.join(zero)} (" in notes[0]
    else:
        assert notes == []
    explicit = margins.margins_report(model, 0.03, 0.04, kp=20.0, kd=0.0)
    assert not any(line.startswith("kd: the rule's") for line in explicit.table().splitlines())
