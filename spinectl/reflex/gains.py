"""Reflex gains: the default rule from the segment's stiffness and inertia, or gains given by the user.

The rule and its reasons are in docs/reflex.md, "The default reflex, and the activation level". The
choice between the rule and the configured gains, then the per-option overrides, is made here once
(:func:`resolve_gains` for segments, :func:`resolve_chain_gains` for the chain's joints) and only here.
"""

from __future__ import annotations

import numpy as np

from .delay import as_arrays
from .inputs import validated


@validated
def default_gains(stiffness, damping, inertia, gain_factor, damping_ratio):
    """The default reflex rule (docs/reflex.md, "The default reflex, and the activation level").

    kp = gain_factor * max(S, 0): the stiffness deficit times a factor > 1, so that the reflexive
    stiffness (gain_factor - 1) S replaces the missing one. kd = max(0, 2 zeta sqrt(theta (kp - S)) + D):
    the delay-free closed loop gets the damping ratio zeta, the muscles' own damping -D >= 0 counted
    first. The rule takes no T_a: the activation lag acts on the reflex's torque after it, as in trunk
    reflexes identified so [3]_. Why 1.5 and zeta = 1 (against Stépán's bound sqrt(2 theta / S) [1]_ [2]_):
    docs/reflex.md, "The default reflex, and the activation level".

    Parameters
    ----------
    stiffness, damping, inertia : array_like
        S [N m/rad], D [N m s/rad], theta [kg m^2].
    gain_factor : float
        Factor on the stiffness deficit [1], > 1.
    damping_ratio : float
        zeta [1], > 0.

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
    s, d, theta = as_arrays(stiffness, damping, inertia)
    kp = gain_factor * np.maximum(s, 0.0)
    return kp, _derivative_gain(kp, s, d, theta, damping_ratio)


KD_RULE = "kd = max(0, 2 zeta sqrt(theta (kp - S)) + D)"
"""The rule's derivative gain in words (:func:`default_gains`), as the outputs that print a rule's kd say it."""


def _derivative_gain(kp, stiffness, damping, inertia, damping_ratio):
    """kd = max(0, 2 zeta sqrt(theta (kp - S)) + D): the rule's damping (see :func:`default_gains`)."""
    # theta s^2 + (kd - D) s + (kp - S) has the damping ratio zeta when kd - D = 2 zeta sqrt(theta (kp - S));
    # D < 0 is the muscles' own damping, counted first, so kd may be 0 where they damp enough
    net = np.maximum(kp - stiffness, 0.0)
    return np.maximum(2.0 * damping_ratio * np.sqrt(inertia * net) + damping, 0.0)


def chain_gains(mass, stiffness, damping, local_stiffness, gain_factor, damping_ratio):
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

    Returns
    -------
    kp, kd : numpy.ndarray, shape (n,)
        [N m/rad], [N m s/rad].
    """
    diagonal = (np.diagonal(np.asarray(x, float)) for x in (mass, stiffness, damping))
    theta, s, d = diagonal
    # the chain's deficit at joint j is k_j (what the whole chain lacks there), not max(S_j, 0): the segment
    # alone can be stable where the chain is not; the damping per joint from the diagonal, as for a segment
    kp = gain_factor * np.maximum(np.asarray(local_stiffness, float), 0.0)
    return kp, _derivative_gain(kp, s, d, theta, damping_ratio)


def _configured(reflex, rule, shape, kp=None, kd=None):
    """The rule's gains (``rule()``, called only for ``gains = "rule"``) or the configured ones, then the overrides.

    Parameters
    ----------
    reflex : spinectl.model.params.Reflex
        ``gains`` ('rule' or 'explicit'), ``kp`` and ``kd``.
    rule : callable
        () -> (kp, kd) of ``shape``: the rule's gains [N m/rad], [N m s/rad].
    shape : tuple of int
        The gains' shape.
    kp, kd : float, optional
        One gain for every element [N m/rad], [N m s/rad], replacing the rule's or configured one.

    Returns
    -------
    kp, kd : numpy.ndarray
        [N m/rad], [N m s/rad], of ``shape``.
    """
    kp0, kd0 = rule() if reflex.gains == "rule" else (np.full(shape, reflex.kp), np.full(shape, reflex.kd))
    kp_out = kp0 if kp is None else np.full(shape, float(kp))
    kd_out = kd0 if kd is None else np.full(shape, float(kd))
    return np.asarray(kp_out, float), np.asarray(kd_out, float)


def resolve_chain_gains(reflex, mass, stiffness, damping, local_stiffness, kp=None, kd=None, scale=1.0):
    """The chain's diagonal gains from the reflex settings, each optionally overridden.

    Parameters
    ----------
    reflex : spinectl.model.params.Reflex
        ``gains = "rule"`` uses :func:`chain_gains` (with its ``gain_factor`` and ``damping_ratio``),
        ``"explicit"`` its ``kp`` and ``kd`` at every joint.
    mass, stiffness, damping : array_like, shape (n, n)
        M [kg m^2], K [N m/rad], D [N m s/rad].
    local_stiffness : array_like, shape (n,)
        k [N m/rad], the least local stiffness (the deficit the rule compensates).
    kp, kd : float, optional
        One gain for every joint [N m/rad], [N m s/rad], replacing the rule's or configured one.
    scale : float, optional
        A factor [1] on the rule's gains alone (the design's hand-over to the local muscles,
        :func:`spinectl.reflex.design.chain.chain_loop_at`); 1 by default.

    Returns
    -------
    kp, kd : numpy.ndarray, shape (n,)
        [N m/rad], [N m s/rad].
    """

    def rule():
        kp0, kd0 = chain_gains(mass, stiffness, damping, local_stiffness, reflex.gain_factor, reflex.damping_ratio)
        return scale * kp0, scale * kd0

    return _configured(reflex, rule, (len(local_stiffness),), kp, kd)


@validated
def resolve_gains(stiffness, damping, inertia, reflex, kp=None, kd=None):
    """Gains per segment from the reflex settings, each optionally overridden.

    Parameters
    ----------
    stiffness, damping, inertia : array_like
        S [N m/rad], D [N m s/rad], theta [kg m^2].
    reflex : spinectl.model.params.Reflex
        ``gains = "rule"`` uses :func:`default_gains` (with its ``gain_factor`` and ``damping_ratio``),
        ``"explicit"`` its ``kp`` and ``kd``.
    kp, kd : float, optional
        Explicit gains [N m/rad], [N m s/rad] that replace the configured ones.

    Returns
    -------
    kp, kd : numpy.ndarray
        [N m/rad], [N m s/rad], each of the broadcast shape of S, D and theta; NaN where
        one of them is NaN.
    """
    s, d, theta = as_arrays(stiffness, damping, inertia)
    rule = lambda: default_gains(s, d, theta, reflex.gain_factor, reflex.damping_ratio)  # noqa: E731
    kp_out, kd_out = _configured(reflex, rule, s.shape, kp, kd)
    nan = np.isnan(s) | np.isnan(d) | np.isnan(theta)
    return np.where(nan, np.nan, kp_out), np.where(nan, np.nan, kd_out)
