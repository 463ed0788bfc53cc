"""Each control's contribution to the least eigenvalue of -K (spinectl.model.contributions).

The derivative d lambda_min / d u_i = -v^T K_i v is checked against central differences of lambda_min in u_i
on the paper's chain (spinectl.model.chain.linear_chain); Euler's identity (the module docstring's
derivation) holds to rounding; a repeated least eigenvalue is said, not differentiated; the removal method's
ordering is checked on a made-up chain whose eigenvalues are known in closed form.
"""

from __future__ import annotations

import numpy as np
import pytest

from spinectl.errors import ParameterError
from spinectl.model.chain import linear_chain
from spinectl.model.config import load_preset
from spinectl.model.contributions import contributions, least_mode, resolve_groups
from spinectl.model.linear_chain import LinearChain

STEP = 1e-4
"""Central-difference step of u [cm^2]: truncation ~STEP^2 lambda''' (lambda'' ~ 1 N m/rad per cm^4 here),
rounding ~eps |K| / STEP ~ 1e-9 N m/rad per cm^2."""

FD_TOLERANCE = 1e-6
"""Relative to the largest |derivative|: above both error terms of :data:`STEP` by two orders."""


def _lambda_min(chain, u, k=0.0):
    s = chain.stiffness(u, k)
    return np.linalg.eigvalsh(-0.5 * (s + s.T))[0]


def _diagonal_chain(offset, per_control, names=None):
    """A made-up chain: K_0 = diag(offset), K_i = diag(per_control[i]) [N m/rad]; unit mass."""
    per = np.array([np.diag(d) for d in per_control], float).transpose(1, 2, 0)
    n, m = len(offset), per.shape[-1]
    return LinearChain(
        joints=tuple(f"j{j}" for j in range(n)),
        controls=tuple(names or (f"c{i}" for i in range(m))),
        control_class=("global",) * m,
        stiffness_per_control=per,
        damping_per_control=np.zeros((n, n, m)),
        stiffness_offset=np.diag(offset).astype(float),
        damping_offset=np.zeros((n, n)),
        mass_matrix=np.eye(n),
        lower=np.zeros(m),
        upper=np.ones(m),
    )


@pytest.mark.parametrize(("e", "lam", "u"), [(0.03, 0.04, [5.0, 5.0, 5.0]), (0.01, 0.02, [2.0, 8.0, 4.0])])
def test_the_derivative_is_the_central_difference_of_lambda_min_on_the_papers_chain(e, lam, u):
    """d lambda_min / d u_i against (lambda(u + h e_i) - lambda(u - h e_i)) / 2h, h = STEP cm^2, to FD_TOLERANCE
    relative; the first point is docs/chain.md's, the second another posture and activation."""
    chain = linear_chain(load_preset("wagner2012"), e, lam)
    c = contributions(chain, u)
    assert not c.least.degenerate
    fd = []
    for i in range(chain.n_controls):
        du = np.eye(chain.n_controls)[i] * STEP
        fd.append((_lambda_min(chain, np.add(u, du)) - _lambda_min(chain, np.subtract(u, du))) / (2 * STEP))
    np.testing.assert_allclose(c.derivative, fd, rtol=0, atol=FD_TOLERANCE * np.max(np.abs(fd)))


def test_eulers_identity_sums_the_shares_and_the_offset_to_lambda_min():
    """sum_i u_i d lambda/du_i + (-v^T (K_0 - diag k) v) = lambda_min (module docstring), to rounding, on the
    paper's chain with local stiffness and on a random chain (seeded) whose K_i are not diagonal."""
    chain = linear_chain(load_preset("wagner2012"), 0.03, 0.04)
    c = contributions(chain, [3.0, 6.0, 1.0], local_stiffness=[10.0, 20.0, 30.0, 40.0, 50.0])
    assert c.offset + c.share.sum() == pytest.approx(c.least.eigenvalue, rel=1e-12, abs=1e-9)
    assert c.least.eigenvalue == pytest.approx(_lambda_min(chain, [3.0, 6.0, 1.0], [10, 20, 30, 40, 50]), rel=1e-12)
    rng = np.random.default_rng(7)
    n, m = 4, 6
    per = rng.normal(size=(n, n, m))
    base = _diagonal_chain(np.zeros(n), np.zeros((m, n)))
    random = LinearChain(
        **{
            **base.__dict__,
            "stiffness_per_control": per + per.transpose(1, 0, 2),
            "stiffness_offset": rng.normal(size=(n, n)),
        }
    )
    u = rng.uniform(size=m)
    c = contributions(random, u)
    assert c.offset + c.share.sum() == pytest.approx(_lambda_min(random, u), rel=1e-12)


