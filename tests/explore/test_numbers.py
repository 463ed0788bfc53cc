"""The explorer's numbers: equal to the library's answers at the same point, and checked by a second method."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
import scipy.linalg

from spinectl.explore import numbers as nb
from spinectl.explore.state import ExploreState, initial_state, model_at
from spinectl.model import chain, geometry
from spinectl.model.config import load_preset, set_parameters
from spinectl.model.stability import segment_stability
from spinectl.optimise.reference import solve_point
from spinectl.reflex.chain_verdict import chain_verdict, margins_with_chain
from spinectl.reflex.delay import delay_text
from spinectl.reflex.design import COST_RATIO
from spinectl.reflex.design.result import RULE_REFLEX
from spinectl.reflex.margins import margins_report, operating_point


@pytest.fixture
def state():
    return ExploreState(0.035, 0.02, mass=30.0, stiffness=15.0, delay=0.08, activation=0.6, activation_lag=0.04)


def _library_model(base, state):
    """The state's model built here from the parameters' dotted names (docs/parameters.md), not from SLIDERS."""
    return set_parameters(
        base,
        {
            "body.mass": state.mass,
            "passive.stiffness": state.stiffness,
            "reflex.delay": state.delay,
            "reflex.activation": state.activation,
            "reflex.activation_time_constant": state.activation_lag,
        },
    )


def test_point_numbers_equal_the_library_at_the_same_point(state):
    """Margins as `spinectl margins` computes them (reflex.margins.margins_report); eigenvalues and CT as
    `spinectl stability` at PCSA = activation x the optimum (docs/reflex.md)."""
    base = load_preset("wagner2012")
    got = nb.point_numbers(base, state)
    model = _library_model(base, state)
    report = margins_report(model, state.eccentricity, state.lordosis)
    np.testing.assert_array_equal(got.delay_margin, [s.delay_margin for s in report.segments])
    assert list(got.stable_at_delay) == [s.stable_at_delay for s in report.segments]
    pcsa = state.activation * solve_point(model, state.eccentricity, state.lordosis).pcsa
    at = segment_stability(model, state.eccentricity, state.lordosis, pcsa)
    np.testing.assert_allclose(got.pcsa, pcsa, rtol=1e-12, atol=0)
    np.testing.assert_allclose(got.eigenvalues, at.eigenvalues, rtol=1e-12, atol=0)
    np.testing.assert_allclose(got.counter_torque, at.counter_torque, rtol=1e-12, atol=1e-12)
    assert [r["counter_torque_Nm"] for r in got.rows()] == [nb.shown(x) for x in at.counter_torque]


def test_eigenvalues_are_the_roots_of_theta_s2_minus_d_s_minus_s(state):
    """Second method: numpy.roots of theta s^2 - D s - S (paper eq. 1) from each segment's S, D, theta."""
    got = nb.point_numbers(load_preset("default"), state)
    for segment, eigs in zip(got.report.segments, got.eigenvalues, strict=True):
        roots = np.roots([segment.inertia, -segment.damping, -segment.stiffness])
        np.testing.assert_allclose(np.sort_complex(eigs), np.sort_complex(roots), rtol=1e-9)


def test_at_activation_one_every_segment_is_self_stable_one_at_the_margin(state):
    """Activation 1 is the minimum stabilising PCSA: every S_k <= -stability_margin (0.1 N m/rad,
    params.Optimisation), the binding segment at it, so every eigenvalue has Re < 0."""
    got = nb.point_numbers(load_preset("default"), ExploreState(**{**state.__dict__, "activation": 1.0}))
    stiffness = np.array([s.stiffness for s in got.report.segments])
    assert np.all(stiffness <= -0.1 + 1e-6) and stiffness.max() == pytest.approx(-0.1, abs=1e-4)
    assert np.all(got.eigenvalues.real < 0)


def test_shown_numbers():
    """Four significant digits; complex as a+bj; an infinite margin 'unbounded' as the command line says it
    (reflex.delay.delay_text), NaN 'none': the user saw Python's 'inf' and 'nan' beside the design's 'none'."""
    assert [nb.shown(x) for x in (np.pi, -1.5 + 2.25j, np.inf, np.nan, 1e-7)] == [
        "3.142",
        "-1.5+2.25j",
        "unbounded",
        "none",
        "1e-07",
    ]
    assert delay_text(np.inf).startswith("unbounded") and delay_text(np.nan) == "none"


