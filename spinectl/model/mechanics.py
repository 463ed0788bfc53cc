"""Segment mechanics: torques of fibres and gravity about the centres of rotation.

Pure array functions, SI units. For CoR k the part above it (thoracic cage,
upper attachments, point mass) rotates by alpha about CoR k; the pelvis and
all lower attachments stay fixed (paper, Methods: "we assumed all other CoR to
be fixed"). alpha is counter-clockwise (towards -x for a point above) and
measured from the upright configuration; torques are positive
counter-clockwise.

Everything muscular is linear in PCSA, so the linearisation is stored per unit
PCSA [per m^2]: :func:`segment_coefficients` returns the torque, stiffness
dM/dalpha and damping dM/domega of every muscle about every CoR, and the
gravity terms, which together define every problem spinectl solves. The
formulas are the paper's [1]_ (Methods), as read in docs/model.md ("Lever arms"
to "Passive stiffness: two conventions").

References
----------
.. [1] Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal
   lordosis optimizes the requirements for a stable erect posture. Theor Biol Med
   Model 9:13. doi:10.1186/1742-4682-9-13
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import geometry, laws
from .params import Model


def rotate(vectors, alpha):
    """Rotate 2-vectors counter-clockwise by ``alpha`` [rad]; broadcasts.

    Parameters
    ----------
    vectors : array_like, shape (..., 2)
        (x, y) components [any length unit].
    alpha : array_like
        Angle [rad], counter-clockwise positive.

    Returns
    -------
    numpy.ndarray, shape (..., 2)
        The rotated vectors, in the unit of ``vectors``; the broadcast shape of
        ``vectors`` and ``alpha``.
    """
    vectors = np.asarray(vectors, float)
    cos, sin = np.cos(alpha), np.sin(alpha)
    x, y = vectors[..., 0], vectors[..., 1]
    return np.stack([cos * x - sin * y, sin * x + cos * y], axis=-1)


def cross2(a, b):
    """z-component of the cross product of 2-vectors, a_x b_y - a_y b_x.

    Parameters
    ----------
    a, b : numpy.ndarray, shape (..., 2)
        The vectors; broadcast together.

    Returns
    -------
    numpy.ndarray, shape (...)
        a x b, in the product of the units of ``a`` and ``b`` (e.g. [m^2]).
    """
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def fibre_length_and_lever_arm(upper, lower, cor, alpha=0.0):
    """Length and signed lever arm of fibres with the upper body rotated by alpha.

    With u = R(alpha)(U - c) and p = P - c (U upper, P lower attachment, c the
    CoR), the fibre vector e = p - u, l = norm(e) and h = (u x e) / l, so that a
    tension T gives the torque T h about c. Equivalently h = -dl/dalpha
    (virtual work), which makes the shortening velocity v = h omega.

    Parameters
    ----------
    upper, lower : array_like, shape (..., 2)
        Attachment points in the upright configuration [m].
    cor : array_like, shape (..., 2)
        Centre of rotation [m].
    alpha : array_like
        Rotation of the upper body about ``cor`` [rad].

    Returns
    -------
    length, lever_arm : numpy.ndarray
        l [m] and h [m].
    """
    u = rotate(np.asarray(upper) - cor, alpha)
    e = np.asarray(lower) - cor - u
    length = np.hypot(e[..., 0], e[..., 1])
    return length, cross2(u, e) / length


def lever_arm_slope(upper, lower, cor):
    """dh/dalpha at alpha = 0 [m/rad], analytic.

    From l'' = (p . u - h^2) / l at alpha = 0 (differentiate l' = -(e . J u)/l
    once more, J the quarter turn) and h = -l': dh/dalpha = (h^2 - p . u) / l.

    Parameters
    ----------
    upper, lower : array_like, shape (..., 2)
        Attachment points in the upright configuration [m].
    cor : array_like, shape (..., 2)
        Centre of rotation [m].

    Returns
    -------
    numpy.ndarray, shape (...)
        dh/dalpha at the upright posture [m/rad]; the broadcast shape of the points
        without their last axis.
    """
    u = np.asarray(upper) - cor
    p = np.asarray(lower) - cor
    length, h = fibre_length_and_lever_arm(upper, lower, cor)
    return (h**2 - np.sum(p * u, axis=-1)) / length


def fibre_torque(alpha, omega, upper, lower, cor, fibre_params, errata):
    """Nonlinear torque of fibres per unit isometric force, M_i / f_iso [m].

    M_i = h_i T(l_i, h_i omega) (paper, Methods: M_i = h_i f_li f_Hi), T the tension of the
    fibre's muscle law (``fibre_params.law``, :func:`spinectl.model.laws.tension`), with
    l_opt = optimal_length_ratio * l0 and l0 the upright length.

    Parameters
    ----------
    alpha : array_like
        Rotation about the CoR [rad].
    omega : array_like
        Angular velocity [rad/s].
    upper, lower, cor : array_like, shape (..., 2)
        Upright attachment points and CoR [m].
    fibre_params : Fibre
        The fibres' constants and ``law``.
    errata : Errata

    Returns
    -------
    numpy.ndarray
        M_i / f_iso [m] of every fibre; the broadcast shape of ``alpha``, ``omega``
        and the points without their last axis.
    """
    l0 = np.linalg.norm(np.asarray(lower) - np.asarray(upper), axis=-1)
    l_opt = fibre_params.optimal_length_ratio * l0
    length, h = fibre_length_and_lever_arm(upper, lower, cor, alpha)
    return laws.tension(laws.get_law(fibre_params.law), length, h * omega, l_opt, fibre_params, errata, lever_arm=h)


def muscle_torque_per_pcsa(model: Model, cor, alpha, omega):
    """Nonlinear torque of every muscle about a CoR per unit PCSA [N m / m^2].

    Sums :func:`fibre_torque` over each muscle's fibres, each fibre carrying
    1/n of the muscle's PCSA, times the specific tension (f_iso per PCSA).

    Parameters
    ----------
    model : Model
    cor : array_like, shape (..., 2)
        CoR position [m].
    alpha, omega : array_like
        Rotation [rad] and angular velocity [rad/s] of the upper body about ``cor``;
        broadcast against ``cor[..., 0]``.

    Returns
    -------
    numpy.ndarray, shape (..., n_muscles)
        Torque of each muscle per unit of its PCSA [N m / m^2].
    """
    upper, lower, share = geometry.all_fibres(model)
    c = np.asarray(cor, float)[..., None, :]
    a = np.asarray(alpha, float)[..., None]
    w = np.asarray(omega, float)[..., None]
    per_fiso = fibre_torque(a, w, upper, lower, c, model.fibre, model.errata)
    return per_fiso @ (model.fibre.specific_tension * share)


def gravity_sign(model: Model) -> float:
    """+1 for the destabilising (corrected) sign of gravity, -1 for the printed one.

    Parameters
    ----------
    model : Model
        Supplies ``errata.gravity_sign``.

    Returns
    -------
    float
        +1.0 ('destabilising') or -1.0 ('printed') [1].
    """
    return 1.0 if model.errata.gravity_sign == "destabilising" else -1.0


def gravity_torque(alpha, cor, model: Model):
    """Torque of the point mass about a CoR, M_ext [N m].

    With r = R(alpha)(m_pos - c), the torque of the weight (0, -m g) is
    -m g r_x. For a mass above the CoR this is m g norm(r) sin(angle from
    vertical), an inverted pendulum: dM_ext/dalpha = m g r_y > 0. This is the
    corrected sign (docs/model.md, "Gravity sign"); the paper prints
    M_ext = -m g r sin(alpha) (``errata.gravity_sign = "printed"`` negates the whole
    torque).

    Parameters
    ----------
    alpha : array_like
        Rotation about the CoR [rad].
    cor : array_like, shape (..., 2)
        CoR position [m].
    model : Model

    Returns
    -------
    numpy.ndarray, shape (...)
        M_ext [N m]; the broadcast shape of ``alpha`` and ``cor`` without its last axis.
    """
    r = rotate(geometry.mass_position(model) - np.asarray(cor), alpha)
    weight = model.body.mass * model.body.gravity
    return gravity_sign(model) * (-weight * r[..., 0])


def inertia(cor, model: Model):
    """Moment of inertia of the upper body about a CoR, theta_k [kg m^2].

    theta_k = m (r_k^2 + rho^2), r_k the CoR-to-mass distance and rho the
    radius of gyration (docs/model.md, "Gravity": default rho = 0, m r_k^2).

    Parameters
    ----------
    cor : array_like, shape (..., 2)
        CoR position [m].
    model : Model
        Supplies the mass [kg], its height [m] and the radius of gyration [m].

    Returns
    -------
    numpy.ndarray, shape (...)
        theta_k [kg m^2]; the shape of ``cor`` without its last axis.
    """
    r = geometry.mass_position(model) - np.asarray(cor)
    return model.body.mass * (np.sum(r**2, axis=-1) + model.body.radius_of_gyration**2)


def passive_stiffness(model: Model, inertia_k):
    """Passive stiffness K as a physical torque stiffness [N m/rad], per CoR.

    'physical': K itself. 'paper': eq. 2 of the paper [1]_ subtracts K from d(omega')/dalpha,
    i.e. K theta_k from dM/dalpha (docs/model.md, "Passive stiffness: two
    conventions" and "Units of eq. 2").

    Parameters
    ----------
    model : Model
        Supplies ``passive.stiffness`` and ``passive.convention``.
    inertia_k : array_like
        theta_k of each CoR [kg m^2]; sets the output shape.

    Returns
    -------
    numpy.ndarray
        K_k [N m/rad], the shape of ``inertia_k``; enters dM_k/dalpha as -K_k.

    References
    ----------
    .. [1] Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal
       lordosis optimizes the requirements for a stable erect posture. Theor Biol Med
       Model 9:13. doi:10.1186/1742-4682-9-13
    """
    k = model.passive.stiffness
    if model.passive.convention == "paper":
        return k * np.asarray(inertia_k)
    return np.full(np.shape(inertia_k), k)


@dataclass(frozen=True)
class SegmentCoefficients:
    """The linearised segment mechanics at one or many (E, Lambda).

    Muscular terms are per unit PCSA of each muscle [per m^2]; a PCSA vector
    ``pcsa`` [m^2] gives e.g. the stiffness ``stiffness_per_pcsa @ pcsa``.
    Leading dimensions are those of the broadcast (E, Lambda).

    Attributes
    ----------
    torque_per_pcsa : numpy.ndarray, shape (..., n_cor, n_muscles)
        Muscle torque at the upright equilibrium [N m / m^2].
    stiffness_per_pcsa : numpy.ndarray, shape (..., n_cor, n_muscles)
        dM/dalpha [N m/rad / m^2]; negative is stabilising.
    damping_per_pcsa : numpy.ndarray, shape (..., n_cor, n_muscles)
        dM/domega [N m s/rad / m^2]; always <= 0 (Hill slope).
    gravity_torque : numpy.ndarray, shape (..., n_cor)
        M_ext at the upright equilibrium [N m].
    gravity_stiffness : numpy.ndarray, shape (..., n_cor)
        dM_ext/dalpha [N m/rad]; positive (destabilising) with the corrected sign.
    passive_stiffness : numpy.ndarray, shape (..., n_cor)
        K as a physical stiffness [N m/rad], entering dM/dalpha as -K.
    inertia : numpy.ndarray, shape (..., n_cor)
        theta_k [kg m^2].
    """

    torque_per_pcsa: np.ndarray
    stiffness_per_pcsa: np.ndarray
    damping_per_pcsa: np.ndarray
    gravity_torque: np.ndarray
    gravity_stiffness: np.ndarray
    passive_stiffness: np.ndarray
    inertia: np.ndarray

    def stiffness(self, pcsa):
        """Total dM_k/dalpha [N m/rad]: muscles, gravity and passive stiffness.

        Parameters
        ----------
        pcsa : array_like, shape (..., n_muscles)
            PCSA of each muscle [m^2].

        Returns
        -------
        numpy.ndarray, shape (..., n_cor)
            S_k [N m/rad]; negative is stabilising.
        """
        muscular = np.einsum("...km,...m->...k", self.stiffness_per_pcsa, np.asarray(pcsa, float))
        return muscular + self.gravity_stiffness - self.passive_stiffness

    def damping(self, pcsa):
        """Total dM_k/domega [N m s/rad] of the muscles.

        Parameters
        ----------
        pcsa : array_like, shape (..., n_muscles)
            PCSA of each muscle [m^2].

        Returns
        -------
        numpy.ndarray, shape (..., n_cor)
            D_k [N m s/rad], <= 0.
        """
        return np.einsum("...km,...m->...k", self.damping_per_pcsa, np.asarray(pcsa, float))

    def counter_torque(self, pcsa):
        """Local counter torques CT_k [N m] making the upright posture an equilibrium.

        CT_k = -(sum_i M_i + M_ext) at alpha = 0, omega = 0 (paper, Methods;
        docs/model.md, "The counter torques"). Affine in PCSA.

        Parameters
        ----------
        pcsa : array_like, shape (..., n_muscles)
            PCSA of each muscle [m^2].

        Returns
        -------
        numpy.ndarray, shape (..., n_cor)
            CT_k [N m].
        """
        muscular = np.einsum("...km,...m->...k", self.torque_per_pcsa, np.asarray(pcsa, float))
        return -(muscular + self.gravity_torque)


def _fibre_laws(model: Model):
    """Every fibre's attachments, its share of the muscles' PCSA times the specific tension (f_iso per PCSA),
    upright length l0 and, there, by its muscle law (:func:`spinectl.model.laws.at_rest`), the tension T, dT/dl
    and (dT/dv) / T (per unit f_iso; the paper's T = f_l, dT/dl = f_l' and (dT/dv) / T = f_H'(0))."""
    upper, lower, share = geometry.all_fibres(model)  # (F, 2), (F, 2), (F, M)
    l0 = np.linalg.norm(lower - upper, axis=-1)
    l_opt = model.fibre.optimal_length_ratio * l0
    rest = laws.at_rest(laws.get_law(model.fibre.law), l0, l_opt, model.fibre, model.errata)
    to_muscle = model.fibre.specific_tension * share
    return upper, lower, to_muscle, l0, rest.tension, rest.length_slope, rest.relative_velocity_slope


def _monomial_coefficients(model: Model):
    """Per-muscle coefficients of the torque, stiffness and damping as polynomials in the CoR (cx, cy).

    At the upright posture the fibre vector e = P - U does not depend on the CoR c, so the
    lever arm h = (u x e) / l with u = U - c is affine in c, h = a + b cx + d cy, and
    p . u = (P - c) . (U - c) is quadratic; so the three sums over fibres of
    :func:`segment_coefficients` are polynomials of degree <= 2 in (cx, cy) whose coefficients
    depend on the fibres only. Summing the fibres into muscles here, once per model, leaves
    a product with the 6 monomials (1, cx, cy, cx^2, cy^2, cx cy) per CoR: the same formulas,
    no per-fibre work per grid point (benchmarks/bench_sweep.py measures it).

    Returns
    -------
    torque, stiffness, damping : numpy.ndarray, shapes (3, n_muscles), (6, n_muscles), (6, n_muscles)
        Coefficients of the monomials [N m / m^2 per m^k, k the monomial's degree; per rad, per rad/s].
    """
    upper, lower, to_muscle, l0, f_l, f_l_slope, f_h_slope = _fibre_laws(model)
    e = lower - upper
    a, b, d = cross2(upper, e) / l0, -e[:, 1] / l0, e[:, 0] / l0  # h = a + b cx + d cy
    h2 = np.stack([a * a, 2 * a * b, 2 * a * d, b * b, d * d, 2 * b * d])  # h^2 in the monomials
    sums, one = upper + lower, np.ones_like(a)
    pu = np.stack([np.sum(upper * lower, axis=-1), -sums[:, 0], -sums[:, 1], one, one, 0.0 * one])  # p.u likewise
    torque = (np.stack([a, b, d]) * f_l) @ to_muscle  # M = h f_l
    stiffness = (h2 * (f_l / l0 - f_l_slope) - pu * (f_l / l0)) @ to_muscle  # h' f_l - h^2 f_l', h' = (h^2 - p.u)/l
    damping = (h2 * (f_l * f_h_slope)) @ to_muscle  # h^2 f_l f_H'(0)
    return torque, stiffness, damping


def per_fibre_sums(model: Model, eccentricity, lordosis):
    """The muscle terms of :func:`segment_coefficients` summed fibre by fibre, as the formulas read.

    torque h f_l, stiffness h' f_l - h^2 f_l', damping h^2 f_l f_H'(0) of every fibre about every
    CoR (:func:`fibre_length_and_lever_arm`, :func:`lever_arm_slope`), summed into muscles: the
    direct form that :func:`segment_coefficients`'s monomial form equals (its test, and the
    benchmark's "before").

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : array_like
        E and Lambda [m]; broadcast together.

    Returns
    -------
    torque, stiffness, damping : numpy.ndarray, shape (..., n_cor, n_muscles)
        Per unit PCSA [N m / m^2], [N m/rad / m^2], [N m s/rad / m^2].
    """
    cor = geometry.cor_positions(eccentricity, lordosis, model.geometry)[..., None, :]
    upper, lower, to_muscle, _, f_l, f_l_slope, f_h_slope = _fibre_laws(model)
    _, h = fibre_length_and_lever_arm(upper, lower, cor)
    h_slope = lever_arm_slope(upper, lower, cor)
    return (h * f_l) @ to_muscle, (h_slope * f_l - h**2 * f_l_slope) @ to_muscle, (h**2 * f_l * f_h_slope) @ to_muscle


def segment_coefficients(model: Model, eccentricity, lordosis) -> SegmentCoefficients:
    """Linearised torques, stiffness and damping of every muscle about every CoR.

    Per fibre at alpha = 0, omega = 0, per unit f_iso (so times specific
    tension per unit PCSA; each fibre carries 1/n of its muscle's PCSA):

    - torque:    M = h f_l(l0)                         (paper: M_i = h_i f_li f_Hi, f_H(0) = f_iso)
    - stiffness: dM/dalpha = h' f_l - h^2 f_l'         (h' from :func:`lever_arm_slope`, dl/dalpha = -h)
    - damping:   dM/domega = h^2 f_l f_H'(0)           (v = h omega)

    These are the partial derivatives that enter the Jacobian of the paper's eq. 1
    [1]_ (docs/model.md, "Stiffness and damping per unit PCSA").

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : array_like
        E and Lambda [m]; broadcast together.

    Returns
    -------
    SegmentCoefficients
        Per unit PCSA, shape (..., n_cor, n_muscles): torque [N m / m^2], stiffness
        [N m/rad / m^2], damping [N m s/rad / m^2]; per CoR, shape (..., n_cor): gravity
        torque [N m] and stiffness [N m/rad], passive stiffness [N m/rad], inertia
        [kg m^2]. ``...`` is the broadcast shape of E and Lambda.

    References
    ----------
    .. [1] Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal
       lordosis optimizes the requirements for a stable erect posture. Theor Biol Med
       Model 9:13. doi:10.1186/1742-4682-9-13
    """
    cor = geometry.cor_positions(eccentricity, lordosis, model.geometry)  # (..., K, 2)
    torque_terms, stiffness_terms, damping_terms = _monomial_coefficients(model)
    cx, cy = cor[..., 0], cor[..., 1]
    monomials = np.stack([np.ones_like(cx), cx, cy, cx * cx, cy * cy, cx * cy], axis=-1)  # (..., K, 6)
    torque = monomials[..., :3] @ torque_terms
    stiffness = monomials @ stiffness_terms
    damping = monomials @ damping_terms

    theta = inertia(cor, model)
    r_y = model.body.mass_height - cor[..., 1]
    return SegmentCoefficients(
        torque_per_pcsa=torque,
        stiffness_per_pcsa=stiffness,
        damping_per_pcsa=damping,
        gravity_torque=gravity_torque(0.0, cor, model),
        gravity_stiffness=gravity_sign(model) * model.body.mass * model.body.gravity * r_y,
        passive_stiffness=passive_stiffness(model, theta),
        inertia=theta,
    )