def test_a_restoring_control_raises_the_index_by_its_stiffness_in_the_mode():
    """The sign convention: a control whose K_i = -I (a restoring spring at every joint, -K positive) has
    d lambda/du = +1 whatever the mode; one with K_i = +diag(2, 0) (a compressive load on joint 0) -2 v_0^2."""
    chain = _diagonal_chain([-1.0, -3.0], [[-1.0, -1.0], [2.0, 0.0]])
    c = contributions(chain, [0.5, 0.5])
    v = c.least.mode
    assert c.derivative[0] == pytest.approx(1.0, rel=1e-14)
    assert c.derivative[1] == pytest.approx(-2.0 * v[0] ** 2, rel=1e-14)


@pytest.mark.parametrize("n_repeated", [2, 3])
def test_a_repeated_least_eigenvalue_is_said_and_not_differentiated(n_repeated):
    """K_0 = -diag(1, ..., 1, 5) with n_repeated ones and the control on joint 0 only at u = 0: lambda_min = 1 is
    repeated, so its derivative depends on the direction (+1 up, 0 down); the derivatives are NaN, the multiplicity
    is said in the table and the JSON, and the removal method still answers."""
    offset = [-1.0] * n_repeated + [-5.0]
    chain = _diagonal_chain(offset, [[-1.0] + [0.0] * n_repeated])
    c = contributions(chain, [0.0], remove=["c0"])
    assert c.least.multiplicity == n_repeated and c.least.degenerate
    assert np.all(np.isnan(c.derivative)) and np.isnan(c.offset)
    assert "repeated" in c.table() and c.to_dict()["degenerate"] is True
    assert c.removals["c0"].least_eigenvalue == pytest.approx(1.0)
    # raised, the restoring control lifts joint 0 alone: lambda_min stays 1 (the other joints), rate 0
    assert c.derivative_up[0] == pytest.approx(0.0, abs=1e-15)


def test_the_one_sided_rate_at_a_repeated_eigenvalue_is_the_central_difference_going_up():
    """At -K = diag(1, 1, 5) a control K_1 = [[1, 1, 0], [1, 0, 0], [0, 0, 0]] (coupling the two repeated
    joints, destabilising joint 0): lambda_min(t) for small t > 0 is 1 + t mu, mu the least eigenvalue of
    -[[1, 1], [1, 0]] = -(1 + sqrt 5)/2 (Kato 1995, ch. II); the one-sided difference (lambda(h) - lambda(0))/h,
    h = 1e-7, agrees to 1e-6, and the two-sided derivative is not given."""
    per = np.zeros((3, 3, 1))
    per[:2, :2, 0] = [[1.0, 1.0], [1.0, 0.0]]
    base = _diagonal_chain([-1.0, -1.0, -5.0], [[0.0, 0.0, 0.0]])
    chain = LinearChain(**{**base.__dict__, "stiffness_per_control": per})
    c = contributions(chain, [0.0])
    mu = -(1 + np.sqrt(5)) / 2
    h = 1e-7
    assert c.derivative_up[0] == pytest.approx(mu, rel=1e-12) and np.isnan(c.derivative[0])
    assert (_lambda_min(chain, [h]) - _lambda_min(chain, [0.0])) / h == pytest.approx(mu, rel=1e-6)


def test_a_near_repeated_eigenvalue_outside_the_tolerance_is_differentiated():
    """Eigenvalues 1 and 1 + 1e-3 of -K: simple (gap 1e-3 > 1e-6 times 5), so the derivative is given."""
    chain = _diagonal_chain([-1.0, -1.001, -5.0], [[-1.0, 0.0, 0.0]])
    mode = least_mode(chain.stiffness([0.0]))
    assert mode.multiplicity == 1 and mode.gap == pytest.approx(1e-3)


def test_the_removal_method_orders_the_controls_as_their_closed_form():
    """Two joints, -K = diag(10 u_big + u_small - 2 u_load) + diag(0, 1), u = 1: lambda_min = 9 (joint 0).
    Removed: big -> -1 (-111.1 %), small -> 8 (-11.1 %), load -> 11 (+22.2 %), each exactly (joint 0 the least)."""
    chain = _diagonal_chain([0.0, -1.0], [[-10, -10], [-1, -1], [2, 2]], names=["big", "small", "load"])
    c = contributions(chain, [1.0, 1.0, 1.0], remove=["big", "small", "load"])
    assert c.least.eigenvalue == pytest.approx(9.0)
    changes = {k: c.removals[k].percent_change for k in ("big", "small", "load")}
    assert changes == pytest.approx({"big": -1000 / 9, "small": -100 / 9, "load": 200 / 9})
    assert sorted(changes, key=changes.get) == ["big", "small", "load"]
    assert c.removals["class:global"].least_eigenvalue == pytest.approx(0.0, abs=1e-12)


