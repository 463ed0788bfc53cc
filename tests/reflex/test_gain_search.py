"""The seeded search over the chain's diagonal reflex gains and the single-mode bound (docs/chain.md).

The section "The delayed reflex" of docs/chain.md; the bound in docs/reflex.md.
"""

from __future__ import annotations

import numpy as np
import pytest

from spinectl import reflex
from spinectl.errors import ParameterError
from spinectl.model.linear_chain import LinearChain
from spinectl.reflex.gain_search import (
    objective,
    pendulum_delay_bound,
    search_chain_gains,
    single_mode_bound,
)
from spinectl.reflex.mimo import chain_delay_margin

LAG = 0.1
SMALL = dict(population=4, generations=6, restarts=4, restart_evaluations=250)
"""A budget for two joints (four gains)."""


def _chain(stiffness, damping, mass) -> LinearChain:
    """A two-joint chain with no controls: M q'' = K q + D q' + u."""
    return LinearChain(
        joints=("a", "b"), controls=(), control_class=(), stiffness_per_control=np.zeros((2, 2, 0)),
        damping_per_control=np.zeros((2, 2, 0)), stiffness_offset=np.asarray(stiffness, float),
        damping_offset=np.asarray(damping, float), mass_matrix=np.asarray(mass, float),
        lower=np.zeros(0), upper=np.zeros(0),
    )  # fmt: skip


# two uncoupled inverted pendulums: the chain's margin is the lesser of the joints'
THETA, S, D = np.array([1.0, 0.5]), np.array([1.0, 2.0]), np.array([-0.2, 0.0])
UNCOUPLED = _chain(np.diag(S), np.diag(D), np.diag(THETA))
COUPLED = _chain([[1.0, 0.6], [0.6, 2.0]], [[-0.2, 0.05], [0.05, -0.1]], [[1.0, 0.2], [0.2, 0.5]])


def _grid_best(theta, s, d, lag):
    """The largest exact segment margin (closed form, spinectl.reflex.delay_margin) on a fine (kp, kd) grid [s]."""
    kp = s * (1.0 + np.logspace(-6, 1, 200))[:, None]
    kd = np.logspace(-3, 2, 400)[None, :] * np.sqrt(theta * s)
    margin = reflex.delay_margin(s, d, theta, kp, kd, lag=lag).margin
    return float(np.max(np.where(np.isfinite(margin), margin, 0.0)))


@pytest.mark.parametrize(
    ("s", "theta", "lag", "d"),
    [(1.0, 1.0, 0.0, 0.0), (1.0, 1.0, 0.1, 0.0), (94.3**2, 1.0, 0.05, 0.0), (1.0, 1.0, 0.3, -0.5)],
)
def test_pendulum_bound_against_the_exact_margin_on_a_grid(s, theta, lag, d):
    """No gains on a fine grid beat the bound, and the best come within 2 % of it: the exact segment margin
    (spinectl.reflex.delay_margin, an independent closed form). T_a = D = 0 is Stépán's sqrt(2 theta / S);
    the third row is the lagged bound of a mode growing at 94.3/s, 2.2 ms."""
    bound = pendulum_delay_bound(s, theta, lag, d)
    if lag == 0 and d == 0:
        assert bound == pytest.approx(np.sqrt(2 * theta / s), rel=1e-14)
    best = _grid_best(theta, s, d, lag)
    assert 0.98 * bound < best < bound


def test_pendulum_bound_is_inf_for_a_stable_pendulum():
    """S <= 0: nothing to hold, no finite bound."""
    assert np.all(np.isinf(pendulum_delay_bound(np.array([0.0, -3.0]), 1.0, 0.05)))


def test_search_reaches_the_grid_best_of_an_uncoupled_chain():
    """Uncoupled joints: the best diagonal margin is the lesser of each joint's best, which a (kp, kd) grid of the
    exact segment margin gives; the search (starting from a rule unstable without delay) reaches it to 3 %,
    and it stays below the single-mode bound, which here is the lesser joint's pendulum bound (modes decouple)."""
    grid = min(_grid_best(t, s, d, LAG) for t, s, d in zip(THETA, S, D, strict=True))
    result = search_chain_gains(UNCOUPLED, S * 0.5, np.zeros(2), LAG, seed=1, **SMALL)
    assert result.rule_margin == 0.0
    assert result.margin > 0.97 * grid
    expected = min(pendulum_delay_bound(s, t, LAG, d) for t, s, d in zip(THETA, S, D, strict=True))
    assert result.bound.coupling == 0.0
    assert result.bound.bound == pytest.approx(expected, rel=1e-12)
    assert result.margin < result.bound.bound
    found = chain_delay_margin(UNCOUPLED.mass_matrix, np.diag(S), np.diag(D), result.kp, result.kd, LAG)
    assert found.margin == result.margin


