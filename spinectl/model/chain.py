"""The coupled chain: every centre of rotation free at once (docs/chain.md).

The paper tests each CoR alone, all others fixed (:mod:`spinectl.model.mechanics`). Here
the generalised coordinates are q = (alpha_1, ..., alpha_n), one rotation per CoR in the
order of ``geometry.cor_heights`` (top to bottom), with the pelvis fixed. Rotating joint k
carries everything above it: the higher CoRs, the thoracic attachments of the global
muscles and the point mass. Every global muscle runs from thorax to pelvis, so it spans
all joints.

Linearised at the upright equilibrium, tau(q, q') ~ tau_0 + K q + D q' with symmetric
n x n matrices, linear in the PCSA like everything muscular: per unit PCSA of muscle i,
K_i[j, k] = -f'_i h_ij h_ik - f_i d2l_i/dq_j dq_k and D_i[j, k] = (df_i/dv) h_ij h_ik;
gravity K_g[j, k] = m g (y_m - y of the higher of CoRs j and k); the passive stiffness
-K_pas on the diagonal. The diagonal is the per-segment analysis: K[k, k] = S_k and
D[k, k] = D_k (:func:`spinectl.model.mechanics.segment_coefficients`). tau_0 is the
per-segment torque, so the counter torques are those of the per-segment model.

The nonlinear generalised torques (:func:`chain_muscle_torque_per_pcsa`,
:func:`chain_gravity_torque`) are what K and D linearise; the tests differentiate them.
Pure array functions, SI units, vectorised over leading (grid) dimensions.

References
----------
Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal lordosis
optimizes the requirements for a stable erect posture. Theor Biol Med Model 9:13.
doi:10.1186/1742-4682-9-13.

Bergmark A (1989). Stability of the lumbar spine. A study in mechanical engineering.
Acta Orthop Scand Suppl 230:1-54. doi:10.3109/17453678909154177.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..units import M2_PER_CM2
from . import geometry, laws
from .linear_chain import LinearChain
from .local_muscles import (  # noqa: F401 (the chain's callers name them here too: the MJCF export among them)
    local_damping,
    local_damping_per_stiffness,
    local_pcsa,
    local_stiffness_per_pcsa,
)
from .mechanics import (
    _fibre_laws,
    cross2,
    fibre_length_and_lever_arm,
    gravity_sign,
    inertia,
    passive_stiffness,
    rotate,
)
from .params import Model
from .source import header


def chain_positions(q, cor):
    """Positions of the centres of rotation, and the thorax's rotation, for joint angles ``q``.

    Joint j is carried by every joint below it: with the bottom CoR fixed on the pelvis,
    c_j(q) = c_{j+1}(q) + R(q_{j+1} + ... + q_n)(c_j - c_{j+1}). The thorax, above the top
    joint, turns by the sum of all angles.

    Parameters
    ----------
    q : array_like, shape (..., n_cor)
        Rotation of each joint [rad], counter-clockwise, top to bottom.
    cor : array_like, shape (..., n_cor, 2)
        Upright positions of the CoRs [m], top to bottom.

    Returns
    -------
    moved : numpy.ndarray, shape (..., n_cor, 2)
        CoR positions in the rotated chain [m].
    thorax_angle : numpy.ndarray, shape (...)
        Rotation of the thorax, sum of ``q`` [rad].
    """
    q = np.asarray(q, float)
    cor = np.asarray(cor, float)
    n = cor.shape[-2]
    moved = np.array(np.broadcast_to(cor, np.broadcast_shapes(q.shape + (2,), cor.shape)))
    angle = np.zeros(moved.shape[:-2])
    # from the pelvis up: CoR j turns about CoR j + 1 by every joint angle below it (the pelvis is fixed)
    for j in range(n - 2, -1, -1):
        angle = angle + q[..., j + 1]
        moved[..., j, :] = moved[..., j + 1, :] + rotate(cor[..., j, :] - cor[..., j + 1, :], angle)
    return moved, angle + q[..., 0]


def carried_points(points, q, cor):
    """Positions of points fixed to the thorax (above every joint) in the rotated chain.

    P(q) = c_1(q) + R(q_1 + ... + q_n)(P - c_1), c_1 the top CoR (:func:`chain_positions`).

    Parameters
    ----------
    points : array_like, shape (n_points, 2)
        Upright positions [m], e.g. the upper attachments of the fibres.
    q : array_like, shape (..., n_cor)
        Joint rotations [rad].
    cor : array_like, shape (..., n_cor, 2)
        Upright CoR positions [m].

    Returns
    -------
    numpy.ndarray, shape (..., n_points, 2)
        [m].
    """
    moved, angle = chain_positions(q, cor)
    top = np.asarray(cor, float)[..., 0, None, :]
    return moved[..., 0, None, :] + rotate(np.asarray(points, float) - top, angle[..., None])


def _carried_by(n: int) -> np.ndarray:
    """carried[b, j]: body b is carried by joint j (b = 0 the upper body, b = i + 1 the level below CoR i)."""
    return (np.arange(n)[None, :] >= np.arange(n)[:, None]).astype(float)


def level_positions(q, cor):
    """Centres of mass of the lumbar levels in the rotated chain [m] (docs/chain.md, "The mass matrix").

    Level i lies between CoRs i and i + 1 (L2 between L1L2 and L2L3, ...); upright, its centre
    of mass is on the line of gravity (x = 0, like the upper body's point mass), halfway up
    between the two CoRs. It is carried by the joints below it, i + 1, ..., n - 1:
    P_i(q) = c_{i+1}(q) + R(q_{i+1} + ... + q_n)(P_i - c_{i+1}).

    Parameters
    ----------
    q : array_like, shape (..., n_cor)
        Joint rotations [rad].
    cor : array_like, shape (..., n_cor, 2)
        Upright CoR positions [m], top to bottom.

    Returns
    -------
    numpy.ndarray, shape (..., n_cor - 1, 2)
        [m].
    """
    q = np.asarray(q, float)
    cor = np.asarray(cor, float)
    moved, _ = chain_positions(q, cor)
    upright = np.stack([np.zeros(cor.shape[:-2] + (cor.shape[-2] - 1,)), (cor[..., :-1, 1] + cor[..., 1:, 1]) / 2], -1)
    angle = np.cumsum(q[..., ::-1], axis=-1)[..., ::-1][..., 1:]  # q_{i+1} + ... + q_n
    return moved[..., 1:, :] + rotate(upright - cor[..., 1:, :], angle)


def level_weight(model: Model) -> float:
    """The weight of one lumbar level that enters gravity [N]: ``levels.weight_in_gravity`` m_level g.

    Parameters
    ----------
    model : Model

    Returns
    -------
    float
        [N]; 0 by default (the levels carry inertia only; docs/chain.md, "The weight of the levels").
    """
    return model.levels.weight_in_gravity * model.levels.mass * model.body.gravity


def _bodies(model: Model, q, cor):
    """The bodies in the rotated chain: upper body then the levels, (..., n, 2) [m], and the moved CoRs."""
    moved, _ = chain_positions(q, cor)
    upper = carried_points(geometry.mass_position(model)[None, :], q, cor)
    return np.concatenate([upper, level_positions(q, cor)], axis=-2), moved


def _masses(model: Model, n: int):
    """Masses [kg] and squared radii of gyration [m^2] of the upper body and the n - 1 levels."""
    body, levels = model.body, model.levels
    masses = np.array([body.mass] + [levels.mass] * (n - 1))
    gyration = np.array([body.radius_of_gyration] + [levels.radius_of_gyration] * (n - 1)) ** 2
    return masses, gyration


def mass_matrix(model: Model, cor, q=None):
    """Mass matrix of the chain [kg m^2], upright or at the posture ``q`` (docs/chain.md, "The mass matrix").

    M = sum over the bodies b of m_b J_v,b' J_v,b + I_b J_w,b' J_w,b, with the upper body (the
    point mass m at (0, ``body.mass_height``), I = m rho^2, rho ``body.radius_of_gyration``)
    carried by every joint and each lumbar level (:func:`level_positions`; ``levels.mass``,
    I = m rho_level^2) by the joints below it. A body carried by joint j moves with
    dP/dq_j = J (P - c_j) (J the quarter turn) and turns with dphi/dq_j = 1, so

        M[j, k] = sum over b carried by j and k of m_b ((P_b - c_j) . (P_b - c_k) + rho_b^2),

    with P_b and c_j where the posture ``q`` puts them (:func:`chain_positions`).
    M[k, k] upright without the levels is theta_k of :func:`spinectl.model.mechanics.inertia`.

    Parameters
    ----------
    model : Model
        ``body`` (mass, height, radius of gyration) and ``levels`` (mass, radius of gyration).
    cor : array_like, shape (..., n_cor, 2)
        Upright CoR positions [m], top to bottom.
    q : array_like, shape (..., n_cor), optional
        Joint rotations [rad]; None: upright.

    Returns
    -------
    numpy.ndarray, shape (..., n_cor, n_cor)
        Symmetric [kg m^2]; positive definite when the levels have mass.

    References
    ----------
    Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal lordosis
    optimizes the requirements for a stable erect posture. Theor Biol Med Model 9:13.
    doi:10.1186/1742-4682-9-13.
    """
    cor = np.asarray(cor, float)
    n = cor.shape[-2]
    positions, moved = _bodies(model, np.zeros(n) if q is None else q, cor)  # (..., n, 2): upper body, levels
    masses, gyration = _masses(model, n)
    carried = _carried_by(n)
    arm = (positions[..., :, None, :] - moved[..., None, :, :]) * carried[..., None]  # (..., b, j, 2)
    mass = np.einsum("b,...bjd,...bkd->...jk", masses, arm, arm) + np.einsum(
        "b,bj,bk->jk", masses * gyration, carried, carried
    )
    return (mass + np.swapaxes(mass, -1, -2)) / 2  # symmetric to the last bit, not just to rounding


def velocity_torque(model: Model, cor, q, qdot):
    """Coriolis and centripetal terms c(q, q') of the chain's equation M(q) q'' + c = tau [N m].

    Every body hangs on a chain of rigid links: the link above joint j turns at
    phi'_j = q'_j + ... + q'_n, so the part of a body's acceleration that does not come
    from q'' is the centripetal a_b = -sum over its links of phi'^2 times the link vector
    (CoR c_{j+1} to c_j, and the last one c_b to P_b). Lagrange's equations with
    dP_b/dq_j = J (P_b - c_j) give c_j = sum over b carried by j of m_b (P_b - c_j) x a_b
    (the planar cross product); the rotations add nothing, a plane body's spin having no
    gyroscopic term (docs/chain.md, "Nonlinear simulation").

    Parameters
    ----------
    model : Model
    cor : array_like, shape (..., n_cor, 2)
        Upright CoR positions [m].
    q, qdot : array_like, shape (..., n_cor)
        Joint rotations [rad] and angular velocities [rad/s].

    Returns
    -------
    numpy.ndarray, shape (..., n_cor)
        c [N m]; quadratic in ``qdot``.

    References
    ----------
    Siciliano B, Sciavicco L, Villani L, Oriolo G (2009). Robotics: Modelling, Planning and
    Control. Springer, London, ch. 7 (Lagrange formulation). doi:10.1007/978-1-84628-642-1.
    """
    cor = np.asarray(cor, float)
    n = cor.shape[-2]
    positions, moved = _bodies(model, q, cor)
    spin = np.cumsum(np.asarray(qdot, float)[..., ::-1], axis=-1)[..., ::-1]  # phi'_j
    links = (moved[..., :-1, :] - moved[..., 1:, :]) * spin[..., 1:, None] ** 2  # link j (c_{j+1} to c_j)
    above = np.cumsum(links[..., ::-1, :], axis=-2)[..., ::-1, :]  # sum over links j, ..., n - 2
    above = np.concatenate([above, np.zeros_like(above[..., :1, :])], axis=-2)  # body b starts at link b
    centripetal = -above - spin[..., None] ** 2 * (positions - moved)  # (..., b, 2), body b carried from joint b
    arm = positions[..., :, None, :] - moved[..., None, :, :]  # (..., b, j, 2)
    cross = arm[..., 0] * centripetal[..., :, None, 1] - arm[..., 1] * centripetal[..., :, None, 0]
    masses, _ = _masses(model, n)
    return np.einsum("b,bj,...bj->...j", masses, _carried_by(n), cross)


def state_matrix(mass, stiffness, damping):
    """The linearised chain as a first-order system: x' = A x, x = (q, q') [1/s^2, 1/s].

    M q'' = K q + D q' (spinectl's tau = K q + D q', the per-segment eq. 1 with theta -> M), so
    A = [[0, I], [M^-1 K, M^-1 D]]. One joint (n = 1) is
    :func:`spinectl.model.stability.jacobian`. Where M is singular (levels without mass), A is NaN.

    Parameters
    ----------
    mass : array_like, shape (..., n, n)
        M [kg m^2] (:func:`mass_matrix`).
    stiffness : array_like, shape (..., n, n)
        K [N m/rad], possibly K - diag(k) with local stiffness.
    damping : array_like, shape (..., n, n)
        D [N m s/rad].

    Returns
    -------
    numpy.ndarray, shape (..., 2 n, 2 n)
        A; NaN where M is singular to working precision.
    """
    mass, stiffness, damping = np.broadcast_arrays(*(np.asarray(x, float) for x in (mass, stiffness, damping)))
    n = mass.shape[-1]
    # a massless level makes M singular: no state form exists, so NaN rather than a solve's noise
    singular = np.linalg.cond(mass) > 1.0 / np.finfo(float).eps
    regular = np.where(singular[..., None, None], np.eye(n), mass)
    lower = np.linalg.solve(regular, np.concatenate([stiffness, damping], axis=-1))  # (..., n, 2 n)
    upper = np.broadcast_to(np.concatenate([np.zeros((n, n)), np.eye(n)], axis=-1), lower.shape)
    a = np.concatenate([upper, lower], axis=-2)
    return np.where(singular[..., None, None], np.nan, a)


def dynamic_eigenvalues(mass, stiffness, damping):
    """Eigenvalues of :func:`state_matrix` [1/s], the largest real part first.

    The chain is dynamically stable iff all lie in the left half-plane
    (:func:`spinectl.model.stability.self_stable` applies to them as to a segment's two).

    Parameters
    ----------
    mass, stiffness, damping : array_like, shape (..., n, n)
        M [kg m^2], K [N m/rad], D [N m s/rad].

    Returns
    -------
    numpy.ndarray, shape (..., 2 n), complex
        [1/s]; NaN where M is singular.

    References
    ----------
    Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal lordosis
    optimizes the requirements for a stable erect posture. Theor Biol Med Model 9:13.
    doi:10.1186/1742-4682-9-13.
    """
    a = state_matrix(mass, stiffness, damping)
    finite = np.all(np.isfinite(a), axis=(-2, -1))
    eigs = np.linalg.eigvals(np.where(finite[..., None, None], a, 0.0)).astype(complex)
    # rightmost first: the first eigenvalue decides stability (stable sort: conjugates keep their order)
    eigs = np.take_along_axis(eigs, np.argsort(-eigs.real, axis=-1, kind="stable"), axis=-1)
    return np.where(finite[..., None], eigs, complex(np.nan, np.nan))


def _fibre_constants(model: Model):
    """Attachments, fibre-to-muscle matrix per unit PCSA, upright length, l_opt and the fibres' muscle law."""
    upper, lower, share = geometry.all_fibres(model)
    l0 = np.linalg.norm(lower - upper, axis=-1)
    l_opt = model.fibre.optimal_length_ratio * l0
    return upper, lower, model.fibre.specific_tension * share, l0, l_opt, laws.get_law(model.fibre.law)


def chain_muscle_torque_per_pcsa(model: Model, cor, q, qdot):
    """Nonlinear generalised torques of every muscle on every joint per unit PCSA [N m / m^2].

    tau_j = sum over fibres of h_j T(l, v) (paper, Methods: M_i = h_i f_li f_Hi; T the tension of the
    fibre's muscle law, :func:`spinectl.model.laws.tension`), with
    the fibre's length l(q), its lever arm about the moved CoR j, h_j = -dl/dq_j, and its
    shortening velocity v = sum_j h_j q'_j. With one joint free this is
    :func:`spinectl.model.mechanics.muscle_torque_per_pcsa`.

    Parameters
    ----------
    model : Model
    cor : array_like, shape (..., n_cor, 2)
        Upright CoR positions [m].
    q : array_like, shape (..., n_cor)
        Joint rotations [rad].
    qdot : array_like, shape (..., n_cor)
        Joint angular velocities [rad/s].

    Returns
    -------
    numpy.ndarray, shape (..., n_cor, n_muscles)
    """
    upper, lower, to_muscle, _, l_opt, law = _fibre_constants(model)
    moved, _ = chain_positions(q, cor)
    tops = carried_points(upper, q, cor)  # (..., F, 2)
    length, h = fibre_length_and_lever_arm(tops[..., None, :, :], lower, moved[..., :, None, :])  # (..., n, F)
    velocity = np.einsum("...jf,...j->...f", h, np.asarray(qdot, float))
    tension = laws.tension(law, length[..., 0, :], velocity, l_opt, model.fibre, model.errata)
    return (h * tension[..., None, :]) @ to_muscle


def chain_gravity_torque(model: Model, cor, q):
    """Nonlinear generalised torque of the weights on every joint [N m].

    tau_j = -dV/dq_j with V = m g y_m(q): tau_j = -m g (m(q) - c_j(q))_x, the torque of the
    weight about the moved CoR j (:func:`spinectl.model.mechanics.gravity_torque` when one
    joint is free, with its sign convention, ``errata.gravity_sign``); plus the fraction
    ``levels.weight_in_gravity`` of the lumbar levels' weights (:func:`level_weight`), each on
    the joints that carry it (0 by default; docs/chain.md, "The weight of the levels").

    Parameters
    ----------
    model : Model
    cor : array_like, shape (..., n_cor, 2)
        Upright CoR positions [m].
    q : array_like, shape (..., n_cor)
        Joint rotations [rad].

    Returns
    -------
    numpy.ndarray, shape (..., n_cor)
    """
    moved, _ = chain_positions(q, cor)
    mass = carried_points(geometry.mass_position(model)[None, :], q, cor)  # (..., 1, 2)
    weight = model.body.mass * model.body.gravity
    torque = -weight * (mass - moved)[..., 0]
    levels = level_positions(q, cor)  # (..., n - 1, 2); level i is carried by joints i + 1, ...
    arm = (levels[..., :, None, 0] - moved[..., None, :, 0]) * _carried_by(moved.shape[-2])[1:]
    torque = torque - level_weight(model) * arm.sum(axis=-2)
    return gravity_sign(model) * torque


@dataclass(frozen=True)
class ChainCoefficients:
    """The linearised chain at one or many (E, Lambda): tau ~ tau_0 + K q + D q'.

    Muscular terms are per unit PCSA of each muscle [per m^2], as in
    :class:`~spinectl.model.mechanics.SegmentCoefficients`; leading dimensions are those
    of the broadcast (E, Lambda). Every matrix is symmetric, and its diagonal is the
    per-segment coefficient of that CoR.

    Attributes
    ----------
    stiffness_per_pcsa : numpy.ndarray, shape (..., n_cor, n_cor, n_muscles)
        K_i = dtau/dq per unit PCSA of muscle i [N m/rad / m^2].
    damping_per_pcsa : numpy.ndarray, shape (..., n_cor, n_cor, n_muscles)
        D_i = dtau/dq' per unit PCSA [N m s/rad / m^2]; negative semidefinite.
    gravity_stiffness : numpy.ndarray, shape (..., n_cor, n_cor)
        K_g [N m/rad]: m g (y_m - y of the higher CoR), positive definite with the corrected sign;
        plus the levels' weight on the joints that carry them, if ``levels.weight_in_gravity`` > 0.
    passive_stiffness : numpy.ndarray, shape (..., n_cor)
        K_pas per joint as a physical stiffness [N m/rad], entering K as -diag(K_pas).
    length_gradient : numpy.ndarray, shape (..., n_fibres, n_cor)
        dl/dq of every fibre [m/rad], = -h; rank <= 3 for fibres from thorax to pelvis.
    local_damping_per_stiffness : float
        c_loc [s]: the local muscles' damping per unit of their joint stiffness
        (:func:`local_damping_per_stiffness`); 0: stiffness only.
    """

    stiffness_per_pcsa: np.ndarray
    damping_per_pcsa: np.ndarray
    gravity_stiffness: np.ndarray
    passive_stiffness: np.ndarray
    length_gradient: np.ndarray
    local_damping_per_stiffness: float = 0.0

    def stiffness(self, pcsa, local_stiffness=0.0):
        """K - diag(k) [N m/rad]: muscles, gravity, passive and local stiffness.

        Parameters
        ----------
        pcsa : array_like, shape (..., n_muscles)
            PCSA of each global muscle [m^2].
        local_stiffness : array_like, shape (..., n_cor)
            Stiffness k_j >= 0 of the local muscles at each joint [N m/rad]; 0: none.

        Returns
        -------
        numpy.ndarray, shape (..., n_cor, n_cor)
            Symmetric [N m/rad]; its diagonal is S_k - k_k.
        """
        muscular = np.einsum("...jkm,...m->...jk", self.stiffness_per_pcsa, np.asarray(pcsa, float))
        # the passive stiffness and the local muscles span one joint each: they enter the diagonal only
        diagonal = self.passive_stiffness + np.asarray(local_stiffness, float)
        return muscular + self.gravity_stiffness - diagonal[..., None] * np.eye(diagonal.shape[-1])

    def damping(self, pcsa, local_stiffness=0.0):
        """D - c_loc diag(k) [N m s/rad]: the global muscles and the local muscles of stiffness k.

        Parameters
        ----------
        pcsa : array_like, shape (..., n_muscles)
            PCSA of each global muscle [m^2].
        local_stiffness : array_like, shape (..., n_cor)
            Stiffness k_j >= 0 of the local muscles at each joint [N m/rad], whose force-velocity
            slope damps the joint by c_loc k_j (:func:`local_damping_per_stiffness`); 0: none.

        Returns
        -------
        numpy.ndarray, shape (..., n_cor, n_cor)
            Symmetric, negative semidefinite [N m s/rad]; its diagonal is D_k - c_loc k_k.
        """
        muscular = np.einsum("...jkm,...m->...jk", self.damping_per_pcsa, np.asarray(pcsa, float))
        local = self.local_damping_per_stiffness * np.asarray(local_stiffness, float)
        return muscular - local[..., None] * np.eye(muscular.shape[-1])


CHAIN_MONOMIALS = ("1", "x_j + x_k", "y_j + y_k", "x_j x_k", "x_j y_k + y_j x_k", "y_j y_k", "x_hi", "y_hi")
"""The monomials in the coordinates (x, y) of CoRs j and k (hi the higher of the two) of which every
muscle's K_i[j, k] and D_i[j, k] is a linear combination (docs/chain.md, "The monomial form")."""


def _monomial_coefficients(model: Model):
    """Per-muscle coefficients of K_i[j, k] and D_i[j, k] in :data:`CHAIN_MONOMIALS`, and each fibre's lever arm.

    Upright, e = P - U and l0 do not depend on the CoRs, so the lever arm h_j = (u_j x e) / l0
    is affine in c_j, h_j = a + b x_j + d y_j, while u_j . u_k + e . u_hi is quadratic in
    (c_j, c_k) and affine in c_hi; both are combinations of the 8 monomials with coefficients
    that depend on the fibre alone (docs/chain.md, "The monomial form"). Summing them into
    muscles here, once for all points, leaves one product per grid point and pair (j, k).

    Returns
    -------
    stiffness, damping : numpy.ndarray, shape (8, n_muscles)
        Coefficients of the monomials [N m/rad / m^2 per m^k, N m s/rad / m^2 per m^k; k the degree].
    lever_arm : numpy.ndarray, shape (3, n_fibres)
        a [m], b and d [1] of every fibre.
    """
    upper, lower, to_muscle, l0, f_l, f_l_slope, f_h_slope = _fibre_laws(model)
    e = lower - upper
    # the lever arm is affine in the CoR c = (x, y): h = a + b x + d y, since the fibre's line does not move
    # with c. So h_j h_k and the Hessian are quadratic in the CoRs' coordinates: per fibre, eight numbers
    # (one per monomial), and every grid point's matrices are one matrix product, no loop over fibres.
    a, b, d = cross2(upper, e) / l0, -e[:, 1] / l0, e[:, 0] / l0
    zero, one = np.zeros_like(a), np.ones_like(a)
    hh = np.stack([a * a, a * b, a * d, b * b, b * d, d * d, zero, zero])  # h_j h_k
    # u_j . u_k + e . u_hi = U . P - U . (c_j + c_k) + c_j . c_k - e . c_hi
    uu = np.stack([np.sum(upper * lower, axis=-1), -upper[:, 0], -upper[:, 1], one, zero, one, -e[:, 0], -e[:, 1]])
    stiffness = (hh * (f_l / l0 - f_l_slope) - uu * (f_l / l0)) @ to_muscle  # -f_l' hh - f_l d2l
    damping = (hh * (f_l * f_h_slope)) @ to_muscle
    return stiffness, damping, np.stack([a, b, d])


def _pairs(n: int):
    """The n (n + 1) / 2 pairs j <= k of CoRs, and the pair of every (j, k): K and D are symmetric by construction."""
    j, k = np.triu_indices(n)
    pair_of = np.empty((n, n), dtype=int)
    pair_of[j, k] = pair_of[k, j] = np.arange(j.size)
    return j, k, pair_of


def _muscle_matrices(model: Model, cor):
    """K_i and D_i per unit PCSA, (..., n, n, M), and dl/dq, (..., F, n), in the monomial form.

    Stacked small matrix products (one per point), not one large one: BLAS threads the large
    one, which costs more than it saves on a shared machine for an inner dimension of 8.
    """
    stiffness_terms, damping_terms, lever_terms = _monomial_coefficients(model)
    x, y = cor[..., 0], cor[..., 1]
    j, k, pair_of = _pairs(cor.shape[-2])  # j <= k: CoR j is the higher (they are ordered top to bottom)
    xj, xk, yj, yk = x[..., j], x[..., k], y[..., j], y[..., k]
    monomials = np.empty(cor.shape[:-2] + (j.size, len(CHAIN_MONOMIALS)))
    for i, value in enumerate((1.0, xj + xk, yj + yk, xj * xk, xj * yk + yj * xk, yj * yk, xj, yj)):
        monomials[..., i] = value
    n_muscles = stiffness_terms.shape[-1]
    both = monomials @ np.concatenate([stiffness_terms, damping_terms], axis=-1)  # (..., pairs, 2 M)
    lever = np.stack([np.ones_like(x), x, y], axis=-1) @ -lever_terms  # (..., n, F): -h = -(a + b x + d y)
    return both[..., pair_of, :n_muscles], both[..., pair_of, n_muscles:], np.swapaxes(lever, -1, -2)


def _gravity_stiffness(model: Model, y):
    """K_g [N m/rad] from the CoR heights y, (..., n): the point mass and the levels' weight (docs/chain.md).

    Level b (upright at the height Y_b = (y_b + y_{b+1}) / 2, :func:`level_positions`) is carried
    by the joints below it, so it adds w (Y_b - y_hi) wherever b < hi, the higher of j and k:
    w (sum_{b < hi} Y_b - hi y_hi).
    """
    n = y.shape[-1]
    # dtau_j/dq_k moves what both joints carry, the weight above the higher of CoRs j and k, so the
    # entry depends on that CoR alone (CoRs are ordered top to bottom: the higher has the lower index)
    higher = np.minimum.outer(np.arange(n), np.arange(n))
    y_hi = y[..., higher]
    below = np.concatenate([np.zeros(y.shape[:-1] + (1,)), np.cumsum((y[..., :-1] + y[..., 1:]) / 2, axis=-1)], -1)
    levels = level_weight(model) * (below[..., higher] - higher * y_hi)
    weight = model.body.mass * model.body.gravity
    return gravity_sign(model) * (weight * (model.body.mass_height - y_hi) + levels)


def chain_coefficients(model: Model, eccentricity, lordosis) -> ChainCoefficients:
    """Stiffness and damping matrices of the chain at the upright equilibrium, per unit PCSA.

    With u_j = U - c_j (upper attachment from CoR j), e = P - U (the fibre) and
    h_j = (u_j x e) / l the lever arm about CoR j, the fibre length has the Hessian

        d2l/dq_j dq_k = (u_j . u_k + e . u_hi - h_j h_k) / l,

    hi the higher of CoRs j and k (the second derivative of the carried point U is
    -u_hi); its diagonal is -dh/dalpha of :func:`~spinectl.model.mechanics.lever_arm_slope`.
    Per unit f_iso of a fibre, K = -f_l' h h' - f_l d2l and D = f_l f_H'(0) h h'
    (docs/chain.md); gravity and the passive stiffness as in the per-segment model.
    The fibres are summed once for all points into polynomials in the CoR coordinates
    (:data:`CHAIN_MONOMIALS`; docs/chain.md, "The monomial form"), which equal the
    per-fibre sums (:func:`chain_per_fibre_sums`) to rounding.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : array_like
        E and Lambda [m]; broadcast together.

    Returns
    -------
    ChainCoefficients

    References
    ----------
    Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal lordosis
    optimizes the requirements for a stable erect posture. Theor Biol Med Model 9:13.
    doi:10.1186/1742-4682-9-13.
    """
    cor = geometry.cor_positions(eccentricity, lordosis, model.geometry)  # (..., n, 2)
    stiffness, damping, length_gradient = _muscle_matrices(model, cor)
    return ChainCoefficients(
        stiffness_per_pcsa=stiffness,
        damping_per_pcsa=damping,
        gravity_stiffness=_gravity_stiffness(model, cor[..., 1]),
        passive_stiffness=passive_stiffness(model, inertia(cor, model)),
        length_gradient=length_gradient,
        local_damping_per_stiffness=local_damping_per_stiffness(model),
    )


def linear_chain(model: Model, eccentricity: float, lordosis: float, coefficients=None) -> LinearChain:
    """The paper's chain at one (E, Lambda) as a :class:`~spinectl.model.linear_chain.LinearChain`.

    The controls are the decision variables x of the optimisation (docs/optimisation.md,
    "Formulation"), so that the chain's programmes and the per-segment problem share them: with
    ``optimisation.activation = "paired"`` one per pair, the PCSA of either side (a pair's total
    is twice it); with ``"independent"`` one per muscle; in cm^2, class ``"global"`` (thorax to
    pelvis), bounds 0 <= x <= ``optimisation.pcsa_max``. Per unit x, K_i and D_i are those of
    :func:`chain_coefficients` per m^2 of the muscles it sets; K_0 = K_g - diag(K_pas) (gravity and
    the passive stiffness), D_0 = 0 (the model has no passive damping), M of :func:`mass_matrix`;
    local joint stiffness brings the damping of its force-velocity slope (:func:`local_damping_per_stiffness`).

    Parameters
    ----------
    model : Model
        ``optimisation`` (activation, pcsa_max) and the physics.
    eccentricity, lordosis : float
        E and Lambda [m].
    coefficients : ChainCoefficients, optional
        :func:`chain_coefficients` at (E, Lambda), if computed already.

    Returns
    -------
    LinearChain
        ``control_unit`` "cm^2"; ``source`` the model's :func:`~spinectl.model.source.header` and (E, Lambda).

    References
    ----------
    Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal lordosis
    optimizes the requirements for a stable erect posture. Theor Biol Med Model 9:13.
    doi:10.1186/1742-4682-9-13.

    Examples
    --------
    >>> from spinectl import load_preset
    >>> from spinectl.model.chain import linear_chain
    >>> chain = linear_chain(load_preset("wagner2012"), 0.03, 0.04)
    >>> chain.controls, chain.control_unit, chain.mass_matrix.shape
    (('straight', 'oblique_outer', 'oblique_inner'), 'cm^2', (5, 5))
    """
    e, lam = float(eccentricity), float(lordosis)
    coeffs = chain_coefficients(model, e, lam) if coefficients is None else coefficients
    n_muscles = coeffs.stiffness_per_pcsa.shape[-1]
    paired = model.optimisation.activation == "paired"
    to_muscles = geometry.pairing_matrix(n_muscles // 2) if paired else np.eye(n_muscles)
    per_var = to_muscles * M2_PER_CM2  # m^2 of each muscle per cm^2 of x
    n, m = coeffs.stiffness_per_pcsa.shape[0], per_var.shape[1]
    return LinearChain(
        joints=model.geometry.cor_names,
        controls=model.pair_names if paired else model.muscle_names,
        control_class=("global",) * m,
        stiffness_per_control=coeffs.stiffness_per_pcsa @ per_var,
        damping_per_control=coeffs.damping_per_pcsa @ per_var,
        stiffness_offset=coeffs.stiffness(np.zeros(n_muscles)),
        damping_offset=np.zeros((n, n)),
        mass_matrix=mass_matrix(model, geometry.cor_positions(e, lam, model.geometry)),
        lower=np.zeros(m),
        upper=np.full(m, model.optimisation.pcsa_max / M2_PER_CM2),
        control_unit="cm^2",
        source=f"{header(model)}; E = {e:g} m, Lambda = {lam:g} m",
        local_damping_per_stiffness=coeffs.local_damping_per_stiffness,
    )


def chain_per_fibre_sums(model: Model, eccentricity, lordosis):
    """The muscle terms of :func:`chain_coefficients` summed fibre by fibre, as the formulas read.

    K = -f_l' h h' - f_l d2l/dq dq' and D = f_l f_H'(0) h h' of every fibre at every pair of
    CoRs, with h from :func:`~spinectl.model.mechanics.fibre_length_and_lever_arm` and the
    Hessian of :func:`chain_coefficients`, summed into muscles: the direct form that the
    monomial form equals (its test, and the "before" of benchmarks/bench_sweep.py).

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : array_like
        E and Lambda [m]; broadcast together.

    Returns
    -------
    stiffness, damping : numpy.ndarray, shape (..., n_cor, n_cor, n_muscles)
        Per unit PCSA [N m/rad / m^2], [N m s/rad / m^2].
    length_gradient : numpy.ndarray, shape (..., n_fibres, n_cor)
        dl/dq [m/rad].
    """
    cor = geometry.cor_positions(eccentricity, lordosis, model.geometry)  # (..., n, 2)
    upper, lower, to_muscle, l0, f_l, f_l_slope, f_h_slope = _fibre_laws(model)
    _, h = fibre_length_and_lever_arm(upper, lower, cor[..., :, None, :])  # (..., n, F)
    u = upper - cor[..., :, None, :]  # (..., n, F, 2)
    n = cor.shape[-2]
    higher = np.minimum.outer(np.arange(n), np.arange(n))
    e_dot_u = np.einsum("fd,...jfd->...jf", lower - upper, u)
    hh = h[..., :, None, :] * h[..., None, :, :]  # (..., n, n, F)
    hessian = (np.einsum("...jfd,...kfd->...jkf", u, u) + e_dot_u[..., higher, :] - hh) / l0
    stiffness = (-f_l_slope * hh - f_l * hessian) @ to_muscle
    return stiffness, (f_l * f_h_slope * hh) @ to_muscle, -np.swapaxes(h, -1, -2)


def coupled_margin(stiffness):
    """Smallest eigenvalue of -K [N m/rad]: the static stability margin of the chain.

    The upright chain is statically stable (Bergmark 1989: the potential energy has a
    minimum) iff -K is positive definite; spinectl's sign convention is that of S_k,
    stable for negative stiffness. Its diagonal entries are -S_k, so the margin is at
    most min_k(-S_k), the per-segment margin.

    Parameters
    ----------
    stiffness : array_like, shape (..., n_cor, n_cor)
        Symmetric K, or K - diag(k) with local stiffness k [N m/rad]
        (:meth:`ChainCoefficients.stiffness`).

    Returns
    -------
    numpy.ndarray, shape (...)
        [N m/rad]; > 0 stable.

    References
    ----------
    Bergmark A (1989). Stability of the lumbar spine. A study in mechanical engineering.
    Acta Orthop Scand Suppl 230:1-54. doi:10.3109/17453678909154177.
    """
    return np.linalg.eigvalsh(-np.asarray(stiffness, float))[..., 0]
