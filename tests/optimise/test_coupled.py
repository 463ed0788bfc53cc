"""Coupled stability of the chain: the unstable modes at the per-segment optimum and the three SDPs (docs/chain.md)."""

from __future__ import annotations

import dataclasses

import cvxpy as cp
import numpy as np
import pytest
import scipy.linalg

from spinectl import load_preset, optimise
from spinectl.errors import ParameterError
from spinectl.model import chain
from spinectl.model.checks import checked_coefficients
from spinectl.model.mechanics import segment_coefficients
from spinectl.model.params import Body, Passive
from spinectl.model.stability import segment_stability
from spinectl.optimise import coupled
from spinectl.optimise.problem import inequalities, problem_data

LOWER = 1 - 1e-4
"""Lowering an optimum's objective by 1e-4 relative must leave the feasible set."""

TOL = 1e-6
"""Feasibility of the LMI [N m/rad], far above the solver's 1e-9 and far below any margin."""


def _with(model, **settings):
    return model.replace(optimisation=dataclasses.replace(model.optimisation, **settings))


def _null_modes(coefficients):
    """Orthonormal joint modes that change no fibre length to first order: null(dl/dq)."""
    _, sing, rows = np.linalg.svd(coefficients.length_gradient)
    return rows[np.sum(sing > 1e-10 * sing[0]) :].T


def test_segment_optimum_leaves_four_chain_modes_unstable():
    """The claim of docs/chain.md ("The finding"), at preset wagner2012, position A (E = Lambda = 0), on the LP optimum:
    the diagonal of K is S_k, all < 0 (self-stable segment by segment), yet K has 4 positive
    eigenvalues; docs/chain.md reports -K's as about -58 ... +258 N m/rad."""
    model = load_preset("wagner2012")
    opt = optimise.solve_point(model, 0.0, 0.0)
    stiffness = chain.chain_coefficients(model, 0.0, 0.0).stiffness(opt.pcsa)
    per_segment = segment_coefficients(model, 0.0, 0.0).stiffness(opt.pcsa)
    np.testing.assert_allclose(np.diag(stiffness), per_segment, rtol=1e-12, atol=1e-9)
    assert np.all(per_segment <= -model.optimisation.stability_margin * (1 - 1e-6))
    eigs = np.linalg.eigvalsh(-stiffness)
    assert np.sum(eigs < 0) == 4
    assert eigs[0] == pytest.approx(-58, abs=1) and eigs[-1] == pytest.approx(258, abs=1)
    assert chain.coupled_margin(stiffness) == pytest.approx(eigs[0])


@pytest.mark.parametrize("preset", ["default", "wagner2012"])
@pytest.mark.parametrize(("E", "L"), [(0.0, 0.0), (0.03, 0.04)])
def test_global_muscles_alone_cannot_stabilise_the_chain(preset, E, L):
    """An independent certificate of (b)'s infeasibility: on the null modes N of dl/dq, every
    muscle's K_i is positive definite (its tension buckles the chain; the f' term is zero there)
    and so is gravity's, so N'K(x)N > 0 for every x >= 0 and -K(x) >= mu I is impossible."""
    model = load_preset(preset)
    coefficients = chain.chain_coefficients(model, E, L)
    modes = _null_modes(coefficients)
    assert modes.shape[1] >= 2  # rank(dl/dq) <= 3 of 5 joints
    per_muscle = np.einsum("ja,jkm,kb->mab", modes, coefficients.stiffness_per_pcsa, modes)
    assert np.all(np.linalg.eigvalsh(per_muscle) > 0)
    assert np.all(np.linalg.eigvalsh(modes.T @ coefficients.stiffness(np.zeros(6)) @ modes) > 0)
    result = coupled.min_global_pcsa(model, E, L)
    assert result.status in optimise.INFEASIBLE_STATUSES and not result.ok
    assert np.isnan(result.total_pcsa) and np.isnan(result.margin)


