"""The Pareto front between the global PCSA total and the local stiffness total (docs/chain.md, "The Pareto front")."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from spinectl import load_preset
from spinectl.errors import ParameterError
from spinectl.model import config
from spinectl.optimise.coupled import (
    coupled_data,
    joint_optimum,
    least_global_within_budget_sdp,
    min_global_pcsa,
    pareto_front,
)
from spinectl.units import M2_PER_CM2


@pytest.fixture(scope="module")
def stiff():
    """default with a passive stiffness of 100 N m/rad: here global muscles alone can stabilise the chain
    (min_global_pcsa is optimal at A, 34.3 cm^2), so the front has both ends."""
    return config.set_parameters(load_preset("default"), {"passive.stiffness": 100.0})


@pytest.fixture(scope="module")
def front(stiff):
    return pareto_front(stiff, 0.0, 0.0, 7)


def _weighted(model, weight):
    return joint_optimum(model.replace(local=dataclasses.replace(model.local, cost_weight=weight)), 0.0, 0.0)


def test_the_trade_off_is_monotone_and_convex(front):
    """More local stiffness allowed, less global PCSA needed: the global total falls strictly, the local
    total rises within its budget, and the front is convex (the optimal value of a convex programme is
    convex in the right-hand side of its constraint)."""
    assert all(p.ok for p in front.points)
    g, k = front.global_total, front.local_total
    assert np.all(np.diff(g) < 0) and np.all(np.diff(k) > 0)
    assert np.all(k <= front.budgets * (1 + 1e-6) + 1e-6)
    assert np.all(np.diff(g, 2) >= -1e-6 * g[0])
    assert all(p.margin >= 0 for p in front.points)  # each point's chain is statically stable (numpy eigvalsh)


def test_ends_are_global_only_and_least_local(stiff, front):
    """Budget 0 is min_global_pcsa (problem (b), a separate SDP with the per-segment rows); the far end is
    the joint optimum with local muscles almost free (w = 1e-4: the least global PCSA, then the least
    local stiffness), both totals."""
    alone = min_global_pcsa(stiff, 0.0, 0.0)
    np.testing.assert_allclose(front.global_total[0], alone.total_pcsa, rtol=1e-5)
    assert front.local_total[0] <= 1e-6  # N m/rad, the solver's tolerance
    cheap = _weighted(stiff, 1e-4)
    np.testing.assert_allclose(front.global_total[-1], cheap.total_pcsa, rtol=1e-3, atol=1e-9)
    np.testing.assert_allclose(front.local_total[-1], np.sum(cheap.local_stiffness), rtol=1e-5)


def test_the_joint_optimum_lies_on_the_front(stiff):
    """The weighted joint optimum (w = 1) is a Pareto point: with its local total as the budget, the least
    global PCSA is its global total."""
    joint = _weighted(stiff, 1.0)
    data = coupled_data(stiff, 0.0, 0.0)
    status, x, _ = least_global_within_budget_sdp(data, float(np.sum(joint.local_stiffness)))
    assert status == "optimal"
    np.testing.assert_allclose(data.problem.weights @ x * M2_PER_CM2, joint.total_pcsa, rtol=1e-4)


def test_without_a_global_only_solution_the_first_point_is_infeasible():
    """wagner2012 at A: no global activation alone stabilises the chain (the issue's finding), so budget 0 is
    'infeasible' with NaN, as min_global_pcsa says; the rest of the front is optimal. JSON and table."""
    model = load_preset("wagner2012")
    front = pareto_front(model, 0.0, 0.0, 3)
    assert min_global_pcsa(model, 0.0, 0.0).status == front.points[0].status == "infeasible"
    assert np.isnan(front.global_total[0]) and all(p.ok for p in front.points[1:])
    document = json.loads(json.dumps(front.to_dict(model)))
    assert document["pareto"]["status"][0] == "infeasible" and len(document["pareto"]["global_pcsa_total_cm2"]) == 3
    assert "infeasible" in front.table(model)


def test_too_few_points_name_the_field(stiff):
    with pytest.raises(ParameterError, match="points"):
        pareto_front(stiff, 0.0, 0.0, 1)


def test_no_activation_at_all_is_an_infeasible_front():
    """A damping margin of 1e4 N m s/rad with at most 1 cm^2 per variable: the damping rows alone cannot
    hold (joint_optimum says 'infeasible' too), so every point is NaN with that status, no exception."""
    model = config.set_parameters(
        load_preset("wagner2012"), {"optimisation.damping_margin": 1e4, "optimisation.pcsa_max": 1e-4}
    )
    front = pareto_front(model, 0.0, 0.0, 3)
    assert joint_optimum(model, 0.0, 0.0).status == "infeasible"
    assert [p.status for p in front.points] == ["infeasible"] * 3
    assert np.all(np.isnan(front.budgets)) and np.all(np.isnan(front.global_total))
