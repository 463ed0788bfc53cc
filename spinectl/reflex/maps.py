"""The delayed, lagged reflex at every point and segment of a landscape, vectorised.

The activation time constant of ``reflex`` enters every column. Gains (:mod:`spinectl.reflex.gains`),
exact and Padé delay margins (:mod:`spinectl.reflex.delay`,
:mod:`spinectl.reflex.pade`) and stability at the model's delay, as arrays of any shape.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .delay import as_arrays, check_retarded, crossings_of, delay_margin_of, stable_at_delay_of, without_delay
from .gains import resolve_gains
from .inputs import validated
from .pade import pade_delay_margin_of


@dataclass(frozen=True)
class ReflexLandscape:
    """Reflex gains and delay margins over a grid of segments (any shape).

    Attributes
    ----------
    kp, kd : numpy.ndarray
        Reflex gains [N m/rad], [N m s/rad].
    delay_margin : numpy.ndarray
        Exact delay margin [s] (:func:`delay_margin`).
    delay_margin_status : numpy.ndarray of int
        Index into :data:`STATUS`.
    crossing_frequency : numpy.ndarray
        Frequency at which stability is lost [rad/s].
    delay_margin_pade : numpy.ndarray
        Padé estimate of the delay margin at the configured order [s].
    stable_at_delay : numpy.ndarray of bool
        Closed loop stable with the configured delay (exact).
    """

    kp: np.ndarray
    kd: np.ndarray
    delay_margin: np.ndarray
    delay_margin_status: np.ndarray
    crossing_frequency: np.ndarray
    delay_margin_pade: np.ndarray
    stable_at_delay: np.ndarray


@validated
def landscape(stiffness, damping, inertia, reflex, kp=None, kd=None, lag=None) -> ReflexLandscape:
    """Gains, exact and Padé delay margins and the stability verdict for arrays of segments.

    The vectorised entry point for sweeps over E x Lambda: pass S, D, theta of every
    segment at every grid point (already scaled by the activation), any shape.

    Parameters
    ----------
    stiffness, damping, inertia : array_like
        S [N m/rad], D [N m s/rad], theta [kg m^2]; NaN (infeasible) gives NaN and status 'undefined'.
    reflex : spinectl.model.params.Reflex
        Delay, activation time constant, Padé order and gains.
    kp, kd : float, optional
        Explicit gains overriding ``reflex``.
    lag : array_like, optional
        Activation time constant T_a [s] in place of ``reflex.activation_time_constant``, broadcast
        against S (e.g. one per row of a stack of models, as the atlas's draws); None: the reflex's.

    Returns
    -------
    ReflexLandscape
        Gains [N m/rad], [N m s/rad], exact and Padé delay margins [s], their status,
        the crossing frequency [rad/s] and the verdict at ``reflex.delay``, each of the
        broadcast shape of S, D and theta.
    """
    s, d, theta = as_arrays(stiffness, damping, inertia)
    lag = reflex.activation_time_constant if lag is None else lag
    kp_, kd_ = resolve_gains(s, d, theta, reflex, kp, kd)  # the rule takes no lag: it acts after the reflex
    check_retarded(theta, d, kd_, lag)
    s, d, theta, kp_, kd_, lag = as_arrays(s, d, theta, kp_, kd_, lag)
    free = without_delay(s, d, theta, kp_, kd_, lag)  # the delay-free loop and the crossings, once for all three
    cr = crossings_of(s, d, theta, kp_, kd_, lag, free)
    exact = delay_margin_of(s, d, theta, kp_, kd_, lag, free, cr)
    pade = pade_delay_margin_of(s, d, theta, kp_, kd_, reflex.pade_order, lag, free, cr)
    tau = np.broadcast_to(np.asarray(reflex.delay, float), s.shape)
    return ReflexLandscape(
        kp=kp_,
        kd=kd_,
        delay_margin=exact.margin,
        delay_margin_status=exact.status,
        crossing_frequency=exact.frequency,
        delay_margin_pade=pade.margin,
        stable_at_delay=stable_at_delay_of(s, d, theta, kp_, kd_, tau, lag, free, cr),
    )
