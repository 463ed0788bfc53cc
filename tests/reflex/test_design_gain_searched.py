"""The design over every diagonal PD reflex (spinectl.reflex.design.gain_searched), its labels and its margin."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from spinectl.model import chain, config
from spinectl.model.checks import checked_coefficients
from spinectl.optimise.reference import solve_point
from spinectl.reflex import design as dz
from spinectl.reflex import gains
from spinectl.reflex.chain_margins import stable_at
from spinectl.reflex.delay import delay_margin
from spinectl.reflex.design.roots import SPECTRAL_NODES, rightmost_root
from spinectl.reflex.mimo import chain_delay_margin

AT = (0.03, 0.04)
"""E = 3 cm, Lambda = 4 cm: the issue's position (``wagner2012``, T_a = 50 ms)."""

DOCS = Path(__file__).resolve().parents[2] / "docs" / "reflex.md"


def _model(delay, **extra):
    return config.set_parameters(config.load_preset("wagner2012"), {"reflex.delay": delay} | extra)


def _chain_at(model, fraction):
    """M, K - f diag(k*), D - c_loc f diag(k*) and the rule's full gains (before the hand-over), recomputed from the
    model's chain (spinectl.model.chain) and the rule (gains.chain_gains), not from the module under test."""
    optimum = np.asarray(solve_point(model, *AT).pcsa, float)
    pcsa = model.reflex.activation * optimum
    coefficients = chain.chain_coefficients(model, *AT)
    mass = chain.linear_chain(model, *AT, coefficients).mass_matrix
    k, d = coefficients.stiffness(pcsa), coefficients.damping(pcsa)
    least = dz.design(model, *AT).chain.least_static
    r = model.reflex
    kp0, kd0 = gains.chain_gains(mass, k, d, least, r.gain_factor, r.damping_ratio)
    local = fraction * least
    c_loc = chain.linear_chain(model, *AT, coefficients).local_damping_per_stiffness
    return mass, k - np.diag(local), d - np.diag(c_loc * local), kp0, kd0


@pytest.fixture(scope="module")
def searched_40ms():
    """The issue's case: 40 ms, ``wagner2012`` at (3, 4) cm, the gain search on (one run, about a minute)."""
    return dz.answer(_model(0.04), *AT, search=True)


def test_the_issues_40ms_gains_hold_less_stiffness_than_the_rule():
    """The issue's claim, recomputed with the library's exact margin: at 0.9 of the rule's f (0.5617 x k*) the chain
    with 0.40 k_p and 0.30 k_d of the rule's gains (before the hand-over) is stable at 40 ms: margin 47.5 ms here
    (the issue says 42.3 ms), rightmost root -0.15 1/s. So the rule's f is not the least over diagonal gains; with
    the rule's own hand-over gains, (1 - 0.9 f)+ of them, the same stiffness holds 27.6 ms only."""
    model = _model(0.04)
    rule = dz.design(model, *AT).chain.fraction
    mass, k, d, kp0, kd0 = _chain_at(model, 0.9 * rule)
    exact = chain_delay_margin(mass, k, d, 0.40 * kp0, 0.30 * kd0, model.reflex.activation_time_constant)
    assert stable_at(exact, 0.04) and exact.margin == pytest.approx(0.04747, abs=2e-4)
    root = rightmost_root(mass, k, d, 0.40 * kp0, 0.30 * kd0, 0.04, model.reflex.activation_time_constant, 24)
    assert root.real < 0
    scaled = 1 - 0.9 * rule
    assert chain_delay_margin(mass, k, d, scaled * kp0, scaled * kd0, 0.05).margin == pytest.approx(0.0276, abs=2e-4)


