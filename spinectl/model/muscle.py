"""Muscle fibre mechanics: the paper's force-length and Hill force-velocity relations.

These are the formulas of the ``wagner2012`` muscle law (:mod:`spinectl.model.laws.wagner2012`):
the model, the chain and the exports reach them through the muscle-law seam
(:mod:`spinectl.model.laws`, docs/model.md, "The muscle-law seam"), never directly.
Pure array functions; ``fibre`` is a :class:`~spinectl.model.params.Fibre` and ``errata`` an
:class:`~spinectl.model.params.Errata`, read by attribute (so that the laws, which the parameters
validate their ``law`` against, import no parameters). Forces are returned per unit isometric force (divide by
f_iso = specific_tension * PCSA), so every quantity is linear in PCSA
(docs/model.md, "Force-velocity"). Velocities are *shortening* velocities:
v >= 0 concentric. The relations are the paper's [1]_ (Methods), with the eccentric
constant C corrected (docs/model.md, "Eccentric Hill constant C"); the hyperbolic
force-velocity relation is Hill's [2]_.

References
----------
.. [1] Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal
   lordosis optimizes the requirements for a stable erect posture. Theor Biol Med
   Model 9:13. doi:10.1186/1742-4682-9-13
.. [2] Hill AV (1938). The heat of shortening and the dynamic constants of muscle.
   Proc R Soc Lond B 126:136-195.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def force_length(length, optimal_length, fibre):
    """Force-length factor f_l [1] (paper, Methods; its refs 17, 18).

    f_l = exp(-(((l / l_opt)^k1 - 1) / k2)^2), the paper's force-length relation [1]_
    (docs/model.md, "Force-length").

    Parameters
    ----------
    length : array_like
        Fibre length l [m].
    optimal_length : array_like
        Optimal fibre length l_opt [m] (paper: 1.2 l0).
    fibre : Fibre
        Supplies k1 and k2 [1].

    Returns
    -------
    numpy.ndarray
        f_l [1], in (0, 1], 1 at l = l_opt; the broadcast shape of ``length`` and
        ``optimal_length``.

    References
    ----------
    .. [1] Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal
       lordosis optimizes the requirements for a stable erect posture. Theor Biol Med
       Model 9:13. doi:10.1186/1742-4682-9-13
    """
    u = ((np.asarray(length) / optimal_length) ** fibre.k1 - 1.0) / fibre.k2
    return np.exp(-(u**2))


def force_length_slope(length, optimal_length, fibre):
    """Derivative df_l/dl of :func:`force_length` [1/m], analytic.

    df_l/dl = f_l * (-2 u / k2) * k1 (l/l_opt)^(k1 - 1) / l_opt, u = ((l/l_opt)^k1 - 1)/k2.
    Positive on the ascending limb (l < l_opt).

    Parameters
    ----------
    length : array_like
        Fibre length l [m].
    optimal_length : array_like
        Optimal fibre length l_opt [m].
    fibre : Fibre
        Supplies k1 and k2 [1].

    Returns
    -------
    numpy.ndarray
        df_l/dl [1/m]; the broadcast shape of ``length`` and ``optimal_length``.
    """
    ratio = np.asarray(length) / optimal_length
    u = (ratio**fibre.k1 - 1.0) / fibre.k2
    return np.exp(-(u**2)) * (-2.0 * u / fibre.k2) * fibre.k1 * ratio ** (fibre.k1 - 1.0) / optimal_length


@dataclass(frozen=True)
class HillConstants:
    """Hill constants per unit f_iso: a, c, A, C in units of f_iso; b, B in m/s.

    From the paper (Methods; its refs 15, 21-23): a = f_iso/4, b = v_max/4,
    c = b (f_iso + a), A = f_ecc f_iso, B = (A - f_iso) b^2 / c and, with
    erratum C, C = (A - f_iso) B (printed: C = (A - f_iso) b).

    Attributes
    ----------
    a : numpy.ndarray
        a / f_iso [1].
    b : numpy.ndarray
        b [m/s].
    c : numpy.ndarray
        c / f_iso [m/s].
    A : numpy.ndarray
        A / f_iso [1], the eccentric asymptote.
    B : numpy.ndarray
        B [m/s].
    C : numpy.ndarray
        C / f_iso [m/s].
    """

    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    A: np.ndarray
    B: np.ndarray
    C: np.ndarray


def max_velocity(optimal_length, fibre):
    """v_max = (vmax_slow + vmax_fast_gain FT) l_opt [m/s] (paper: (6 + 10 FT) l_opt).

    Parameters
    ----------
    optimal_length : array_like
        l_opt [m].
    fibre : Fibre
        Supplies vmax_slow, vmax_fast_gain [l_opt/s] and fast_twitch [1].

    Returns
    -------
    numpy.ndarray
        v_max [m/s], the shape of ``optimal_length``.
    """
    return (fibre.vmax_slow + fibre.vmax_fast_gain * fibre.fast_twitch) * np.asarray(optimal_length)


def hill_constants(optimal_length, fibre, errata) -> HillConstants:
    """Hill constants per unit f_iso for fibres of optimal length ``optimal_length`` [m].

    The paper's constants [1]_ (Methods; docs/model.md, "Force-velocity") of the
    Hill-type force-velocity relation [2]_.

    Parameters
    ----------
    optimal_length : array_like
        l_opt [m].
    fibre : Fibre
        hill_a, hill_b, vmax_*, fast_twitch, eccentric_enhancement.
    errata : Errata
        ``eccentric_constant``: 'corrected' C = (A - 1) B or 'printed' C = (A - 1) b
        (docs/model.md, "Eccentric Hill constant C").

    Returns
    -------
    HillConstants
        a, A [1] and c, C [m/s] per unit f_iso; b, B [m/s]; each of the shape of
        ``optimal_length`` (a and A are scalars).

    References
    ----------
    .. [1] Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal
       lordosis optimizes the requirements for a stable erect posture. Theor Biol Med
       Model 9:13. doi:10.1186/1742-4682-9-13
    .. [2] Hill AV (1938). The heat of shortening and the dynamic constants of muscle.
       Proc R Soc Lond B 126:136-195.
    """
    a = fibre.hill_a
    b = fibre.hill_b * max_velocity(optimal_length, fibre)
    c = b * (1.0 + a)
    A = fibre.eccentric_enhancement
    B = (A - 1.0) * b**2 / c
    C = (A - 1.0) * (B if errata.eccentric_constant == "corrected" else b)
    return HillConstants(np.asarray(a), b, c, np.asarray(A), B, C)


def force_velocity(velocity, hill: HillConstants):
    """Hill force-velocity factor f_H / f_iso [1], both branches (paper, Methods).

    Concentric (v >= 0): f_H = c / (v + b) - a.
    Eccentric (v < 0):   f_H = C / (v - B) + A.

    Parameters
    ----------
    velocity : array_like
        Shortening velocity v [m/s].
    hill : HillConstants

    Returns
    -------
    numpy.ndarray
        f_H / f_iso [1], 1 at v = 0; the broadcast shape of ``velocity`` and the
        constants.
    """
    v = np.asarray(velocity, float)
    concentric = hill.c / (np.where(v >= 0, v, 0.0) + hill.b) - hill.a
    eccentric = hill.C / (np.where(v < 0, v, 0.0) - hill.B) + hill.A
    return np.where(v >= 0, concentric, eccentric)


def force_velocity_slope(velocity, hill: HillConstants):
    """Derivative d(f_H/f_iso)/dv [s/m], analytic; at v = 0 the concentric branch's.

    Concentric: -c / (v + b)^2; eccentric: -C / (v - B)^2. With erratum C both
    equal -(1 + a)/b at v = 0, so the damping is well defined.

    Parameters
    ----------
    velocity : array_like
        Shortening velocity v [m/s].
    hill : HillConstants

    Returns
    -------
    numpy.ndarray
        d(f_H/f_iso)/dv [s/m], negative on both branches; the broadcast shape of
        ``velocity`` and the constants.
    """
    v = np.asarray(velocity, float)
    concentric = -hill.c / (np.where(v >= 0, v, 0.0) + hill.b) ** 2
    eccentric = -hill.C / (np.where(v < 0, v, 0.0) - hill.B) ** 2
    return np.where(v >= 0, concentric, eccentric)