def test_every_activation_leaves_as_many_unstable_modes_as_null_modes(rng):
    """By Courant-Fischer, K > 0 on the null modes gives K at least dim(N) positive eigenvalues."""
    model = load_preset("default")
    coefficients = chain.chain_coefficients(model, 0.03, 0.04)
    n_modes = _null_modes(coefficients).shape[1]
    for pcsa in rng.uniform(0, 50e-4, (20, 6)):
        assert np.sum(np.linalg.eigvalsh(coefficients.stiffness(pcsa)) > 0) >= n_modes


def _dual_bound(stiffness, margin):
    """max <Z, K + mu I> over Z >= 0, diag(Z) <= 1: by weak duality a lower bound on sum(k) of (a)."""
    n = stiffness.shape[0]
    z = cp.Variable((n, n), PSD=True)
    problem = cp.Problem(cp.Maximize(cp.trace(z @ (stiffness + margin * np.eye(n)))), [cp.diag(z) <= 1])
    problem.solve(solver="CLARABEL")
    value = z.value
    assert np.linalg.eigvalsh(value).min() >= -1e-7 and np.diag(value).max() <= 1 + 1e-7
    return float(np.sum(value * (stiffness + margin * np.eye(n))))


@pytest.mark.parametrize("preset", ["default", "wagner2012"])
def test_least_local_stiffness_is_feasible_and_minimal(preset):
    """(a) at the LP optimum: eigvalsh shows the LMI holds, a 1e-4 smaller k breaks it, and the
    dual SDP's bound meets sum(k) (a second problem: the two are optimal together)."""
    model = load_preset(preset)
    E, L = 0.03, 0.04
    opt = optimise.solve_point(model, E, L)
    result = coupled.least_local_stiffness(model, E, L, opt.pcsa)
    assert result.ok
    mu = model.optimisation.stability_margin
    stiffness = chain.chain_coefficients(model, E, L).stiffness(opt.pcsa)
    k = result.local_stiffness
    assert np.all(k >= 0)
    assert chain.coupled_margin(stiffness - np.diag(k)) >= mu - 1e-12
    assert result.margin == pytest.approx(chain.coupled_margin(stiffness - np.diag(k)))
    assert chain.coupled_margin(stiffness - np.diag(LOWER * k)) < mu
    assert _dual_bound(stiffness, mu) == pytest.approx(k.sum(), rel=1e-6)
    np.testing.assert_allclose(result.local_pcsa, k / chain.local_stiffness_per_pcsa(model), rtol=1e-12)
    np.testing.assert_allclose(result.pcsa, opt.pcsa, rtol=1e-12)
    np.testing.assert_allclose(result.counter_torque, opt.counter_torque, rtol=1e-9, atol=1e-9)


def test_no_local_stiffness_needed_where_the_chain_is_already_stable(model):
    """A chain stabilised by a large passive stiffness alone needs k = 0 (a diagonal -K_pas > mu I)."""
    stiff = model.replace(passive=Passive(stiffness=1e4))
    result = coupled.least_local_stiffness(stiff, 0.0, 0.0, [0.0, 0.0, 0.0])
    assert result.ok
    np.testing.assert_allclose(result.local_stiffness, 0.0, atol=1e-6)


@pytest.mark.parametrize("activation", ["paired", "independent"])
def test_global_only_optimum_where_passive_stiffness_makes_it_feasible(activation):
    """(b) with K = 100 N m/rad: feasible, LMI held by eigvalsh, a 1e-4 smaller x breaks it,
    and never below the per-segment minimum (the LMI's diagonal is the per-segment rows)."""
    model = _with(load_preset("default"), activation=activation)
    model = model.replace(passive=Passive(stiffness=100.0))
    result = coupled.min_global_pcsa(model, 0.0, 0.0)
    assert result.ok
    mu = model.optimisation.stability_margin
    coefficients = chain.chain_coefficients(model, 0.0, 0.0)
    assert chain.coupled_margin(coefficients.stiffness(result.pcsa)) >= mu - TOL
    lowered = LOWER * result.pcsa
    assert np.all(segment_coefficients(model, 0.0, 0.0).damping(lowered) < -model.optimisation.damping_margin)
    assert chain.coupled_margin(coefficients.stiffness(lowered)) < mu  # so it is the LMI that breaks
    assert result.total_pcsa >= optimise.solve_point(model, 0.0, 0.0).min_pcsa * (1 - 1e-6)
    np.testing.assert_array_equal(result.local_stiffness, 0.0)