def test_the_searched_answer_is_certified_and_below_the_rules(searched_40ms):
    """At its reported f and gains the library's exact margin meets 40 ms with no crossing below, and the rightmost
    root (Chebyshev seeds) lies on the left; f is strictly below the rule's (the 0.9 f of the issue holds, so the
    bisection's fourth step, 0.9 x 0.5617 = 0.5055 or lower, is certified)."""
    s, rule = searched_40ms.searched, searched_40ms.chain
    assert s.fraction < rule.fraction and s.fraction <= 0.9 * rule.fraction + 1e-12
    mass, k, d, _, _ = _chain_at(_model(0.04), s.fraction)
    np.testing.assert_allclose(s.local_stiffness, s.fraction * rule.least_static)
    exact = chain_delay_margin(mass, k, d, s.kp, s.kd, 0.05)
    assert stable_at(exact, 0.04) and exact.margin >= 0.04 and exact.margin == pytest.approx(s.delay_margin)
    root = rightmost_root(mass, k, d, s.kp, s.kd, 0.04, 0.05, SPECTRAL_NODES)
    assert root.real < 0 and root.real == pytest.approx(s.max_root_real, rel=1e-6, abs=1e-9)
    assert {"reflex", "kp_Nm_per_rad", "budget"} <= set(searched_40ms.to_dict()["chain_gain_searched"])
    table = searched_40ms.table()
    assert "over diagonal PD gains (the rule's shape" in table and "the reflex rule, (1 - f)+" in table
    quoted = [line for line in table.splitlines() if line.startswith("over diagonal PD gains")]
    assert quoted
    # docs/reflex.md includes these lines as generated at the build, not typed (tests/suites/test_docs_numbers.py
    # compares them with the command's)
    assert "{include} _generated/design-chain-searched.md" in DOCS.read_text(encoding="utf-8")


def test_the_searched_heading_names_the_stage_that_found_the_gains(searched_40ms):
    """The issue's 40 ms case: the certified gains are exactly the rule's full gains (recomputed by _chain_at from
    the model's chain and gains.chain_gains, not by the module) times the shape factors the answer reports, so the
    first stage found them, and the table says so ("found by the first stage, the rule's shape: k_p x a, k_d x b"),
    under a heading that says "at most" (a search is no proof of least) and names both stages, the search's members
    those of gain_search.population_members for its budget (before: "over any diagonal PD gains, searched: local
    stiffness ...", read as the free search's answer, and "population 1" beside docs' "10 members")."""
    from spinectl.reflex.design import gain_searched as gs
    from spinectl.reflex.gain_search import population_members

    s = searched_40ms.searched
    assert s.found_by == "shape" and s.shape[0] in gs.SHAPE_FACTORS and s.shape[1] in gs.SHAPE_FACTORS
    _, _, _, kp0, kd0 = _chain_at(_model(0.04), s.fraction)
    np.testing.assert_allclose(s.kp, s.shape[0] * kp0, rtol=1e-9)
    np.testing.assert_allclose(s.kd, s.shape[1] * kd0, rtol=1e-9)
    table = searched_40ms.table()
    members = population_members(gs.SEARCH_BUDGET["population"], len(s.kp))
    heading = (
        f"over diagonal PD gains (the rule's shape at {len(gs.SHAPE_FACTORS) ** 2} strengths, then a budgeted search "
        f"of {members} members): at most {np.sum(s.local_stiffness):.1f} N m/rad, certified"
    )
    assert heading in table
    assert f"found by the first stage, the rule's shape: k_p x {s.shape[0]:g}, k_d x {s.shape[1]:g}" in table
    assert f"differential evolution of {members} members" in table and "population 1 per gain" in table
    assert f"{members} members, 3 generations" in DOCS.read_text(encoding="utf-8")  # the docs say the same
    assert searched_40ms.to_dict()["chain_gain_searched"]["shape_factors"] == list(s.shape)


def test_the_rules_answer_is_the_searched_answer_when_no_smaller_fraction_is_certified(monkeypatch):
    """The rule's design is the first candidate: where no gains certify any smaller fraction (every certificate
    refused), every halving fails and the answer is the rule's own f, gains, margin and root, never above them."""
    from spinectl.reflex.design import gain_searched

    monkeypatch.setattr(gain_searched._Chain, "certify", lambda self, f, kp, kd: None)
    monkeypatch.setattr(gain_searched._Chain, "search", lambda self, f, starts: starts[0])
    model = _model(0.12, **{"body.mass": 35.0, "passive.stiffness": 10.0})  # a variant: the subject at 120 ms
    result = dz.answer(model, *AT, search=True)
    s, rule = result.searched, result.chain
    assert s.fraction == rule.fraction and s.delay_margin == rule.delay_margin >= 0.12
    np.testing.assert_array_equal(s.kp, rule.kp)
    np.testing.assert_array_equal(s.kd, rule.kd)
    assert "0 % less" in result.table()
    assert s.found_by == "rule" and "found: the rule's own gains (no smaller fraction certified)" in result.table()


