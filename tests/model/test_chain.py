"""The coupled chain: kinematics, nonlinear torques and their linearisation (docs/chain.md)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from spinectl import load_preset
from spinectl.model import chain, geometry, mechanics, muscle, stability
from spinectl.model.params import Body, Errata, Fibre, Geometry, Levels, Local, Model, MusclePair, Passive

STEP = 1e-6
N_COR = 5


def _random_positions(rng, n=4):
    return rng.uniform(-0.08, 0.08, n), rng.uniform(-0.08, 0.08, n)


def _central_difference(func, n=N_COR, step=STEP):
    """d func / d z_k by central differences, stacked on a new axis after the joint axis."""
    columns = [(func(step * np.eye(n)[k]) - func(-step * np.eye(n)[k])) / (2 * step) for k in range(n)]
    return np.stack(columns, axis=-1)


def test_one_free_joint_is_the_per_segment_model(model, rng):
    """Only joint k turning (alpha, omega) is the paper's segment k with all other CoRs fixed:
    the chain's torque on joint k is mechanics' nonlinear torque about CoR k, muscles and gravity."""
    E, L = _random_positions(rng)
    cor = geometry.cor_positions(E, L, model.geometry)
    for k in range(N_COR):
        alpha, omega = rng.uniform(-0.2, 0.2), rng.uniform(-1.0, 1.0)
        q, qdot = alpha * np.eye(N_COR)[k], omega * np.eye(N_COR)[k]
        muscles = chain.chain_muscle_torque_per_pcsa(model, cor, q, qdot)[..., k, :]
        segment = mechanics.muscle_torque_per_pcsa(model, cor[..., k, :], alpha, omega)
        np.testing.assert_allclose(muscles, segment, rtol=1e-10, atol=1e-9 * np.abs(segment).max())
        gravity = chain.chain_gravity_torque(model, cor, q)[..., k]
        np.testing.assert_allclose(gravity, mechanics.gravity_torque(alpha, cor[..., k, :], model), rtol=1e-12)


@pytest.mark.parametrize("convention", ["physical", "paper"])
def test_diagonal_is_the_per_segment_stiffness_and_damping(rng, convention):
    """K[k, k] = S_k and D[k, k] = D_k of segment_coefficients, every muscle, gravity and passive."""
    model = Model(passive=Passive(stiffness=15.0, convention=convention))
    E, L = _random_positions(rng)
    coupled = chain.chain_coefficients(model, E, L)
    segment = mechanics.segment_coefficients(model, E, L)
    per_muscle = np.diagonal(coupled.stiffness_per_pcsa, axis1=-3, axis2=-2).swapaxes(-1, -2)
    np.testing.assert_allclose(per_muscle, segment.stiffness_per_pcsa, rtol=1e-12, atol=1e-9)
    damping = np.diagonal(coupled.damping_per_pcsa, axis1=-3, axis2=-2).swapaxes(-1, -2)
    np.testing.assert_allclose(damping, segment.damping_per_pcsa, rtol=1e-12, atol=1e-9)
    pcsa = rng.uniform(0, 20e-4, 6)
    np.testing.assert_allclose(
        np.diagonal(coupled.stiffness(pcsa), axis1=-2, axis2=-1), segment.stiffness(pcsa), rtol=1e-12, atol=1e-9
    )
    np.testing.assert_allclose(
        np.diagonal(coupled.damping(pcsa), axis1=-2, axis2=-1), segment.damping(pcsa), rtol=1e-12, atol=1e-12
    )


def test_matrices_are_symmetric(model, rng):
    coupled = chain.chain_coefficients(model, *_random_positions(rng))
    for matrix in (coupled.stiffness_per_pcsa, coupled.damping_per_pcsa):
        np.testing.assert_array_equal(matrix, np.swapaxes(matrix, -3, -2))
    np.testing.assert_array_equal(coupled.gravity_stiffness, np.swapaxes(coupled.gravity_stiffness, -1, -2))


@pytest.mark.parametrize("preset", ["default", "wagner2012"])
def test_stiffness_is_central_difference_of_nonlinear_chain_torques(rng, preset):
    """dtau_j/dq_k of chain_muscle_torque_per_pcsa (q' = 0), every muscle and pair of joints."""
    model = load_preset(preset)
    E, L = _random_positions(rng)
    cor = geometry.cor_positions(E, L, model.geometry)
    zero = np.zeros(N_COR)
    fd = _central_difference(lambda q: chain.chain_muscle_torque_per_pcsa(model, cor, q, zero))  # (..., j, M, k)
    fd = np.moveaxis(fd, -1, -2)
    expected = chain.chain_coefficients(model, E, L).stiffness_per_pcsa
    np.testing.assert_allclose(expected, fd, atol=1e-6 * np.abs(fd).max())


def test_damping_is_central_difference_of_nonlinear_chain_torques(model, rng):
    """dtau_j/dq'_k; the Hill curve has a kink in its second derivative at v = 0, hence 1e-6."""
    E, L = _random_positions(rng)
    cor = geometry.cor_positions(E, L, model.geometry)
    zero = np.zeros(N_COR)
    fd = np.moveaxis(_central_difference(lambda w: chain.chain_muscle_torque_per_pcsa(model, cor, zero, w)), -1, -2)
    damping = chain.chain_coefficients(model, E, L).damping_per_pcsa
    np.testing.assert_allclose(damping, fd, atol=1e-6 * np.abs(fd).max())
    # negative semidefinite for every muscle: sum of f_l f_H'(0) h h' with f_H'(0) < 0
    eigs = np.linalg.eigvalsh(np.moveaxis(damping, -1, -3))
    assert np.all(eigs <= 1e-9 * np.abs(eigs).max())


@pytest.mark.parametrize("sign", ["destabilising", "printed"])
def test_gravity_stiffness_is_central_difference_and_closed_form(rng, sign):
    """K_g = dtau_g/dq by differences, and by hand: m g (y_m - y of the higher CoR)."""
    model = Model(errata=Errata(gravity_sign=sign))
    E, L = _random_positions(rng)
    cor = geometry.cor_positions(E, L, model.geometry)
    fd = _central_difference(lambda q: chain.chain_gravity_torque(model, cor, q))
    coupled = chain.chain_coefficients(model, E, L)
    np.testing.assert_allclose(coupled.gravity_stiffness, fd, rtol=1e-7)
    y = np.asarray(model.geometry.cor_heights)
    weight = model.body.mass * model.body.gravity * (1 if sign == "destabilising" else -1)
    # L1L2 (row 0) is the higher CoR of every pair it is in; L5S1 (4) with L4L5 (3): L4L5
    np.testing.assert_allclose(coupled.gravity_stiffness[..., 0, 4], weight * (0.326 - y[0]), rtol=1e-12)
    np.testing.assert_allclose(coupled.gravity_stiffness[..., 4, 3], weight * (0.326 - y[3]), rtol=1e-12)
    # the matrix min(s_j, s_k), s = y_m - y > 0 distinct: a Brownian-motion covariance, positive definite
    eigs = np.linalg.eigvalsh(coupled.gravity_stiffness * (1 if sign == "destabilising" else -1))
    assert np.all(eigs > 0)


def test_single_vertical_fibre_closed_form(vertical_model):
    """U = (d, T), P = (d, 0): h_j = -d at every joint, and by hand
    d2l/dq_j dq_k = ((T - y_j)(T - y_k) - T (T - y_hi)) / T, y_hi the higher of the two."""
    m = vertical_model
    coupled = chain.chain_coefficients(m, 0.0, 0.0)
    d, top = 0.12, 0.24
    y = np.asarray(m.geometry.cor_heights)
    higher = np.maximum.outer(y, y)
    hessian = (np.outer(top - y, top - y) - top * (top - higher)) / top
    l_opt = 1.2 * top
    f_l = muscle.force_length(top, l_opt, m.fibre)
    f_l_slope = muscle.force_length_slope(top, l_opt, m.fibre)
    expected = m.fibre.specific_tension * (-f_l_slope * d**2 - f_l * hessian)
    np.testing.assert_allclose(coupled.stiffness_per_pcsa[..., 0], expected, rtol=1e-12)
    np.testing.assert_allclose(coupled.stiffness_per_pcsa[..., 1], expected, rtol=1e-12)  # the mirror fibre
    np.testing.assert_allclose(coupled.length_gradient[..., 0, :], d, rtol=1e-12)  # dl/dq = -h = d


@pytest.mark.parametrize("preset", ["default", "wagner2012"])
def test_length_gradient_has_rank_at_most_three(rng, preset):
    """h_ij = (U_i - c_j) x e_i / l_i is affine in c_j: at most 3 independent columns (1, c_x, c_y),
    2 when the CoRs lie on a vertical line (Lambda = 0, c_x = -E), so 2-3 joint modes get no f'."""
    model = load_preset(preset)
    E, L = _random_positions(rng, 6)
    gradient = chain.chain_coefficients(model, E, L).length_gradient  # (6, F, 5)
    assert list(np.linalg.matrix_rank(gradient)) == [3] * 6
    straight = chain.chain_coefficients(model, E, 0.0).length_gradient
    assert list(np.linalg.matrix_rank(straight)) == [2] * 6


def test_chain_positions_are_a_rigid_chain(model, rng):
    """Turning joint k moves the CoRs above it rigidly about c_k and none below; the thorax turns by sum(q)."""
    cor = geometry.cor_positions(0.02, 0.05, model.geometry)
    q = rng.uniform(-0.3, 0.3, N_COR)
    moved, angle = chain.chain_positions(q, cor)
    assert angle == pytest.approx(q.sum(), rel=1e-14)
    np.testing.assert_array_equal(moved[-1], cor[-1])  # L5S1 sits on the pelvis
    for j in range(N_COR - 1):  # link lengths are kept
        assert np.linalg.norm(moved[j] - moved[j + 1]) == pytest.approx(np.linalg.norm(cor[j] - cor[j + 1]))
    k = 2
    one, _ = chain.chain_positions(0.1 * np.eye(N_COR)[k], cor)
    np.testing.assert_allclose(one[k:], cor[k:], atol=1e-15)
    np.testing.assert_allclose(one[:k], cor[k] + mechanics.rotate(cor[:k] - cor[k], 0.1), atol=1e-15)
    upper, _, _ = geometry.all_fibres(model)
    tops = chain.carried_points(upper, q, cor)
    np.testing.assert_allclose(tops, moved[0] + mechanics.rotate(upper - cor[0], q.sum()), atol=1e-15)


def test_coupled_margin_is_the_smallest_eigenvalue_of_minus_k():
    """A diagonal K gives min(-S_k); a coupling lowers it below every -S_k (2 x 2 by hand)."""
    assert chain.coupled_margin(np.diag([-3.0, -1.0, -2.0])) == pytest.approx(1.0)
    # [[-2, 1], [1, -2]]: eigenvalues of -K are 1 and 3
    assert chain.coupled_margin(np.array([[-2.0, 1.0], [1.0, -2.0]])) == pytest.approx(1.0)


def test_local_muscle_stiffness_per_pcsa_by_hand():
    """q sigma r^2 / l = 10 * 25 N/cm^2 * (7 cm)^2 / 3.5 cm = 350 N m/rad per 10 cm^2: the paper's
    17 cm^2 local muscle (30 N m at 7 cm) is a joint stiffness of 595 N m/rad."""
    model = Model()
    assert chain.local_stiffness_per_pcsa(model) == pytest.approx(10 * 25e4 * 0.07**2 / 0.035)
    assert float(chain.local_pcsa(595.0, model)) == pytest.approx(17e-4)
    halved = Model(local=Local(stiffness_gain=5.0))
    assert float(chain.local_pcsa(595.0, halved)) == pytest.approx(34e-4)


def test_local_damping_per_stiffness_is_the_hill_slope_at_rest():
    """c_loc = l |f_H'(0)| / q (docs/chain.md, "Local muscles as joint stiffness and damping"), three ways:
    the closed form of the Hill slope, (1 + a) / b with b = hill_b (vmax_slow + vmax_fast_gain FT) l_opt and
    l_opt = 1.2 l (docs/model.md), so (1 + 0.25) / (0.25 * 11 * 1.2) / 10 = 0.03788 s at the defaults; a central
    difference of the Hill force at v = +-h (muscle.force_velocity, both branches); and a central difference in
    omega of the joint torque r F f_H(r omega) of a local muscle at force F, whose stiffness is q F r^2 / l."""
    model = Model()
    fibre, local = model.fibre, model.local
    b = fibre.hill_b * (fibre.vmax_slow + fibre.vmax_fast_gain * fibre.fast_twitch) * 1.2 * local.length
    closed = local.length * (1.0 + fibre.hill_a) / b / local.stiffness_gain
    assert closed == pytest.approx(1.25 / 3.3 / 10, rel=1e-12)
    assert chain.local_damping_per_stiffness(model) == pytest.approx(closed, rel=1e-12)
    hill = muscle.hill_constants(1.2 * local.length, fibre, model.errata)
    h = 1e-9  # the branches' curvatures differ at 0, so the central difference is first order in h
    slope = (muscle.force_velocity(h, hill) - muscle.force_velocity(-h, hill)) / (2 * h)  # [s/m], < 0
    by_difference = local.length * -slope / local.stiffness_gain
    assert chain.local_damping_per_stiffness(model) == pytest.approx(by_difference, rel=1e-6)
    force, r = 80.0, local.lever_arm  # N; any force: both stiffness and damping are proportional to it
    k = local.stiffness_gain * force * r**2 / local.length
    torque = lambda w: r * force * muscle.force_velocity(r * w, hill)  # noqa: E731
    damping = -(torque(h) - torque(-h)) / (2 * h)  # N m s/rad, damping the motion
    assert float(chain.local_damping(k, model)) == pytest.approx(damping, rel=1e-5)
    slow = Model(fibre=Fibre(fast_twitch=0.0))  # all slow-twitch: v_max 6 instead of 11 l_opt/s
    assert chain.local_damping_per_stiffness(slow) == pytest.approx(closed * 11 / 6, rel=1e-12)
    assert chain.local_damping_per_stiffness(Model(local=Local(damping=0.0))) == 0.0
    assert chain.local_damping_per_stiffness(Model(local=Local(damping=0.5))) == pytest.approx(closed / 2)


@pytest.mark.parametrize("preset", ["default", "wagner2012"])
def test_damping_with_local_muscles_is_the_hand_built_matrix(rng, preset):
    """D with local stiffness k: the global muscles' D (sum_i x_i D_i, built here from damping_per_pcsa) minus
    c_loc diag(k), c_loc = l |f_H'(0)| / q by hand; the same from LinearChain.damping and LinearChain.at. The
    stiffness-only model (local.damping = 0) gives the former D bit for bit, whatever k."""
    model = load_preset(preset)
    e, lam = rng.uniform(-0.06, 0.06, 2)
    coefficients = chain.chain_coefficients(model, e, lam)
    pcsa = rng.uniform(0.0, 20e-4, len(model.muscle_names))
    k = rng.uniform(0.0, 100.0, N_COR)
    fibre = model.fibre
    b = fibre.hill_b * (fibre.vmax_slow + fibre.vmax_fast_gain * fibre.fast_twitch) * fibre.optimal_length_ratio
    c_loc = (1.0 + fibre.hill_a) / b / model.local.stiffness_gain  # l cancels: b is per l_opt = 1.2 l
    global_only = np.einsum("jkm,m->jk", coefficients.damping_per_pcsa, pcsa)
    expected = global_only - c_loc * np.diag(k)
    np.testing.assert_allclose(coefficients.damping(pcsa, k), expected, rtol=1e-12, atol=1e-12 * np.abs(expected).max())
    np.testing.assert_array_equal(coefficients.damping(pcsa), global_only)
    linear = chain.linear_chain(model, e, lam, coefficients)
    x = pcsa[::2] * 1e4 if model.optimisation.activation == "paired" else pcsa * 1e4
    pcsa_x = np.repeat(pcsa[::2], 2) if model.optimisation.activation == "paired" else pcsa
    at_x = coefficients.damping(pcsa_x, k)
    np.testing.assert_allclose(linear.damping(x, k), at_x, rtol=1e-12, atol=1e-12 * np.abs(at_x).max())
    np.testing.assert_allclose(linear.at(x, k).damping(()), at_x, rtol=1e-12, atol=1e-12 * np.abs(at_x).max())
    off = model.replace(local=dataclasses.replace(model.local, damping=0.0))
    off_coefficients = chain.chain_coefficients(off, e, lam)
    np.testing.assert_array_equal(off_coefficients.damping(pcsa, k), coefficients.damping(pcsa))
    off_linear = chain.linear_chain(off, e, lam, off_coefficients)
    np.testing.assert_array_equal(off_linear.damping(x, k), linear.damping(x))
    np.testing.assert_array_equal(off_linear.at(x, k).damping(()), linear.damping(x))


def test_coefficients_broadcast_over_a_grid(model):
    E, L = np.meshgrid(np.linspace(0, 0.08, 3), np.linspace(0, 0.08, 2), indexing="ij")
    grid = chain.chain_coefficients(model, E, L)
    assert grid.stiffness_per_pcsa.shape == (3, 2, 5, 5, 6)
    assert grid.length_gradient.shape == (3, 2, 30, 5)
    one = chain.chain_coefficients(model, E[2, 1], L[2, 1])
    np.testing.assert_allclose(grid.stiffness_per_pcsa[2, 1], one.stiffness_per_pcsa, rtol=1e-12)


# --- the monomial form against the per-fibre sums ------------------------------------------------


def _term_scales(model, E, L):
    """The size of the largest term that either form adds up, per muscle for K and D and per fibre for dl/dq.

    Every term of either form is at most r^2 times a fibre's weight (f_l' h h', f_l/l (u . u, e . u, h h),
    U . P, U . c, c . c, f_l f_H' h h), r = |U| + |P| + the largest |c|; both forms round at that size,
    so an entry near 0 (a vertical fibre through a CoR) is compared at it, not at its own size.
    """
    upper, lower, share = geometry.all_fibres(model)
    cor = geometry.cor_positions(E, L, model.geometry)
    reach = np.linalg.norm(upper, axis=-1) + np.linalg.norm(lower, axis=-1) + np.abs(cor).sum(-1).max(-1)[..., None]
    l0 = np.linalg.norm(lower - upper, axis=-1)
    l_opt = model.fibre.optimal_length_ratio * l0
    f_l = muscle.force_length(l0, l_opt, model.fibre)
    f_l_slope = muscle.force_length_slope(l0, l_opt, model.fibre)
    f_h_slope = muscle.force_velocity_slope(0.0 * l0, muscle.hill_constants(l_opt, model.fibre, model.errata))
    weights = model.fibre.specific_tension * share
    stiffness = (reach**2 * (np.abs(f_l_slope) + 2 * f_l / l0)) @ weights
    damping = (reach**2 * np.abs(f_l * f_h_slope)) @ weights
    return stiffness[..., None, None, :], damping[..., None, None, :], reach[..., :, None]


def _assert_equals_per_fibre_sums(model, E, L):
    """chain_coefficients (the monomial form) against chain_per_fibre_sums (the formulas of docs/chain.md
    fibre by fibre, as before the monomial form) to 1e-12 of the terms they add (:func:`_term_scales`)."""
    coupled = chain.chain_coefficients(model, E, L)
    expected = chain.chain_per_fibre_sums(model, E, L)
    got = (coupled.stiffness_per_pcsa, coupled.damping_per_pcsa, coupled.length_gradient)
    for value, reference, scale in zip(got, expected, _term_scales(model, E, L), strict=True):
        assert value.shape == reference.shape
        assert np.all(np.abs(value - reference) <= 1e-12 * scale)
    for matrix in got[:2]:
        np.testing.assert_array_equal(matrix, np.swapaxes(matrix, -3, -2))  # symmetric by construction
    return coupled, expected


@pytest.mark.parametrize("preset", ["default", "wagner2012"])
def test_monomial_form_equals_per_fibre_sums_on_the_papers_grid(preset):
    """The paper's 0-8 cm in 5 mm steps, and the mirrored range beyond it (the modelled -10 to 10 cm);
    there also to 1e-12 of each muscle's largest entry at the point (about 1e-14 measured)."""
    model = load_preset(preset)
    for axis in (np.linspace(0.0, 0.08, 17), np.linspace(-0.1, 0.1, 9)):
        coupled, (stiffness, damping, _) = _assert_equals_per_fibre_sums(model, *np.meshgrid(axis, axis, indexing="ij"))
        for value, reference in ((coupled.stiffness_per_pcsa, stiffness), (coupled.damping_per_pcsa, damping)):
            largest = np.abs(reference).max(axis=(-3, -2), keepdims=True)
            assert np.all(np.abs(value - reference) <= 1e-12 * largest)


def _reals(low, high):
    return st.floats(low, high, allow_nan=False, allow_infinity=False)


@st.composite
def _chain_models(draw):
    """1-3 pairs anywhere around the spine (attachments may cross the CoRs' heights), 1-6 CoRs at random
    heights on the spine, a random optimal length, and passive stiffness and levels' weight on or off."""
    pairs = []
    for i in range(draw(st.integers(1, 3))):
        top = draw(_reals(0.03, 0.35))
        upper, lower = (draw(_reals(-0.2, 0.2)), top), (draw(_reals(-0.2, 0.2)), draw(_reals(-0.1, top - 0.025)))
        pairs.append(MusclePair(f"p{i}", upper, lower, draw(_reals(0.0, 0.02)), draw(st.integers(1, 5))))
    heights = draw(st.lists(_reals(0.0, 0.176), min_size=1, max_size=6, unique=True))
    return Model(
        muscles=tuple(pairs),
        geometry=Geometry(cor_names=tuple(f"C{i}" for i in range(len(heights))), cor_heights=sorted(heights)[::-1]),
        fibre=Fibre(optimal_length_ratio=draw(_reals(1.01, 1.6))),
        passive=Passive(draw(st.sampled_from([0.0, 15.0])), draw(st.sampled_from(["physical", "paper"]))),
        levels=Levels(weight_in_gravity=draw(st.sampled_from([0.0, 1.0]))),
    )


@settings(max_examples=100, deadline=None)
@given(_chain_models(), st.lists(st.tuples(_reals(-0.1, 0.1), _reals(-0.1, 0.1)), min_size=1, max_size=4))
def test_monomial_form_equals_per_fibre_sums_on_random_geometries(model, positions):
    E, L = np.array(positions).T
    _assert_equals_per_fibre_sums(model, E, L)
    _assert_equals_per_fibre_sums(model, E[0], L[0])  # a single point: no leading dimensions


# --- inertia and dynamic stability -------------------------------------------------------------


def _bodies_by_rotations(model, q, cor):
    """Upper-body point and level centres in the rotated chain, built joint by joint from the pelvis:
    turning joint j (bottom first) rotates every body and CoR above it about the current c_j."""
    n = cor.shape[0]
    y = cor[:, 1]
    points = [np.array([0.0, model.body.mass_height])] + [np.array([0.0, (y[i] + y[i + 1]) / 2]) for i in range(n - 1)]
    base = [0] + [i + 1 for i in range(n - 1)]  # the highest joint carrying each body
    points, cors = [p.copy() for p in points], cor.copy()
    for j in range(n - 1, -1, -1):
        centre = cors[j].copy()
        points = [
            centre + mechanics.rotate(p - centre, q[j]) if j >= b else p for p, b in zip(points, base, strict=True)
        ]
        cors[:j] = centre + mechanics.rotate(cors[:j] - centre, q[j])
    angles = [q[b:].sum() for b in base]
    return np.array(points), np.array(angles)


@pytest.mark.parametrize("preset", ["default", "wagner2012"])
@pytest.mark.parametrize("posture", [0.0, 0.2])
def test_mass_matrix_is_the_hessian_of_the_kinetic_energy(rng, preset, posture):
    """T(q') = 1/2 sum m |v|^2 + 1/2 m rho^2 phi'^2 with v and phi' by central differences of the
    bodies' positions and angles (built rotation by rotation); M[j, k] = T(e_j + e_k) - T(e_j) - T(e_k)
    (T is quadratic), and M is symmetric positive definite; upright and at a bent posture q."""
    model = load_preset(preset)
    model = model.replace(body=Body(mass=model.body.mass, mass_height=model.body.mass_height, radius_of_gyration=0.05))
    E, L = _random_positions(rng, 1)
    cor = geometry.cor_positions(E[0], L[0], model.geometry)
    masses = np.array([model.body.mass] + [model.levels.mass] * (N_COR - 1))
    gyration = np.array([0.05] + [model.levels.radius_of_gyration] * (N_COR - 1))

    q = posture * rng.uniform(-1, 1, N_COR)

    def kinetic(qdot, h=1e-6):
        (p_plus, a_plus), (p_minus, a_minus) = (_bodies_by_rotations(model, q + s * h * qdot, cor) for s in (1, -1))
        v, w = (p_plus - p_minus) / (2 * h), (a_plus - a_minus) / (2 * h)
        return 0.5 * np.sum(masses * (np.sum(v**2, axis=-1) + gyration**2 * w**2))

    eye = np.eye(N_COR)
    hessian = np.array(
        [[kinetic(eye[j] + eye[k]) - kinetic(eye[j]) - kinetic(eye[k]) for k in range(N_COR)] for j in range(N_COR)]
    )
    mass = chain.mass_matrix(model, cor, q)
    np.testing.assert_allclose(mass, hessian, rtol=1e-7, atol=1e-9 * np.abs(mass).max())
    np.testing.assert_array_equal(mass, mass.T)
    assert np.all(np.linalg.eigvalsh(mass) > 0)


def test_velocity_torque_is_the_christoffel_form_of_the_mass_matrix(rng):
    """Lagrange's equations give c_j = sum_kl (dM_jk/dq_l - 1/2 dM_kl/dq_j) q'_k q'_l; dM/dq here by
    central differences of mass_matrix at a bent posture, a second route to velocity_torque's closed form."""
    model = load_preset("wagner2012")
    cor = geometry.cor_positions(0.02, -0.03, model.geometry)
    q, qdot = rng.uniform(-0.3, 0.3, N_COR), rng.uniform(-2.0, 2.0, N_COR)
    slope = _central_difference(lambda dq: chain.mass_matrix(model, cor, q + dq))  # (j, k, l) = dM_jk/dq_l
    christoffel = np.einsum("jkl,k,l->j", slope, qdot, qdot) - 0.5 * np.einsum("klj,k,l->j", slope, qdot, qdot)
    np.testing.assert_allclose(chain.velocity_torque(model, cor, q, qdot), christoffel, rtol=1e-7, atol=1e-9)
    assert np.all(chain.velocity_torque(model, cor, q, np.zeros(N_COR)) == 0)


def test_mass_matrix_diagonal_is_theta_without_levels(rng):
    """With massless levels, M[k, k] is the per-segment theta_k = m (r_k^2 + rho^2) of mechanics.inertia,
    and M = m J'J + m rho^2 1 1' has rank 3: singular, so the state matrix is NaN."""
    model = Model(body=Body(radius_of_gyration=0.1), levels=Levels(mass=0.0))
    E, L = _random_positions(rng)
    cor = geometry.cor_positions(E, L, model.geometry)
    mass = chain.mass_matrix(model, cor)
    np.testing.assert_allclose(np.diagonal(mass, axis1=-2, axis2=-1), mechanics.inertia(cor, model), rtol=1e-12)
    assert list(np.linalg.matrix_rank(mass)) == [3] * len(E)
    assert np.all(np.isnan(chain.dynamic_eigenvalues(mass, -np.eye(N_COR), -np.eye(N_COR))))


def test_decoupled_chain_has_the_per_segment_eigenvalues(rng):
    """Diagonal M, K and D: the 2n eigenvalues of the state matrix are the segments' eq. 1 roots
    (stability.eigenvalues, closed form), stable and unstable, real and complex."""
    theta = rng.uniform(0.5, 4.0, N_COR)
    stiffness = np.array([-30.0, 20.0, -5.0, -100.0, 0.5])
    damping = np.array([-2.0, -1.0, -0.1, -30.0, 0.0])
    eigs = chain.dynamic_eigenvalues(np.diag(theta), np.diag(stiffness), np.diag(damping))
    expected = stability.eigenvalues(stiffness, damping, theta).ravel()
    np.testing.assert_allclose(np.sort_complex(eigs), np.sort_complex(expected), atol=1e-10)
    assert np.all(np.diff(eigs.real) <= 0)  # the largest real part first
    # one joint: the state matrix is the segment's Jacobian
    np.testing.assert_allclose(
        chain.state_matrix([[theta[0]]], [[stiffness[0]]], [[damping[0]]]),
        stability.jacobian(stiffness[0], damping[0], theta[0]),
        rtol=1e-14,
    )


@pytest.mark.parametrize("sign", ["destabilising", "printed"])
def test_level_weight_in_gravity(rng, sign):
    """With levels.weight_in_gravity = 1, K_g is the central difference of the nonlinear gravity
    torques (point mass and levels), and by hand each level b adds m_l g (y_b - y_hi) on the joints
    below it; upright, their weight loads the joints below them (beyond the per-segment CT)."""
    base = Model(errata=Errata(gravity_sign=sign))
    model = base.replace(levels=Levels(weight_in_gravity=1.0))
    E, L = _random_positions(rng)
    cor = geometry.cor_positions(E, L, model.geometry)
    fd = _central_difference(lambda q: chain.chain_gravity_torque(model, cor, q))
    gravity = chain.chain_coefficients(model, E, L).gravity_stiffness
    np.testing.assert_allclose(gravity, fd, rtol=1e-7)
    # upright, a level on the line of gravity (x = 0) loads each joint below it with w x_j (w its weight)
    zero = np.zeros(N_COR)
    loading = chain.chain_gravity_torque(model, cor, zero) - chain.chain_gravity_torque(base, cor, zero)
    signed = model.levels.mass * model.body.gravity * (1 if sign == "destabilising" else -1)
    np.testing.assert_allclose(loading, signed * np.arange(N_COR) * cor[..., 0], rtol=1e-12, atol=1e-12)
    y = np.asarray(model.geometry.cor_heights)
    w = model.levels.mass * model.body.gravity * (1 if sign == "destabilising" else -1)
    extra = gravity - chain.chain_coefficients(base, E, L).gravity_stiffness
    # joint L5S1 (4) carries all four levels, at heights (y_i + y_{i+1}) / 2 above y_4
    by_hand = w * sum((y[i] + y[i + 1]) / 2 - y[4] for i in range(4))
    np.testing.assert_allclose(extra[..., 4, 4], by_hand, rtol=1e-12)
    np.testing.assert_allclose(extra[..., 0, :], 0.0, atol=1e-12)  # L1L2 carries no level


@pytest.mark.parametrize("activation", ["paired", "independent"])
def test_linear_chain_is_the_chain_at_the_decision_variables(activation):
    """model.chain.linear_chain: controls the optimisation's decision variables x [cm^2] (one per pair,
    either side's PCSA, or one per muscle). Checked against chain_coefficients at the muscles' PCSA
    (pairing_matrix @ x, times 1e-4 m^2 per cm^2), a second route: K(x), D(x) to rounding; M is
    mass_matrix's; names, classes and the bounds 0 <= x <= pcsa_max as the model states them."""
    base = load_preset("wagner2012")
    model = base.replace(optimisation=dataclasses.replace(base.optimisation, activation=activation))
    e, lam = 0.03, 0.04
    linear = chain.linear_chain(model, e, lam)
    coefficients = chain.chain_coefficients(model, e, lam)
    paired = activation == "paired"
    to_muscles = geometry.pairing_matrix(3) if paired else np.eye(6)
    x = np.arange(1.0, to_muscles.shape[1] + 1.0)  # cm^2
    pcsa = to_muscles @ x * 1e-4
    np.testing.assert_allclose(linear.stiffness(x), coefficients.stiffness(pcsa), rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(linear.damping(x), coefficients.damping(pcsa), rtol=1e-12, atol=1e-12)
    cor = geometry.cor_positions(e, lam, model.geometry)
    np.testing.assert_array_equal(linear.mass_matrix, chain.mass_matrix(model, cor))
    assert linear.joints == model.geometry.cor_names
    assert linear.controls == (model.pair_names if paired else model.muscle_names)
    assert set(linear.control_class) == {"global"} and linear.control_unit == "cm^2"
    np.testing.assert_array_equal(linear.upper, model.optimisation.pcsa_max * 1e4)
    assert not linear.lower.any()