def test_landscapes_match_the_reference_solver_at_grid_points(state):
    """The fast path's minimum PCSA and ||CT|| at three grid points against the cvxpy reference
    (optimise.reference.solve_point, a second method; docs/optimisation.md: they agree to the solver tolerance)."""
    base = load_preset("default")
    dataset = nb.landscapes(base, state, points=5)
    assert dict(dataset.sizes) == {"E": 5, "Lambda": 5}
    model = _library_model(base, state)
    for i, j in [(0, 0), (2, 3), (4, 1)]:
        e, lam = float(dataset.E[i]), float(dataset.Lambda[j])
        reference = solve_point(model, e, lam)
        assert float(dataset.min_pcsa_cm2[i, j]) == pytest.approx(reference.min_pcsa * 1e4, rel=1e-5)
        assert float(dataset.counter_torque_norm_Nm[i, j]) == pytest.approx(
            np.linalg.norm(reference.counter_torque), rel=1e-4, abs=1e-6
        )


def _chain_matrices(model, state, pcsa):
    """M, K and D of the chain at the state's point (docs/chain.md), built here from spinectl.model.chain."""
    coefficients = chain.chain_coefficients(model, state.eccentricity, state.lordosis)
    mass = chain.mass_matrix(model, geometry.cor_positions(state.eccentricity, state.lordosis, model.geometry))
    return mass, coefficients.stiffness(pcsa), coefficients.damping(pcsa)


def test_chain_row_is_the_chain_verdict_at_the_same_point(state):
    """The chain's row: its criterion, and the verdict and exact delay margin of reflex.chain_verdict.chain_verdict
    called directly at the operating point of reflex.margins.operating_point (not through margins_with_chain)."""
    base = load_preset("default")
    got = nb.point_numbers(base, state).chain_row()
    model = _library_model(base, state)
    point = operating_point(model, state.eccentricity, state.lordosis, state.activation)
    verdict = chain_verdict(model, point, state.delay, state.activation_lag)
    assert got["criterion"] == "chain (all 5 CoRs free)"
    assert got["stable_at_delay"] == ("yes" if verdict.stable_at_delay else "no")
    assert got["delay_margin_s"] == nb.shown(verdict.exact.margin)
    assert got["frequency_rad_s"] == nb.shown(verdict.exact.frequency)


def test_chain_modes_are_the_roots_of_the_quadratic_eigenproblem(state):
    """Second method for the modes without reflex: the generalised eigenvalues of the linearisation
    [[0, I], [K, D]] x = s [[I, 0], [0, M]] x of M s^2 - D s - K (scipy.linalg.eig, no M^-1), at
    activation x the optimum's PCSA; growth times are 1 / Re s of the growing modes."""
    base = load_preset("default")
    got = nb.point_numbers(base, state)
    mass, stiffness, damping = _chain_matrices(got.model, state, got.pcsa)
    n = mass.shape[0]
    left = np.block([[np.zeros((n, n)), np.eye(n)], [stiffness, damping]])
    right = np.block([[np.eye(n), np.zeros((n, n))], [np.zeros((n, n)), mass]])
    roots = scipy.linalg.eigvals(left, right)
    growing = np.sort(roots.real[roots.real >= 0])[::-1]
    row = got.chain_row()
    assert growing.size > 0  # at this point the chain without reflex is unstable (docs/chain.md)
    assert row["modes"] == f"{growing.size} of {2 * n} grow"
    assert row["growth_times_s"] == f"{nb.shown(1 / growing[0])} to {nb.shown(1 / growing[-1])}"
    assert row["slowest_time_constant_s"] == "none: a mode grows"  # no time constant while a mode grows