def test_the_removal_method_uses_the_resolver_and_names_its_status():
    """With a resolver (an optimum re-solved), the index is taken at the re-solved controls: here the small
    control doubles to replace what is removed (joint 0: 2 - 2 = 0, joint 1: 1), and an infeasible re-solve is NaN."""
    chain = _diagonal_chain([0.0, -1.0], [[-10, -10], [-1, -1], [2, 2]], names=["big", "small", "load"])

    def resolve(held):
        if held[1]:
            return None, "re-solved: infeasible"
        return np.where(held, 0.0, [1.0, 2.0, 1.0]), "re-solved: optimal"

    c = contributions(chain, [1.0, 1.0, 1.0], remove=["big", "small"], resolve=resolve)
    assert c.removals["big"].least_eigenvalue == pytest.approx(0.0, abs=1e-12)
    assert np.isnan(c.removals["small"].least_eigenvalue) and "infeasible" in c.table()
    assert c.removals["big"].status == "re-solved: optimal"


def test_groups_by_a_prefix_a_regex_or_a_list_and_their_errors():
    """A group is a regular expression matched at the start of a name (a prefix is one) or a list of names;
    one matching none, a bad expression or an unknown name is one ParameterError naming the group."""
    names = ("IL_r", "IL_l", "LTpT_r", "rect_abd_r", "EO1_r")
    assert resolve_groups(names, {"il": "IL"})["il"] == ("IL_r", "IL_l")
    assert resolve_groups(names, {"back": "IL|LTp"})["back"] == ("IL_r", "IL_l", "LTpT_r")
    assert resolve_groups(names, {"abs": ["EO1_r", "rect_abd_r"]})["abs"] == ("rect_abd_r", "EO1_r")
    for bad in ({"x": "abd"}, {"x": "("}, {"x": ["nope"]}):
        with pytest.raises(ParameterError, match="group x"):
            resolve_groups(names, bad)


def test_per_class_and_group_sums_and_the_json():
    """A class's or group's derivative and share are the sums over its members; the JSON lists the largest first."""
    chain = _diagonal_chain([0.0, -1.0], [[-10, -10], [-1, -1], [2, 2]], names=["big", "small", "load"])
    c = contributions(chain, [1.0, 0.5, 1.0], groups={"springs": ["big", "small"]})
    doc = c.to_dict(2)
    assert [row["name"] for row in doc["controls"]] == ["big", "load"]
    assert doc["groups"]["springs"]["share_Nm_per_rad"] == pytest.approx(10.0 + 0.5)
    assert doc["classes"]["global"]["derivative_Nm_per_rad_per_activation"] == pytest.approx(10 + 1 - 2)


def _paper_point(e=0.03, lam=0.04, pcsa_cm2=(2.0, 8.0, 4.0)):
    from spinectl.model.operating_point import OperatingPoint

    model = load_preset("wagner2012")
    return model, OperatingPoint(model, e, lam, np.repeat(pcsa_cm2, 2) * 1e-4)


@pytest.mark.parametrize(("e", "lam", "pcsa"), [(0.03, 0.04, (2.0, 8.0, 4.0)), (0.01, 0.02, (6.0, 1.0, 3.0))])
def test_pairs_sum_their_muscles_as_the_paired_chain_differentiates(e, lam, pcsa):
    """A pair's PCSA x sets both its muscles, so on the paired chain (linear_chain's own controls)
    d lambda/dx_pair = the sum of its two muscles' derivatives on the per-muscle chain that pair_contributions
    builds: two chains, one identity. Each pair's part of a CoR's -K_jj and the offset sum to -K_jj(x)."""
    from spinectl.model.contributions import pair_contributions

    model, point = _paper_point(e, lam, pcsa)
    pairs = pair_contributions(point)
    paired = linear_chain(model, e, lam)
    whole = contributions(paired, pcsa)
    summed = [pairs.contributions.sums(m)[0] for m in pairs.contributions.groups.values()]
    np.testing.assert_allclose(summed, whole.derivative, rtol=1e-10)
    assert pairs.chain_share() == pytest.approx(whole.share, rel=1e-10)
    restoring = -np.diag(paired.stiffness(pcsa)) + np.diag(paired.stiffness_offset)
    np.testing.assert_allclose(pairs.cor_share().sum(axis=1), restoring, rtol=1e-10)


def test_which_pair_stabilises_each_cor_and_the_chain():
    """At docs/chain.md's point with only oblique_outer active (the paper's optimum is so: the other pairs at 0),
    it is the pair that stabilises every CoR; no pair gives the chain's least mode restoring stiffness there
    (its share is negative: the chain is unstable though each CoR is stable, docs/chain.md), said as none."""
    from spinectl.model.contributions import pair_contributions

    _, point = _paper_point(pcsa_cm2=(0.0, 18.0, 0.0))
    doc = pair_contributions(point).to_dict()
    assert doc["cor_stabilised_most_by"] == ["oblique_outer"] * 5
    assert doc["chain_share_Nm_per_rad"][1] < 0 and doc["chain_stabilised_most_by"] is None
    assert "* the largest" in pair_contributions(point).table()