@pytest.mark.parametrize(("delay", "ratio"), [(0.1, 1.2), (0.04, 1.5)])
def test_a_margin_ratio_is_the_design_at_ratio_times_the_delay(delay, ratio):
    """--margin R is the rule's design at R x the delay (it then holds every delay up to R tau: its exact margin is
    the first critical delay): the chain's fraction and the joint-by-joint activation equal design() there."""
    result = dz.answer(_model(delay), *AT, ratio=ratio)
    direct = dz.design(_model(ratio * delay), *AT)
    assert result.chain.fraction == direct.chain.fraction and result.activation == direct.activation
    assert result.delay == pytest.approx(ratio * delay) and result.nominal_delay == delay
    assert result.margin_cost is None and "holds every delay up to" in result.table()


def test_the_default_shows_the_cost_of_a_margin_of_1_1():
    """Without --margin the table says the least value is a stability boundary and what 1.1 x the delay costs: the
    rule's design at 1.1 tau (from design() itself), more local stiffness than at tau."""
    result = dz.answer(_model(0.1), *AT)
    longer = dz.design(_model(0.11), *AT).chain
    assert result.margin_cost.ratio == dz.COST_RATIO == 1.1
    assert result.margin_cost.fraction == longer.fraction > result.chain.fraction
    table = result.table()
    assert "sits on its stability boundary (margin = the delay)" in table
    assert f"{np.sum(longer.local_stiffness):.1f} N m/rad" in table


@pytest.mark.parametrize("K", [0.0, 40.0])
def test_the_printed_global_pcsa_is_the_activation_times_the_minimum_pcsa_at_K(K):
    """The chain's global PCSA is reflex.activation x the minimum stabilising PCSA of optimise.solve_point at this
    K (which shrinks as K grows: K = 40 a variant); the gains are the rule's at the design, (1 - f)+ of the full."""
    model = _model(0.04, **{"passive.stiffness": K})
    result = dz.answer(model, *AT)
    optimum = np.sum(solve_point(model, *AT).pcsa)
    assert result.chain.pcsa == pytest.approx(model.reflex.activation * optimum, rel=1e-12)
    assert result.to_dict()["chain"]["global_pcsa_cm2"] == pytest.approx(1e4 * 0.5 * optimum, rel=1e-12)
    assert f"global PCSA {1e4 * 0.5 * optimum:.2f} cm^2" in result.table()
    mass, _, _, kp0, kd0 = _chain_at(model, result.chain.fraction)
    np.testing.assert_allclose(result.chain.kp, (1 - result.chain.fraction) * kp0, rtol=1e-12)
    np.testing.assert_allclose(result.chain.kd, (1 - result.chain.fraction) * kd0, rtol=1e-12)


def test_the_issues_l1l2_claim_with_the_segments_exact_margin():
    """The issue's joint-by-joint claim, recomputed: at 120 ms (``wagner2012``, (3, 4) cm) L1L2 at 0.6 of its rule
    co-contraction, with the rule's k_p and k_d = 8 instead of the rule's 3.9 N m s/rad, has the exact margin 128.0 ms
    (spinectl.reflex.delay.delay_margin with the lag) where the rule's gains hold 92.3 ms."""
    model = _model(0.12)
    result = dz.design(model, *AT)
    coefficients = checked_coefficients(model, *AT)
    pcsa = 0.6 * result.segments[0].activation * np.asarray(solve_point(model, *AT).pcsa, float)
    s, d, theta = coefficients.stiffness(pcsa)[0], coefficients.damping(pcsa)[0], coefficients.inertia[0]
    kp, kd = (float(x[0]) for x in gains.resolve_gains([s], [d], [theta], model.reflex))
    assert kd == pytest.approx(3.91, abs=0.01)
    margins = delay_margin([s, s], [d, d], [theta, theta], [kp, kp], [kd, 8.0], 0.05).margin
    np.testing.assert_allclose(margins, [0.0923, 0.1280], atol=2e-4)