@pytest.mark.parametrize("preset", ["default", "wagner2012"])
def test_joint_optimum_is_feasible_minimal_and_below_the_sequential_answer(preset):
    """(c): the LMI holds; x and k lowered together by 1e-4 break it; and its cost is at most that
    of the LP optimum plus (a)'s local stiffness there, a feasible point of (c)."""
    model = load_preset(preset)
    E, L = 0.0, 0.0
    result = coupled.joint_optimum(model, E, L)
    assert result.ok
    mu = model.optimisation.stability_margin
    coefficients = chain.chain_coefficients(model, E, L)
    k = result.local_stiffness
    assert chain.coupled_margin(coefficients.stiffness(result.pcsa, k)) >= mu - TOL
    assert chain.coupled_margin(coefficients.stiffness(LOWER * result.pcsa, LOWER * k)) < mu
    w = model.local.cost_weight
    cost = result.total_pcsa + w * result.total_local_pcsa
    opt = optimise.solve_point(model, E, L)
    sequential = coupled.least_local_stiffness(model, E, L, opt.pcsa)
    assert cost <= opt.total_pcsa + w * sequential.total_local_pcsa
    independent = coupled.joint_optimum(_with(model, activation="independent"), E, L)
    assert independent.total_pcsa + w * independent.total_local_pcsa <= cost * (1 + 1e-6)


@pytest.mark.parametrize("preset", ["default", "wagner2012"])
def test_joint_optimum_meets_its_dual_bound(preset):
    """(c) against the Lagrange dual, built here from the chain's matrices and the per-segment
    rows without the stiffness rows (S_k - k_k <= -mu is the LMI's diagonal):
    max <Z, K_0 + mu I> - lambda'h  s.t.  Z >= 0, diag(Z) <= w / kappa, lambda >= 0,
    weights_i + <Z, K_i> + (G'lambda)_i = 0. Weak duality: any such (Z, lambda) bounds (c) below."""
    model = load_preset(preset)
    data = coupled.coupled_data(model, 0.0, 0.0)
    x = np.array([1.0, 2.0, 3.0])  # the data's matrices are the chain's, per cm^2 of x
    pcsa = data.problem.to_muscles @ x * 1e-4
    np.testing.assert_allclose(data.matrix(x), data.coefficients.stiffness(pcsa), rtol=1e-12, atol=1e-9)
    n_cor, mu = 5, model.optimisation.stability_margin
    lhs, rhs = optimise.inequalities(data.problem)
    lhs, rhs = lhs[n_cor:], rhs[n_cor:]
    z = cp.Variable((n_cor, n_cor), PSD=True)
    lam = cp.Variable(rhs.size, nonneg=True)
    price = model.local.cost_weight / data.local_per_cm2
    stationary = [
        data.problem.weights[i] + cp.trace(z @ data.stiffness[:, :, i]) + lhs[:, i] @ lam == 0 for i in range(x.size)
    ]
    dual = cp.Problem(
        cp.Maximize(cp.trace(z @ (data.stiffness_offset + mu * np.eye(n_cor))) - rhs @ lam),
        [cp.diag(z) <= price, *stationary],
    )
    dual.solve(solver="CLARABEL")
    assert dual.status == "optimal"
    result = coupled.joint_optimum(model, 0.0, 0.0)
    cost = (result.total_pcsa + model.local.cost_weight * result.total_local_pcsa) / 1e-4
    assert dual.value == pytest.approx(cost, rel=1e-6)