def test_levels_without_mass_leave_the_chain_undefined():
    """levels.mass = 0 makes the chain's mass matrix singular (docs/chain.md): no modes and no margin to judge,
    shown as 'undefined' and nan, never as a verdict; the segments, judged alone, keep theirs."""
    base = set_parameters(load_preset("default"), {"levels.mass": 0.0})
    got = nb.point_numbers(base, initial_state(base))
    row = got.chain_row()
    assert row["stable_at_delay"] == "undefined" and row["modes"] == "undefined"
    assert row["delay_margin_s"] == "none" and row["growth_times_s"] == "none"
    assert all(r["stable_at_delay"] in ("yes", "no") for r in got.rows())


@pytest.fixture(scope="module")
def answer():
    """The design answer at the README's point of 'default' (40 kg, K 0, tau 100 ms, T_a 50 ms)."""
    base = load_preset("default")
    return base, initial_state(base), nb.design_numbers(base, initial_state(base))


def test_design_meets_the_delay_checked_by_the_margins_report(answer):
    """Joint by joint, second route: reflex.margins.margins_report with reflex.activation = the answer gives every
    segment an exact delay margin >= tau, and 1 % less activation leaves one below (the least); the chain's
    least static local stiffness is the chain verdict's (margins_with_chain at the same operating point)."""
    base, state, design = answer
    assert design.status == "ok"
    model = model_at(base, state)
    at = margins_report(
        set_parameters(model, {"reflex.activation": design.activation}), state.eccentricity, state.lordosis
    )
    assert min(s.delay_margin for s in at.segments) >= state.delay * (1 - 1e-9)
    below = set_parameters(model, {"reflex.activation": 0.99 * design.activation})
    assert min(s.delay_margin for s in margins_report(below, state.eccentricity, state.lordosis).segments) < state.delay
    verdict = nb.point_numbers(base, state).chain
    np.testing.assert_allclose(design.chain.least_static, verdict.local_stiffness, rtol=1e-9)
    assert design.chain.delay_margin >= state.delay and design.chain.max_root_real < 0


def test_design_is_the_commands_answer_with_the_reflex_it_assumes(answer):
    """design_numbers answers as `spinectl design` does (reflex.design.gain_searched.answer, the function the
    command calls): the chain's answer labelled with the rule's reflex, its global PCSA (activation x the
    minimum stabilising PCSA, solve_point here) and gains recorded, the cost of 1.1 x the delay beside it, and
    joint by joint the answer over every segment's gains (before: reflex.design.curve.design, none of these)."""
    base, state, design = answer
    assert design.chain.reflex == RULE_REFLEX and design.searched is None
    optimum = solve_point(model_at(base, state), state.eccentricity, state.lordosis).pcsa
    assert design.chain.pcsa == pytest.approx(state.activation * np.sum(optimum), rel=1e-6)
    assert np.all(np.isfinite(design.chain.kp)) and np.all(np.isfinite(design.chain.kd))
    assert design.margin_cost.ratio == COST_RATIO and design.joint_searched is not None


def test_design_rows_are_the_lines_spinectl_design_prints(answer):
    """design_rows: Design.readings part by part, each line as Design.table() prints it (the command's table),
    without the two spaces of a note, marked as one instead; among them the reflex-assumed lines and the
    boundary lines of both criteria (their words the library's: RULE_REFLEX)."""
    _, _, design = answer
    rows = nb.design_rows(design)
    table = design.table().splitlines()
    assert [line for part in rows.values() for line, _ in part] == [
        line if line in design.readings()["joint_table"] else line.strip() for line in table if line
    ]
    notes = {line.strip() for line in table if line.startswith("  ")}
    assert {line for part in rows.values() for line, note in part if note} == notes
    chain = [line for line, _ in rows["chain"]]
    assert f"reflex assumed: {RULE_REFLEX}" in "\n".join(chain)
    assert any(line.startswith("boundary: the least value sits on its stability boundary") for line in chain)
    assert any(line.startswith("boundary:") for line, _ in rows["joint"])
    assert rows["chain_title"][0][0].startswith("chain (all 5 CoRs free): least local stiffness under the reflex rule")


