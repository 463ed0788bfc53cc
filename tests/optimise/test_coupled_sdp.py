"""The chain's semidefinite programmes on a chain built by hand (spinectl/optimise/coupled/sdp.py, docs/chain.md).

Two joints, three controls, every matrix written down: the chain's gravity K_0 = g 1 1' (it tips
both joints together), two local controls that stiffen one joint each, K_1 = -e_1 e_1',
K_2 = -e_2 e_2', and one global control across both, K_3 = -1 1'. So

    -K(u) = diag(u_1, u_2) + (u_3 - g) 1 1',

and with u_1 = u_2 = s its eigenvalues are s (along (1, -1)) and s + 2 (u_3 - g) (along (1, 1)).
Each programme is convex and unchanged by swapping the joints, so it has an optimum with
u_1 = u_2 (the mean of any optimum and its mirror image); over those the LMI -K(u) >= mu I is
the two linear rows s >= mu, s + 2 (u_3 - g) >= mu, and the optimum is a vertex of a small LP.
"""

from __future__ import annotations

import numpy as np
import pytest

from spinectl.errors import ParameterError
from spinectl.model.linear_chain import LinearChain
from spinectl.optimise.coupled import sdp

G, MU = 3.0, 0.5
"""g [N m/rad] and the margin mu [N m/rad]."""


def _chain(upper=np.inf) -> LinearChain:
    e1, e2, one = np.diag([1.0, 0.0]), np.diag([0.0, 1.0]), np.ones((2, 2))
    return LinearChain(
        joints=("top", "bottom"),
        controls=("local_top", "local_bottom", "global"),
        control_class=("local", "local", "global"),
        stiffness_per_control=np.stack([-e1, -e2, -one], axis=-1),
        damping_per_control=np.zeros((2, 2, 3)),
        stiffness_offset=G * one,
        damping_offset=-0.5 * np.eye(2),
        mass_matrix=2.0 * np.eye(2),
        lower=np.zeros(3),
        upper=np.array([np.inf, np.inf, upper]),
    )


def test_least_control_is_the_vertex_of_the_symmetric_lp():
    """Unit prices: min 2 s + u_3 over s >= mu, s + 2 u_3 - 2 g >= mu, u_3 >= 0 has the vertices
    (s, u_3) = (mu, g), cost 2 mu + g = 4, and (mu + 2 g, 0), cost 2 mu + 4 g = 13: the global
    control carries the tipping mode, the local ones only the margin of the other."""
    status, u = sdp.least_control_sdp(_chain(), np.ones(3), MU, tolerance=1e-9)
    assert status == "optimal"
    np.testing.assert_allclose(u, [MU, MU, G], atol=1e-6)
    assert np.linalg.eigvalsh(-_chain().stiffness(u))[0] >= MU - 1e-6


def test_a_bound_on_the_global_control_moves_the_optimum_along_the_closed_form():
    """With u_3 <= U < g (the chain's bounds, LinearChain.bound_rows): u_3 = U and
    s = mu + 2 (g - U), cost 2 mu + 4 g - 3 U; U = 1: u = (4.5, 4.5, 1), cost 11."""
    chain = _chain(upper=1.0)
    lhs, rhs = chain.bound_rows()
    assert lhs.shape == (4, 3) and rhs.tolist() == [0.0, 0.0, 0.0, 1.0]  # -u <= 0, u_3 <= 1 (the others unbounded)
    status, u = sdp.least_control_sdp(chain, np.ones(3), MU, tolerance=1e-9)
    assert status == "optimal"
    np.testing.assert_allclose(u, [MU + 2 * (G - 1), MU + 2 * (G - 1), 1.0], atol=1e-6)
    np.testing.assert_allclose(u.sum(), 2 * MU + 4 * G - 3.0, atol=1e-6)


def test_least_local_stiffness_at_fixed_controls():
    """At u = 0, K = g 1 1': diag(k) - K >= mu I with k_1 = k_2 = k has the eigenvalues k - mu and
    k - mu - 2 g, so the least sum is 2 (mu + 2 g) = 13; with u_3 = g the tipping is carried and
    only the margin is left: 2 mu = 1."""
    chain = _chain()
    status, k = sdp.least_local_stiffness_of(chain, np.zeros(3), MU, 1e-9)
    assert status == "optimal"
    np.testing.assert_allclose(k, [MU + 2 * G] * 2, atol=1e-6)
    _, k = sdp.least_local_stiffness_of(chain, [0.0, 0.0, G], MU, 1e-9)
    np.testing.assert_allclose(k, [MU, MU], atol=1e-6)