def test_joint_optimum_meets_the_per_segment_requirements(model):
    """Segment k with its local stiffness is self-stable, S_k - k_k <= -mu (the LMI's diagonal)."""
    result = coupled.joint_optimum(model, 0.03, 0.04)
    segment = segment_coefficients(model, 0.03, 0.04)
    mu = model.optimisation.stability_margin
    assert np.all(segment.stiffness(result.pcsa) - result.local_stiffness <= -mu + TOL)
    assert np.all(segment.damping(result.pcsa) <= -model.optimisation.damping_margin * (1 - 1e-6))


@pytest.mark.parametrize("solve", ["least_local", "joint"])
def test_totals_scale_with_the_mass(solve):
    """With K_pas = 0 and no margins, K_g is proportional to m and K_i to x: doubling m doubles
    x and k at the optimum (the LMI and the damping rows are homogeneous)."""
    base = _with(load_preset("wagner2012"), stability_margin=0.0, damping_margin=0.0)
    heavy = base.replace(body=Body(mass=2 * base.body.mass))
    if solve == "joint":
        light_result, heavy_result = (coupled.joint_optimum(m, 0.03, 0.04) for m in (base, heavy))
        assert heavy_result.total_pcsa == pytest.approx(2 * light_result.total_pcsa, rel=1e-5)
    else:
        pcsa = optimise.solve_point(base, 0.03, 0.04).pcsa
        light_result = coupled.least_local_stiffness(base, 0.03, 0.04, pcsa)
        heavy_result = coupled.least_local_stiffness(heavy, 0.03, 0.04, 2 * pcsa)
    assert heavy_result.local_stiffness.sum() == pytest.approx(2 * light_result.local_stiffness.sum(), rel=1e-5)


def test_outside_the_modelled_range_is_an_error(model):
    """E = 0.5 m lies outside geometry.eccentricity_range (+-0.1 m): an error naming E, not a NaN."""
    with pytest.raises(ParameterError):
        coupled.joint_optimum(model, 0.5, 0.0)


# --- the coupled chain at the per-segment optimum (spinectl stability --coupled) ---------------