def test_the_explorers_design_is_what_the_command_prints_for_its_toml_export(tmp_path):
    """The state's TOML export (state_toml) and the command the panel gives (design_panel.design_command),
    run as a user would: `spinectl design` prints the lines of design_rows, the header apart (the command names
    the file, the explorer the preset). A state with three sliders moved off the preset's values, not the
    opening one."""
    from spinectl.explore.design_panel import TOML_NAME, design_command
    from spinectl.explore.state import state_toml

    base = load_preset("wagner2012")
    state = ExploreState(0.025, 0.05, mass=base.body.mass, stiffness=20.0, delay=0.07, activation=0.4,
                         activation_lag=base.reflex.activation_time_constant)  # fmt: skip
    (tmp_path / TOML_NAME).write_text(state_toml(base, state))
    argv = design_command(state).split()
    assert argv[:2] == ["spinectl", "design"]
    done = subprocess.run(
        [sys.executable, "-m", "spinectl", *argv[1:]], cwd=tmp_path, capture_output=True, text=True, timeout=600
    )
    assert done.returncode == 0, done.stderr
    printed = [line for line in done.stdout.splitlines() if line]
    rows = nb.design_rows(nb.design_numbers(base, state))
    shown = [line for key, part in rows.items() if key != "header" for line, _ in part]
    assert printed[0].startswith(f"preset wagner2012, K = 20 N m/rad, convention physical; config {TOML_NAME}")
    assert [line if line in rows["joint_table"] else line.strip() for line in printed[1:]] == shown
    assert rows["header"][0][0] == (
        "preset wagner2012, K = 20 N m/rad, convention physical; overridden: passive.stiffness, reflex.delay, "
        "reflex.activation"
    )  # the sliders moved, and only those (before: all five, moved or not)


@pytest.mark.parametrize("change", [{"delay": 0.0}, {"delay": 0.2}, {"activation_lag": 0.1}, {"activation": 0.3}])
def test_the_previous_points_chain_is_reused_only_where_the_delay_alone_moved(state, change):
    """point_numbers(..., previous=): the chain's verdict equals the one computed afresh at the new state
    (margins_with_chain), for a delay moved (reused: the margin does not depend on the delay; 0 and 0.2 s judge
    it on both sides) and for the lag or the activation moved (computed again: both move the chain's margin)."""
    base = load_preset("default")
    previous = nb.point_numbers(base, state)
    moved = ExploreState(**{**state.__dict__, **change})
    got = nb.point_numbers(base, moved, previous=previous)
    fresh = margins_with_chain(_library_model(base, moved), moved.eccentricity, moved.lordosis).chain
    assert got.chain.to_dict() == fresh.to_dict() and got.chain.delay == moved.delay
    assert got.chain_row()["stable_at_delay"] == ("yes" if fresh.stable_at_delay else "no")
    reused = got.chain.exact is previous.chain.exact
    assert reused == ("delay" in change)


def test_the_first_lines_give_both_verdicts_each_with_its_criterion():
    """wagner2012 at E = 3 cm, Lambda = 4 cm, activation 0.5, 100 ms (the explorer's opening point): every segment
    alone is stable at the delay while the chain is not (margins_with_chain, called here directly); the two lines
    that head the page say both, each with its criterion and the chain's exact margin (before: the chain's verdict
    was below the fold, under five green bars)."""
    from spinectl.explore.app import UNSTABLE_COLOUR, verdicts_html
    from spinectl.reflex.delay import delay_text

    base = load_preset("wagner2012")
    state = ExploreState(0.03, 0.04, mass=base.body.mass, stiffness=0.0, delay=0.1, activation=0.5,
                         activation_lag=0.05)  # fmt: skip
    numbers = nb.point_numbers(base, state)
    report = margins_with_chain(_library_model(base, state), 0.03, 0.04)
    assert all(s.stable_at_delay for s in report.segments) and not report.chain.stable_at_delay  # the premise
    joint, chain_line = numbers.verdicts()
    assert joint == (
        "joint by joint (each CoR alone, the others fixed; the paper's criterion): every segment stable at τ = 100 ms"
    )
    assert chain_line == (
        "chain (all 5 CoRs free), the same reflex at every joint: NOT stable at τ = 100 ms "
        f"(exact delay margin {delay_text(report.chain.exact.margin)})"
    )
    page = verdicts_html(numbers)
    assert page.index('data-verdict="joint"') < page.index('data-verdict="chain"')
    assert page.count(UNSTABLE_COLOUR) == 1 and page.index(UNSTABLE_COLOUR) > page.index('data-verdict="chain"')
