"""Root counting at a given delay: roots in the right half-plane, stability, the phase margin.

The delay-free loop's roots in Re s > 0 plus the net crossings (+ destabilising,
- stabilising) at the delays below the given one (Cooke and van den Driessche 1986 [1]_).

References
----------
.. [1] Cooke KL, van den Driessche P (1986). On zeroes of some transcendental
   equations. Funkcialaj Ekvacioj 29:77-90.
"""

from __future__ import annotations

import numpy as np

from ..inputs import validated
from .free import WithoutDelay, as_arrays, check_retarded, without_delay
from .frequencies import Crossings, _axis_slot, crossings, crossings_of
from .margin import pure_gain, undefined_inputs


@validated(zero_inertia=True)
def right_half_plane_roots(stiffness, damping, inertia, kp, kd, delay, lag=0.0):
    """Number of closed-loop roots with Re s > 0 at the delay ``delay`` [s], exactly.

    N(tau) = N(0) + 2 sum over crossings of direction * #{k >= 0: phi/w + 2 pi k/w < tau}:
    every crossing moves a conjugate pair (retarded type: no root comes from
    infinity). N(0) counts the roots of the delay-free loop R(s) in Re s > 0. A pair on
    the axis at tau = 0 counts 2 for tau > 0 if it leaves to the right, else 0
    (:func:`without_delay`); without a reflex the roots do not move. The pure gain
    (theta = D = T_a = kd = 0) has infinitely many (inf) for tau > 0 where abs(kp) > abs(S).

    Parameters
    ----------
    stiffness, damping, inertia : array_like
        S [N m/rad], D [N m s/rad], theta [kg m^2].
    kp, kd : array_like
        Reflex gains [N m/rad], [N m s/rad].
    delay : array_like
        tau [s].
    lag : array_like, optional
        Activation time constant T_a [s].

    Returns
    -------
    numpy.ndarray
        The count, as floats (NaN where an input is NaN).

    Raises
    ------
    ParameterError
        Naming ``kd``, for a loop of neutral type (:func:`check_retarded`).
    """
    check_retarded(inertia, damping, kd, lag)
    s, d, theta, kp, kd, tau, lag = as_arrays(stiffness, damping, inertia, kp, kd, delay, lag)
    free = without_delay(s, d, theta, kp, kd, lag)
    return _right_half_plane_roots(s, d, theta, kp, kd, tau, lag, free, crossings_of(s, d, theta, kp, kd, lag, free))


def _right_half_plane_roots(s, d, theta, kp, kd, tau, lag, free: WithoutDelay, cr: Crossings):
    with np.errstate(invalid="ignore"):
        passed = np.floor((tau[..., None] - cr.first_delay) * cr.frequency / (2.0 * np.pi)) + 1.0
    passed = np.where(np.isnan(passed), 0.0, np.maximum(passed, 0.0))
    direction = np.nan_to_num(cr.direction)
    count = free.unstable + 2.0 * np.sum(direction * passed, axis=-1)
    # the axis pair's crossing at tau = 0 counts by where it goes, not by sign F'
    at_zero = _axis_slot(cr.frequency, free.axis_frequency)
    count -= 2.0 * np.sum(np.where(at_zero, direction, 0.0), axis=-1)
    count += 2.0 * np.where((tau > 0) & ~np.isnan(free.axis_frequency), np.maximum(free.departure, 0.0), 0.0)
    count = np.where((kp == 0) & (kd == 0), free.unstable, count)  # no reflex: Delta = P for every delay
    infinite = pure_gain(theta, d, kd, lag) & (tau > 0) & (np.abs(kp) > np.abs(s))
    count = np.where(infinite, np.inf, count)
    return np.where(undefined_inputs(s, d, theta, kp, kd, tau, lag), np.nan, count)