@pytest.mark.parametrize(("delay", "extra"), [(0.12, {}), (0.07, {"body.mass": 35.0, "passive.stiffness": 10.0})])
def test_joint_by_joint_over_every_gain_is_certified_and_below_the_rule(delay, extra):
    """Each segment at the common activation the grid certified, with its reported gains: the exact margin (recomputed
    by delay_margin) meets the delay and the rightmost root of theta s^2 - D s - S + (kp + kd s) e^{-s tau} / (T_a s
    + 1) at the delay lies on the left; the activation is at most the rule's, and strictly below it at 120 ms
    (the issue's case: 0.0288 against 0.3783) and for the subject at 70 ms (a variant)."""
    model = _model(delay, **extra)
    result = dz.answer(model, *AT)
    j = result.joint_searched
    assert j.activation < result.activation and np.all(j.segment_activation <= j.activation + 1e-12)
    coefficients = checked_coefficients(model, *AT)
    pcsa = j.activation * np.asarray(solve_point(model, *AT).pcsa, float)
    s, d, theta = coefficients.stiffness(pcsa), coefficients.damping(pcsa), coefficients.inertia
    margins = np.asarray(delay_margin(s, d, theta, j.kp, j.kd, 0.05).margin)
    assert np.all(margins >= delay) and margins == pytest.approx(j.delay_margin)
    for k in range(len(s)):
        root = rightmost_root([[theta[k]]], [[s[k]]], [[d[k]]], [j.kp[k]], [j.kd[k]], delay, 0.05, SPECTRAL_NODES)
        assert root.real < 0
    lines = [line for line in result.table().splitlines() if line.startswith("over any PD gains per segment")]
    # docs/reflex.md includes the 120 ms lines as generated at the build (tests/suites/test_docs_numbers.py)
    assert lines and (extra or "{include} _generated/design-joint-searched.md" in DOCS.read_text(encoding="utf-8"))
    assert result.to_dict()["joint_gain_searched"]["activation"] == j.activation


@pytest.mark.parametrize(("delay", "stiffness"), [(0.1, 200.0), (0.15, 150.0)])
def test_rule_infeasible_joint_by_joint_names_the_reflex_and_searches_from_no_reflex(delay, stiffness):
    """With K = 200 N m/rad at 100 ms (the issue's case; 150 at 150 ms, a variant) the rule has no activation, yet
    with no reflex every segment's exact margin (delay_margin with k_p = k_d = 0, recomputed here) is unbounded: the
    searched answer starts from no reflex instead of reporting none, is certified (margin >= the delay) and the
    table names the rule's k_d as what the infeasibility rests on, with the remedy."""
    model = _model(delay, **{"passive.stiffness": stiffness})
    result = dz.answer(model, 0.0, 0.0)
    assert result.status == "infeasible" and np.isnan(result.activation)
    j = result.joint_searched
    assert np.isfinite(j.activation) and np.all(j.delay_margin >= delay)
    coefficients = checked_coefficients(model, 0.0, 0.0)
    pcsa = j.activation * np.asarray(solve_point(model, 0.0, 0.0).pcsa, float)
    s, d, theta = coefficients.stiffness(pcsa), coefficients.damping(pcsa), coefficients.inertia
    assert np.all(np.isinf(delay_margin(s, d, theta, 0.0 * s, 0.0 * s, 0.05).margin))
    table = result.table()
    # the status is joint by joint's under the rule, not the table's: the chain's and the searched answers exist
    assert (
        "; status (the rule, joint by joint): infeasible" in table.splitlines()[1] and "status infeasible" not in table
    )
    assert np.isfinite(result.chain.fraction) and np.isfinite(j.activation)
    assert "the infeasibility rests on the reflex rule" in table and "destabilise the segments" in table
    assert "margins unbounded" in table and "--gains search" in table
    assert "none (the rule has no design" not in table
    assert result.to_dict()["joint_gain_searched"]["no_reflex_delay_margin_s"] == [None] * len(s)