@pytest.mark.parametrize("preset", ["default", "wagner2012"])
def test_coupled_stability_at_the_segment_optimum(preset):
    """At position A and the LP optimum: K = K_g - diag(K_pas) + sum_i x_i dK/dx_i rebuilt from the
    per-variable matrices (x the paired PCSA in cm^2); its diagonal and D's are eq. 1's S_k and D_k;
    the eigenvalues are those of the quadratic eigenproblem det(lambda^2 M - lambda D - K) = 0 solved
    as a generalised eigenproblem by scipy; four grow (the four unstable static modes), and the least
    local stiffness of (a) makes every one decay."""
    model = load_preset(preset)
    result = coupled.coupled_stability_at(model, 0.0, 0.0)
    opt = optimise.solve_point(model, 0.0, 0.0)
    # its PCSA is the fast path's (optimise.active_set.solve_point): the reference's to 1e-9 of the total
    # (the agreement of tests/optimise/test_active_set.py; 1e-12 relative seen)
    np.testing.assert_allclose(result.pcsa, opt.pcsa, rtol=0, atol=1e-9 * opt.min_pcsa)
    pcsa = result.pcsa
    x = pcsa[::2] * 1e4  # paired: one variable per pair, cm^2 (both sides equal)
    rebuilt = result.gravity_stiffness - model.passive.stiffness * np.eye(5)
    rebuilt = rebuilt + np.einsum("i,ijk->jk", x, result.stiffness_per_variable)
    np.testing.assert_allclose(result.stiffness, rebuilt, rtol=1e-9, atol=1e-9)
    segment = segment_stability(model, 0.0, 0.0, pcsa)
    np.testing.assert_allclose(np.diag(result.stiffness), segment.stiffness, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(np.diag(result.damping), segment.damping, rtol=1e-12)
    a = np.block([[np.zeros((5, 5)), np.eye(5)], [result.stiffness, result.damping]])
    b = np.block([[np.eye(5), np.zeros((5, 5))], [np.zeros((5, 5)), result.mass]])
    np.testing.assert_allclose(
        np.sort_complex(result.eigenvalues), np.sort_complex(scipy.linalg.eig(a, b, right=False)), rtol=1e-7
    )
    assert np.sum(result.eigenvalues.real > 0) == 4 and not result.self_stable
    assert result.margin == pytest.approx(np.linalg.eigvalsh(-result.stiffness)[0])
    least = coupled.least_local_stiffness(model, 0.0, 0.0, pcsa)
    np.testing.assert_allclose(result.local.local_stiffness, least.local_stiffness, rtol=1e-9)
    assert result.stable_with_local and np.all(result.local_eigenvalues.real < 0)


def test_coupled_stability_dict_has_the_units_in_its_keys():
    """The JSON document: matrices as nested lists of the right shapes, SI with units in the names."""
    model = load_preset("default")
    result = coupled.coupled_stability_at(model, 0.03, 0.04, [10e-4, 10e-4, 10e-4])
    document = result.to_dict(model, pcsa_source="given")["coupled"]
    for key in ("stiffness_matrix_Nm_per_rad", "gravity_stiffness_matrix_Nm_per_rad", "damping_matrix_Nms_per_rad"):
        assert np.shape(document[key]) == (5, 5)
    assert np.shape(document["mass_matrix_kgm2"]) == (5, 5)
    assert np.shape(document["stiffness_matrix_per_cm2"]) == (3, 5, 5)
    assert document["decision_variables"] == list(model.pair_names)
    assert document["pcsa_cm2"] == pytest.approx(dict.fromkeys(model.muscle_names, 10.0))
    assert np.shape(document["eigenvalues"]) == (10, 2) and document["self_stable"] is False
    assert document["local_stiffness_total_Nm_per_rad"] == pytest.approx(sum(document["local_stiffness_Nm_per_rad"]))
    assert document["margin_Nm_per_rad"] == pytest.approx(result.margin)


def test_stacked_least_local_stiffness_is_the_per_point_sdp():
    """The stacked Clarabel problem (one PSD cone per point) against one cvxpy SDP per point, on random
    symmetric matrices of the chain's size and scale: the same optimum (total) to 1e-6 relative, every k
    feasible by numpy's eigvalsh, and a NaN matrix gives NaN without disturbing the others."""
    rng = np.random.default_rng(12)
    a = rng.normal(scale=60.0, size=(12, 5, 5))
    matrices = (a + np.swapaxes(a, -1, -2)) / 2
    matrices[4] = np.nan
    status, k = coupled.least_local_stiffness_stacked(matrices, 0.1, 1e-9)
    assert status == "optimal" and np.isnan(k[4]).all()
    for i in (0, 1, 2, 3, 5, 6, 7, 8, 9, 10, 11):
        _, reference = coupled.least_local_stiffness_at(matrices[i], 0.1, 1e-9)
        assert k[i].sum() == pytest.approx(reference.sum(), rel=1e-6)
        assert np.linalg.eigvalsh(np.diag(k[i]) - matrices[i])[0] >= 0.1 * (1 - 1e-9)
        assert np.all(k[i] >= 0)


@pytest.mark.parametrize("activation", ["paired", "independent"])
def test_stacked_joint_optimum_is_the_per_point_sdp(activation):
    """Problem (c) for four points as one Clarabel problem against joint_optimum_sdp (cvxpy) per point:
    the same objective to 1e-6, the LMI diag(k) - K(x) >= mu I by numpy's eigvalsh, x within its rows."""
    model = load_preset("wagner2012")
    model = model.replace(optimisation=dataclasses.replace(model.optimisation, activation=activation))
    e, lam = np.array([0.0, 0.03, 0.08, 0.05]), np.array([0.0, 0.04, 0.0, 0.08])
    data = problem_data(model, checked_coefficients(model, e, lam))
    kappa = chain.local_stiffness_per_pcsa(model) * 1e-4
    status, x, k = coupled.joint_optimum_stacked(
        data, chain.chain_coefficients(model, e, lam), 0.1, kappa, model.local.cost_weight
    )
    assert status == "optimal"
    lhs, rhs = inequalities(data)
    for i in range(e.size):
        point = coupled.coupled_data(model, e[i], lam[i])
        _, x_ref, k_ref = coupled.joint_optimum_sdp(point)
        cost = data.weights @ x[i] + k[i].sum() / kappa
        assert cost == pytest.approx(data.weights @ x_ref + k_ref.sum() / kappa, rel=1e-6)
        assert chain.coupled_margin(point.matrix(x[i], k[i])) >= 0.1 * (1 - 1e-9)
        assert np.all(lhs[i, 5:] @ x[i] <= rhs[i, 5:] + 1e-6)


def _least_damping_ratio(eigenvalues):
    """The smallest damping ratio -Re s / |s| of the chain's modes, and that mode's frequency [Hz]."""
    zeta = -eigenvalues.real / np.abs(eigenvalues)
    i = int(np.argmin(zeta))
    return float(zeta[i]), float(abs(eigenvalues[i].imag) / (2 * np.pi))


@pytest.mark.parametrize("preset", ["default", "wagner2012"])
def test_local_damping_lifts_the_least_damped_mode_and_leaves_the_statics(preset):
    """With the least local stiffness of (a) at the paper's optimum (position A), stability --coupled's ten modes
    with the local muscles' force-velocity damping (local.damping = 1, D - c_loc diag(k)) against the
    stiffness-only model (0). Stiffness only, the least-damped mode rings at 16-26 Hz with zeta 0.002
    (default) and 0.011 (wagner2012), the independent audit's 0.002-0.011; with the damping every mode has
    zeta above 0.9 (the audit's figure and these are the eigenvalues' -Re s / |s|). The statics do not move:
    the least local stiffness and the eigenvalues without local muscles are the same bit for bit, and off,
    the modes with local stiffness are the former ones (K - diag(k), the global muscles' D), bit for bit."""
    on = load_preset(preset)
    off = on.replace(local=dataclasses.replace(on.local, damping=0.0))
    with_damping = coupled.coupled_stability_at(on, 0.0, 0.0)
    stiffness_only = coupled.coupled_stability_at(off, 0.0, 0.0)
    np.testing.assert_array_equal(with_damping.local.local_stiffness, stiffness_only.local.local_stiffness)
    np.testing.assert_array_equal(with_damping.eigenvalues, stiffness_only.eigenvalues)
    np.testing.assert_array_equal(with_damping.damping, stiffness_only.damping)
    k = stiffness_only.local.local_stiffness
    former = chain.dynamic_eigenvalues(
        stiffness_only.mass, stiffness_only.stiffness - np.diag(k), stiffness_only.damping
    )
    np.testing.assert_array_equal(stiffness_only.local_eigenvalues, former)
    zeta_off, hz_off = _least_damping_ratio(stiffness_only.local_eigenvalues)
    zeta_on, _ = _least_damping_ratio(with_damping.local_eigenvalues)
    assert 0.001 < zeta_off < 0.012 and 16 < hz_off < 27
    assert zeta_on > 0.9 and with_damping.stable_with_local
    c_loc = chain.local_damping_per_stiffness(on)
    rebuilt = chain.dynamic_eigenvalues(
        with_damping.mass, with_damping.stiffness - np.diag(k), with_damping.damping - c_loc * np.diag(k)
    )
    np.testing.assert_allclose(np.sort_complex(with_damping.local_eigenvalues), np.sort_complex(rebuilt), rtol=1e-9)
