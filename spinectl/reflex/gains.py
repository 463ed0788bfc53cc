"""Reflex gains: the default rule from the segment's stiffness and inertia, or gains given by the user.

The rule and its reasons are in docs/reflex.md, "The default reflex, and the activation level".
"""

from __future__ import annotations

import numpy as np

from .delay import as_arrays
from .inputs import validated


@validated
def default_gains(stiffness, damping, inertia, gain_factor, damping_ratio, lag=0.0):
    """The default reflex rule (docs/reflex.md, "The default reflex, and the activation level").

    kp = gain_factor * max(S, 0): the stiffness deficit below self-stability
    times a factor > 1, so that the reflexive stiffness kp - S = (gain_factor - 1) S
    replaces the missing one; a self-stable segment (S < 0) gets no proportional
    reflex. kd = max(0, 2 zeta sqrt(theta (kp - S)) + D): the delay-free closed loop
    theta s^2 + (kd - D) s + (kp - S) gets the damping ratio zeta, counting the
    muscles' own damping -D >= 0 first (kd = 0 when they already damp enough).
    The rule is the lag-free segment's: the activation lag 1/(T_a s + 1) acts on the reflex's
    torque after it, as the muscles' force generation does, and the gains do not undo it. (Before, the
    rule added kp T_a to kd; where the damping part is 0, at the default operating point,
    that made the reflex kp (T_a s + 1), which cancels the lag exactly, so that the margins did
    not depend on T_a.) Trunk reflexes are identified so: delayed gains on the trunk's angle and
    angular velocity, in series with the muscles' activation dynamics (Moorhouse and Granata
    2007 [3]_; docs/reflex.md, "The default reflex, and the activation level").
    The factor 1.5 and zeta = 1 were chosen against Stépán's bound sqrt(2 theta / S),
    the longest delay any delayed PD can balance the reflex-only segment with [1]_ [2]_
    (docs/reflex.md).

    Parameters
    ----------
    stiffness, damping, inertia : array_like
        S [N m/rad], D [N m s/rad], theta [kg m^2].
    gain_factor : float
        Factor on the stiffness deficit [1], > 1.
    damping_ratio : float
        zeta [1], > 0.
    lag : array_like, optional
        Activation time constant T_a [s]; the rule does not use it (the lag acts after the reflex),
        kept for the callers that pass it.

    Returns
    -------
    kp, kd : numpy.ndarray
        [N m/rad], [N m s/rad]; NaN where an input is NaN.

    References
    ----------
    .. [1] Stépán G (1989). Retarded Dynamical Systems: Stability and Characteristic
       Functions. Longman Scientific & Technical, Harlow.
    .. [2] Stépán G, Kollár L (2000). Balancing with reflex delay. Math Comput Model
       31:199-205.
    .. [3] Moorhouse KM, Granata KP (2007). Role of reflex dynamics in spinal stability:
       intrinsic muscle stiffness alone is insufficient for stability. J Biomech 40:1058-1065.
       doi:10.1016/j.jbiomech.2006.04.018.
    """
    s, d, theta, lag = as_arrays(stiffness, damping, inertia, lag)
    kp = gain_factor * np.maximum(s, 0.0)
    return kp, _derivative_gain(kp, s, d, theta, damping_ratio, lag)


def _derivative_gain(kp, stiffness, damping, inertia, damping_ratio, lag):
    """kd = max(0, 2 zeta sqrt(theta (kp - S)) + D): the rule's damping (see :func:`default_gains`; T_a unused)."""
    net = np.maximum(kp - stiffness, 0.0)
    kd = np.maximum(2.0 * damping_ratio * np.sqrt(inertia * net) + damping, 0.0)
    return kd + 0.0 * np.asarray(lag, float)  # the broadcast shape of the inputs, lag included


def chain_gains(mass, stiffness, damping, local_stiffness, gain_factor, damping_ratio, lag=0.0):
    """The default rule on the chain: diagonal gains from the chain's stiffness deficit (docs/chain.md).

    A joint's deficit is the least local stiffness k_j of
    :func:`spinectl.optimise.coupled.local.least_local_stiffness` (diag(k) - K >= mu I): what the
    joint lacks for the whole chain to be stable, where the segment's deficit max(S, 0) is
    what it lacks alone. kp_j = gain_factor k_j, and kd_j is the segment rule's
    (:func:`default_gains`) with theta = M[j, j], S = K[j, j], D = D[j, j]. Without delay,
    K_p - K >= mu I + (gain_factor - 1) diag(k) is positive definite; with K_d - D positive
    definite too the delay-free chain is stable (a mechanical system with positive definite
    stiffness and damping; Lyapunov function the energy).

    Parameters
    ----------
    mass, stiffness, damping : array_like, shape (n, n)
        M [kg m^2], K [N m/rad], D [N m s/rad].
    local_stiffness : array_like, shape (n,)
        k [N m/rad], the least local stiffness.
    gain_factor, damping_ratio : float
        As in :func:`default_gains` [1].
    lag : float, optional
        Activation time constant T_a [s]; unused, as in :func:`default_gains`.

    Returns
    -------
    kp, kd : numpy.ndarray, shape (n,)
        [N m/rad], [N m s/rad].
    """
    diagonal = (np.diagonal(np.asarray(x, float)) for x in (mass, stiffness, damping))
    theta, s, d = diagonal
    kp = gain_factor * np.maximum(np.asarray(local_stiffness, float), 0.0)
    return kp, _derivative_gain(kp, s, d, theta, damping_ratio, lag)


@validated
def resolve_gains(stiffness, damping, inertia, reflex, kp=None, kd=None, lag=None):
    """Gains per segment from the reflex settings, each optionally overridden.

    Parameters
    ----------
    stiffness, damping, inertia : array_like
        S [N m/rad], D [N m s/rad], theta [kg m^2].
    reflex : spinectl.model.params.Reflex
        ``gains = "rule"`` uses :func:`default_gains` (with its ``activation_time_constant``),
        ``"explicit"`` its ``kp`` and ``kd``.
    kp, kd : float, optional
        Explicit gains [N m/rad], [N m s/rad] that replace the configured ones.
    lag : array_like, optional
        Activation time constant T_a [s] in place of ``reflex.activation_time_constant``
        (:func:`default_gains`'s ``lag``); None: the reflex's.

    Returns
    -------
    kp, kd : numpy.ndarray
        [N m/rad], [N m s/rad], each of the broadcast shape of S, D and theta; NaN where
        one of them is NaN.
    """
    s, d, theta = as_arrays(stiffness, damping, inertia)
    lag = reflex.activation_time_constant if lag is None else lag
    if reflex.gains == "rule":
        kp0, kd0 = default_gains(s, d, theta, reflex.gain_factor, reflex.damping_ratio, lag)
    else:
        kp0, kd0 = np.full(s.shape, reflex.kp), np.full(s.shape, reflex.kd)
    kp_out = kp0 if kp is None else np.full(s.shape, float(kp))
    kd_out = kd0 if kd is None else np.full(s.shape, float(kd))
    nan = np.isnan(s) | np.isnan(d) | np.isnan(theta)
    return np.where(nan, np.nan, kp_out), np.where(nan, np.nan, kd_out)