def test_default_answer_says_it_is_the_rules_least_and_both_sit_on_their_boundary():
    """At 100 ms (`wagner2012`, (3, 4) cm) the chain's heading says 'under the reflex rule', one line points to
    --gains search, and the joint-by-joint answer carries a boundary note, true because the segment setting the
    common activation has tau_m = the delay (the bisection stops on the margin, to 1e-3 of it)."""
    result = dz.answer(_model(0.1), *AT)
    table = result.table()
    assert "least local stiffness under the reflex rule at activation 0.5000" in table
    assert "  the least under the reflex rule; other diagonal PD gains may need less: --gains search" in table
    joint = [line for line in table.splitlines() if line.startswith("  boundary: the least value sits on")]
    assert len(joint) == 2  # joint by joint and the chain
    binding = max(result.segments, key=lambda s: s.activation)
    assert binding.delay_margin == pytest.approx(0.1, rel=1e-3)


def test_given_gains_are_not_called_the_rule():
    """With explicit gains (a variant: k_p = 20, k_d = 2 at every joint) the answer is not the rule's: no 'under the
    reflex rule' heading and no pointer that other gains may need less than the rule."""
    table = dz.answer(_model(0.04), *AT, kp=20.0, kd=2.0).table()
    assert "under the reflex rule" not in table and "--gains search" not in table.split("chain (")[1]


@pytest.mark.parametrize(("delay", "ratio"), [(0.1, 1.2), (0.04, 1.5)])
def test_margin_design_names_the_designed_delay_and_shows_the_nominal_cost(delay, ratio):
    """--margin R (the issue's 100 ms x 1.2; 40 ms x 1.5, a variant): the certificate's root is at R tau and says so,
    and beside it stands the design at tau itself, the same local stiffness as the plain design at tau (dz.design,
    computed here separately), so the margin's cost is visible and not negative."""
    result = dz.answer(_model(delay), *AT, ratio=ratio)
    plain = dz.design(_model(delay), *AT).chain
    nominal = result.nominal_design
    np.testing.assert_allclose(nominal.local_stiffness, plain.local_stiffness, rtol=1e-9)
    table = result.table()
    designed = f"rightmost root at the designed delay {1000 * ratio * delay:.4g} ms Re s ="
    assert designed in table
    total = np.sum(plain.local_stiffness)
    assert f"the design at {1000 * delay:.4g} ms itself needs {total:.1f} N m/rad" in table
    assert np.sum(result.chain.local_stiffness) >= total
    assert result.to_dict()["nominal_design"]["local_stiffness_fraction"] == nominal.fraction


def test_the_searched_certificate_under_a_margin_names_the_designed_delay_too():
    """With --margin 1.2 at 100 ms the searched answer is certified at R tau = 120 ms, as the rule's is: its
    certificate line says 'at the designed delay 120 ms', not 'at the delay' (before: the rule's line said the
    designed delay, the searched one 'the delay', which reads as 100 ms). A made-up searched answer stands in
    for the seeded search (its numbers do not matter here, only the wording); without a margin it says 'the
    delay' (the variant)."""
    import dataclasses

    from spinectl.reflex.design.gain_searched import GainSearchedDesign

    n = 5
    fake = GainSearchedDesign(0.5, np.ones(n), np.ones(n), np.ones(n), 0.13, -1e-3, 1, 1, "made up")
    robust = dataclasses.replace(dz.answer(_model(0.1), *AT, ratio=1.2), searched=fake).table()
    searched = next(line for line in robust.splitlines() if "certificate: exact delay margin 130" in line)
    assert "rightmost root at the designed delay 120 ms" in searched
    plain = dataclasses.replace(dz.answer(_model(0.1), *AT), searched=fake).table()
    assert "rightmost root at the delay Re s" in next(
        line for line in plain.splitlines() if "certificate: exact delay margin 130" in line
    )