@validated(zero_inertia=True)
def stable_at_delay(stiffness, damping, inertia, kp, kd, delay, lag=0.0):
    """True where the closed loop with the true delay [s] has every root in Re s < 0.

    Exact for every delay, also beyond the delay margin (stability switches). A root
    fixed at s = 0 (kp = S), a pair on the axis at tau = 0, and a pair that stays on the
    axis for every delay (no reflex on an undamped segment, S < 0 and D = 0) count as unstable;
    so does the pure gain with abs(kp) = abs(S) for tau > 0 (roots on the axis).

    Parameters
    ----------
    stiffness, damping, inertia : array_like
        S [N m/rad], D [N m s/rad], theta [kg m^2].
    kp, kd : array_like
        Reflex gains [N m/rad], [N m s/rad].
    delay : array_like
        tau [s].
    lag : array_like, optional
        Activation time constant T_a [s].

    Returns
    -------
    numpy.ndarray of bool
        True where the closed loop with delay tau is asymptotically stable; the broadcast
        shape of the inputs (False where an input is NaN).

    Raises
    ------
    ParameterError
        Naming ``kd``, for a loop of neutral type (:func:`check_retarded`).
    """
    check_retarded(inertia, damping, kd, lag)
    s, d, theta, kp, kd, tau, lag = as_arrays(stiffness, damping, inertia, kp, kd, delay, lag)
    free = without_delay(s, d, theta, kp, kd, lag)
    return stable_at_delay_of(s, d, theta, kp, kd, tau, lag, free, crossings_of(s, d, theta, kp, kd, lag, free))


def stable_at_delay_of(s, d, theta, kp, kd, tau, lag, free: WithoutDelay, cr: Crossings):
    """:func:`stable_at_delay` from the delay-free loop and the crossings (:func:`crossings_of`).

    Parameters
    ----------
    s, d, theta, kp, kd, tau, lag : numpy.ndarray
        As :func:`stable_at_delay`, float arrays of one shape, checked (:func:`check_retarded`).
    free : WithoutDelay
        Their :func:`without_delay`.
    cr : Crossings
        Their :func:`crossings_of`.

    Returns
    -------
    numpy.ndarray of bool
        As :func:`stable_at_delay`.
    """
    count = _right_half_plane_roots(s, d, theta, kp, kd, tau, lag, free, cr)
    axis = ~np.isnan(free.axis_frequency) & ((tau == 0) | (free.departure == 0))
    marginal_gain = pure_gain(theta, d, kd, lag) & (tau > 0) & (np.abs(kp) == np.abs(s))
    return (count == 0) & ~free.zero_root & ~axis & ~marginal_gain


@validated(zero_inertia=True)
def phase_margin(stiffness, damping, inertia, kp, kd, delay, lag=0.0):
    """Exact phase margin [rad] and gain crossover [rad/s] of the loop with the true delay.

    At the crossover w_c that limits the delay margin (smallest phi/w),
    PM = 180 deg + arg L(j w_c) = phi - w_c tau, wrapped to [-pi, pi) as python-control does;
    so PM / w_c is the delay that may still be added when 0 < PM < pi.
    inf and NaN (no crossover) like python-control's ``stability_margins``.

    Parameters
    ----------
    stiffness, damping, inertia : array_like
        S [N m/rad], D [N m s/rad], theta [kg m^2].
    kp, kd : array_like
        Reflex gains [N m/rad], [N m s/rad].
    delay : array_like
        tau [s].
    lag : array_like, optional
        Activation time constant T_a [s]; its phase is part of L.

    Returns
    -------
    phase_margin, crossover : numpy.ndarray
        PM [rad] and w_c [rad/s], each of the broadcast shape of the inputs.
    """
    cr = crossings(stiffness, damping, inertia, kp, kd, lag)
    tau = np.asarray(delay, float)
    delays = np.where(np.isnan(cr.first_delay), np.inf, cr.first_delay)
    slot = np.argmin(delays, axis=-1)[..., None]
    w = np.take_along_axis(cr.frequency, slot, axis=-1)[..., 0]
    phi = np.take_along_axis(cr.phase, slot, axis=-1)[..., 0]
    pm = np.mod(phi - w * tau + np.pi, 2.0 * np.pi) - np.pi
    return np.where(np.isnan(w), np.inf, pm), w


# --- critical gains ------------------------------------------------------------------------