def test_graded_objective_moves_an_unstable_start_to_stability():
    """From a rule unstable without delay, Nelder-Mead alone (no evolution) finds a positive margin: the objective
    grades unstable loops by their rightmost root (the margin alone is 0 there, flat)."""
    budget = dict(generations=0, restarts=3, restart_evaluations=300)
    result = search_chain_gains(COUPLED, [0.5, 0.5], [0.0, 0.0], LAG, **budget)
    assert result.rule_margin == 0.0 and result.margin > 0.0
    lower = objective(COUPLED, np.log10([0.5, 0.5, 1e-2, 1e-2]), LAG, 1.0)[0]
    nearer = objective(COUPLED, np.log10([2.0, 3.0, 1e-2, 1e-2]), LAG, 1.0)[0]
    assert lower > nearer > 1.0


def test_search_never_returns_less_than_the_rule():
    """Rule gains near the optimum (those of a longer search) with no budget come back unchanged with their own exact
    margin; with a budget the result is at least the rule's margin."""
    best = search_chain_gains(COUPLED, [3.0, 3.0], [1.0, 1.0], LAG, seed=2, **SMALL)
    kp, kd = best.kp * 1.02, best.kd * 0.98
    rule = chain_delay_margin(COUPLED.mass_matrix, COUPLED.stiffness(()), COUPLED.damping(()), kp, kd, LAG).margin
    none = search_chain_gains(COUPLED, kp, kd, LAG, generations=0, restarts=0)
    assert none.margin == rule and np.array_equal(none.kp, kp) and np.array_equal(none.kd, kd)
    some = search_chain_gains(COUPLED, kp, kd, LAG, seed=5, population=2, generations=2, restarts=1)
    assert some.rule_margin == rule and some.margin >= rule


def test_a_rule_with_zero_gains_is_kept_when_nothing_beats_it():
    """Joint b is self-stable (S = -4, damped) and the rule gives it no reflex: 0 lies outside the log-gain box, so the
    search starts b at its scale, where the delayed reflex costs margin (0.20 s against the rule's 0.83 s, both
    exact); without a budget the rule comes back, gains and margin."""
    chain = _chain(np.diag([1.0, -4.0]), np.diag([-0.2, -0.5]), np.diag([1.0, 0.5]))
    kp, kd = np.array([1.3, 0.0]), np.array([1.2, 0.0])
    rule = chain_delay_margin(chain.mass_matrix, chain.stiffness(()), chain.damping(()), kp, kd, LAG).margin
    result = search_chain_gains(chain, kp, kd, LAG, generations=0, restarts=0)
    assert result.margin == rule > 0.5 and np.array_equal(result.kp, kp) and np.array_equal(result.kd, kd)


def test_same_seed_same_result_and_bound_above_it():
    """The search is reproducible: the same seed gives the same gains, margin and count; the coupled chain's margin is
    below its single-mode bound (checked here, not proved for joint gains)."""
    first, second = (search_chain_gains(COUPLED, [3.0, 3.0], [1.0, 1.0], LAG, seed=7, **SMALL) for _ in range(2))
    assert np.array_equal(first.kp, second.kp) and np.array_equal(first.kd, second.kd)
    assert first.margin == second.margin and first.evaluations == second.evaluations
    assert first.margin > first.rule_margin and first.margin < first.bound.bound
    assert first.bound.coupling > 0
    assert first.bound.bound == pytest.approx(single_mode_bound(COUPLED, LAG).bound)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [(dict(rule_kp=[1.0], rule_kd=[0.0, 0.0]), "rule_kp"), (dict(rule_kp=[1.0, 1.0], rule_kd=[0.0, -1.0]), "rule_kd"),
     (dict(rule_kp=[1.0, 1.0], rule_kd=[0.0, 0.0], restarts=-1), "restarts"),
     (dict(rule_kp=[1.0, 1.0], rule_kd=[0.0, 0.0], population=1.5), "population")],
)  # fmt: skip
def test_bad_inputs_name_their_field(kwargs, field):
    """Gains not one per joint or negative, budgets not integers above their least: a ParameterError naming them."""
    with pytest.raises(ParameterError, match=field):
        search_chain_gains(COUPLED, **kwargs)