@pytest.mark.parametrize(("delay", "decay"), [(0.1, 0.0), (0.1, 2.0)])
def test_the_readings_are_the_tables_lines_part_by_part(delay, decay):
    """Design.readings (what the explorer's design panel shows) holds every line of Design.table (what spinectl
    design prints), in its order, part by part: the model, the headline, each criterion's title, the segments'
    table and the answer with its notes; the reflex assumed and the boundary (or, with a decay rate of 2 1/s where
    no design meets it, the decay-rate lines) are in each criterion's part, not elsewhere."""
    result = dz.answer(_model(delay), *AT, decay=decay)
    parts = result.readings()
    assert list(parts) == ["header", "headline", "joint_title", "joint_table", "joint", "chain_title", "chain"]
    assert [line for lines in parts.values() for line in lines] == [x for x in result.table().splitlines() if x]
    assert parts["joint"][1].startswith("  reflex assumed: the reflex rule at each activation")
    assert any(x.startswith("  reflex assumed: the reflex rule, (1 - f)+") for x in parts["chain"])
    if decay:
        assert "(--decay-rate)" in parts["joint"][0] and "(--decay-rate)" in parts["chain"][0]
    else:
        assert any(x.startswith("  boundary: the least value sits on its stability boundary") for x in parts["chain"])


def test_the_status_names_the_criterion_and_the_reflex_it_is_about():
    """The status words scope each failure (the JSON status keeps its value): the chain's ('chain_infeasible'), with
    given gains (a variant: kp = 20, kd = 2) named as such, and 'ok' left as it was; the optimum's own status where
    the optimum failed (method 'none: no optimum', joint.joint_design)."""
    import dataclasses

    rule = dz.answer(_model(0.1), *AT)
    given = dz.answer(_model(0.04), *AT, kp=20.0, kd=2.0)
    assert rule.status_text() == "status ok" and "; status ok" in rule.table().splitlines()[1]
    chain_failed = dataclasses.replace(rule, status="chain_infeasible")
    assert chain_failed.status_text() == "status (the rule, the chain): infeasible"
    assert "status (the rule, the chain): infeasible" in chain_failed.table()
    assert dataclasses.replace(given, status="infeasible").status_text() == (
        "status (the given gains, joint by joint): infeasible"
    )
    no_optimum = dataclasses.replace(rule, status="solver_error", method="none: no optimum")
    assert no_optimum.status_text() == "status (the per-segment optimum): solver_error"


@pytest.mark.parametrize(("kp", "kd", "top"), [(30.0, 8.0, "LOCAL_MAX"), (300.0, 0.0, "LOCAL_MAX")])
def test_no_chain_design_names_the_top_as_a_multiple_of_k_star(kp, kd, top):
    """``design --kp 30 --kd 8`` (the issue's case; 300 and 0, a variant) finds no local stiffness for the chain:
    the method said "no fraction up to 2 meets the delay", 2 of nothing named; it says the top as a multiple of
    k*, the least local stiffness for static stability (the top is result.LOCAL_MAX with given gains)."""
    from spinectl.reflex.design import result as rs

    design = dz.answer(_model(0.1), *AT, kp=kp, kd=kd)
    assert np.isnan(design.chain.fraction)  # the premise
    words = f"no local stiffness up to {getattr(rs, top):g} x k* (k*: the least for static stability) meets the delay"
    assert design.chain.method == words and words in design.table()


def test_joint_by_joint_with_given_gains_names_them_and_where_the_margin_jumps():
    """``design --kp 30 --kd 8`` at 100 ms: the joint-by-joint answer rests on the given gains, not the rule (it
    said "reflex assumed: the reflex rule at each activation" and "the rule's 0.3682"), and the segment that sets the
    common activation (the largest, L2L3) has its exact margin far above the delay (444.7 ms measured), so the
    boundary line says the margin jumps past the delay with that segment's ratio, computed here from the table's own
    segments; the rule's design (the variant) keeps the boundary at the delay."""
    given = dz.answer(_model(0.1), *AT, kp=30.0, kd=8.0)
    lines = given.readings()["joint"]
    setting = max(given.segments, key=lambda s: s.activation)
    ratio = setting.delay_margin / 0.1
    assert ratio > 1.1  # the premise: the margin is not at the delay
    assert "  reflex assumed: the given gains kp, kd at each segment" in lines
    assert any(f"({setting.name}) jumps past the delay" in x and f"({ratio:.3g} x the delay)" in x for x in lines)
    assert any(f"the given gains' {given.activation:.4f}" in x for x in lines)
    assert not any("the rule" in x for x in lines)
    rule = dz.answer(_model(0.1), *AT).readings()["joint"]
    assert "  reflex assumed: the reflex rule at each activation" in rule
    assert any(x.startswith("  boundary: the least value sits on its stability boundary") for x in rule)