@pytest.mark.parametrize(("weight", "expected"), [(0.1, 0.1 * 2 * (MU + 2 * G) / 1.0), (10.0, 2 * MU + G)])
def test_priced_added_stiffness_against_the_controls(weight, expected):
    """(c) with added stiffness k at w per unit (kappa = 1): it is the local controls again at the
    price w, so the optimum is the cheaper vertex of min 2 w s' + 2 s + u_3 (k_1 = k_2 = s' and
    u_1 = u_2 = s act alike): w = 0.1, all by k: k = mu + 2 g each, cost 0.1 x 13 = 1.3; w = 10,
    k unused: the least control's 2 mu + g = 4. With a budget of 0 on k: (b) itself."""
    chain = _chain()
    status, u, k = sdp.least_cost_with_local_sdp(chain, np.ones(3), MU, tolerance=1e-9, local_weight=weight)
    assert status == "optimal"
    np.testing.assert_allclose(u.sum() + weight * k.sum(), expected, atol=1e-5)
    _, u0, k0 = sdp.least_cost_with_local_sdp(chain, np.ones(3), MU, tolerance=1e-9, local_budget=0.0)
    np.testing.assert_allclose(u0, [MU, MU, G], atol=1e-5)
    np.testing.assert_allclose(k0, 0.0, atol=1e-6)


def test_the_chain_at_fixed_controls_is_the_same_linear_system():
    """LinearChain.at(u): no controls, and its K and D are those of the chain at u, bit for bit."""
    chain, u = _chain(), np.array([1.0, 2.0, 0.5])
    fixed = chain.at(u)
    assert fixed.n_controls == 0 and fixed.joints == chain.joints
    np.testing.assert_array_equal(fixed.stiffness(()), chain.stiffness(u))
    np.testing.assert_array_equal(fixed.damping(()), chain.damping(u))


def test_local_controls_at_a_fixed_global_activation():
    """LinearChain.fix: the global control held at u_3 (moved into K_0), the local ones left to (b).
    Over u_1 = u_2 = s the rows are s >= mu and s >= mu + 2 (g - u_3): at u_3 = 2, s = mu + 2 = 2.5;
    at u_3 = g the margin alone, s = mu. The fixed chain's K equals the full chain's, to rounding."""
    chain = _chain()
    held = chain.fix({"global": 2.0})
    assert held.controls == ("local_top", "local_bottom") and held.control_class == ("local", "local")
    np.testing.assert_allclose(held.stiffness([1.0, 2.0]), chain.stiffness([1.0, 2.0, 2.0]), atol=1e-12)
    for u3, s in ((2.0, MU + 2 * (G - 2.0)), (G, MU)):
        status, u = sdp.least_control_sdp(chain.fix({"global": u3}), np.ones(2), MU, tolerance=1e-9)
        assert status == "optimal"
        np.testing.assert_allclose(u, [s, s], atol=1e-6)
    with pytest.raises(ParameterError, match="no control of the chain: nope"):
        chain.fix({"nope": 1.0})


@pytest.mark.parametrize(
    ("criterion", "expected"),
    [("joints", [7 / 6, 7 / 6, 7 / 3]), ("chain", [13 / 18, 13 / 18, 26 / 9])],
)
def test_least_quadratic_cost_under_each_criterion(criterion, expected):
    """(d) min u_1^2 + u_2^2 + u_3^2, strictly convex and symmetric, so its optimum has u_1 = u_2 = s
    and is min 2 s^2 + u_3^2 on the criterion's rows: joints, -K_jj = s + u_3 - g >= mu,
    the active row by Lagrange (4 s = lambda, 2 u_3 = lambda) u_3 = 2 s, 3 s = g + mu: s = 7/6;
    the chain, s >= mu (inactive) and s + 2 (u_3 - g) >= mu active, u_3 = 4 s, 9 s = mu + 2 g: s = 13/18."""
    status, u = sdp.least_quadratic_cost_sdp(_chain(), np.ones(3), MU, criterion, tolerance=1e-9)
    assert status == "optimal"
    np.testing.assert_allclose(u, expected, atol=1e-6)


def test_least_quadratic_cost_with_equality_rows():
    """Equality rows A u = b: without a criterion, u_1 + u_2 + u_3 = 3 gives the least-norm point of that
    plane, u = (1, 1, 1); u_3 = 1 held, the chain's rows become s >= mu and s >= mu + 2 (g - 1) = 4.5,
    so u = (4.5, 4.5, 1); u_3 = 2 with the bound u_3 <= 1 is infeasible, an answer (status, None);
    an unknown criterion is refused in one line."""
    plane = (np.ones((1, 3)), np.array([3.0]))
    status, u = sdp.least_quadratic_cost_sdp(_chain(), np.ones(3), MU, "none", equalities=plane, tolerance=1e-9)
    assert status == "optimal"
    np.testing.assert_allclose(u, [1.0, 1.0, 1.0], atol=1e-6)
    rows = (np.array([[0.0, 0.0, 1.0]]), np.array([1.0]))
    status, u = sdp.least_quadratic_cost_sdp(_chain(), np.ones(3), MU, "chain", equalities=rows, tolerance=1e-9)
    assert status == "optimal"
    np.testing.assert_allclose(u, [MU + 2 * (G - 1), MU + 2 * (G - 1), 1.0], atol=1e-6)
    status, u = sdp.least_quadratic_cost_sdp(
        _chain(upper=1.0), np.ones(3), MU, "none", equalities=(rows[0], np.array([2.0]))
    )
    assert status.startswith("infeasible") and u is None
    with pytest.raises(ParameterError, match="criterion: must be one of"):
        sdp.least_quadratic_cost_sdp(_chain(), np.ones(3), MU, "diagonal")
