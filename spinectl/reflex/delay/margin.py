"""The segment's exact delay margin from the quasi-polynomial P + Q exp(-s tau) with the activation lag.

The first destabilising crossing delay tau = (phi + 2 pi k) / w over the crossing
frequencies, with its status code (:data:`STATUS`); the pure gain has a closed form
(docs/reflex.md, "Crossing frequencies and the exact delay margin").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..inputs import validated
from .free import WithoutDelay, as_arrays, check_retarded, without_delay
from .frequencies import Crossings, crossings_of

STATUS = ("finite", "delay_independent", "unstable_without_delay", "undefined")
"""Meaning of :attr:`DelayMargin.status` codes 0..3.

- ``finite``: stable without delay; it loses stability at the finite delay margin.
- ``delay_independent``: stable without delay and no root can reach the imaginary
  axis (abs(Q(jw)) != abs(P(jw)) for every w > 0): stable for every delay, margin = inf.
  This is where self-stability makes the delay irrelevant.
- ``unstable_without_delay``: not asymptotically stable even at tau = 0 (a root in
  Re s >= 0 of P + Q): margin = 0, the largest tau_m with stability on all of [0, tau_m) being none.
- ``undefined``: an input is NaN (e.g. an infeasible optimum): margin = NaN.
"""
FINITE, DELAY_INDEPENDENT, UNSTABLE_WITHOUT_DELAY, UNDEFINED = range(len(STATUS))


@dataclass(frozen=True)
class DelayMargin:
    """Delay margin of the reflex loop at many points.

    Attributes
    ----------
    margin : numpy.ndarray
        The largest tau_m with the closed loop stable for every delay in [0, tau_m) [s];
        inf (delay-independent), 0 (unstable without delay) or NaN (undefined), see :data:`STATUS`.
    frequency : numpy.ndarray
        Frequency at which the loop loses stability at tau_m [rad/s]; NaN if none.
    status : numpy.ndarray of int
        Index into :data:`STATUS`.
    """

    margin: np.ndarray
    frequency: np.ndarray
    status: np.ndarray

    @property
    def status_names(self) -> np.ndarray:
        """:attr:`status` as strings."""
        return np.asarray(STATUS, dtype=object)[self.status]


def margin_from_delays(first_delays, frequency, stable0, undefined) -> DelayMargin:
    """Smallest critical delay over the crossings, with the status rules of :data:`STATUS`.

    Parameters
    ----------
    first_delays : array_like, shape (..., n_crossings)
        The first destabilising delay of each crossing [s]; NaN where there is none.
    frequency : array_like, shape (..., n_crossings)
        The crossing frequencies [rad/s].
    stable0 : array_like of bool, shape (...)
        Stable without delay.
    undefined : array_like of bool, shape (...)
        An input is NaN.

    Returns
    -------
    DelayMargin
        The margin [s], the frequency at it [rad/s] and the status code of each point,
        each of shape (...).
    """
    delays = np.where(np.isnan(first_delays), np.inf, first_delays)
    slot = np.argmin(delays, axis=-1)
    smallest = np.take_along_axis(delays, slot[..., None], axis=-1)[..., 0]
    at = np.take_along_axis(frequency, slot[..., None], axis=-1)[..., 0]
    status = np.where(np.isfinite(smallest), FINITE, DELAY_INDEPENDENT)
    status = np.where(stable0, status, UNSTABLE_WITHOUT_DELAY)
    status = np.where(undefined, UNDEFINED, status)
    margin = np.choose(status, [smallest, np.inf, 0.0, np.nan])
    freq = np.where(status == FINITE, at, np.nan)
    return DelayMargin(margin=margin, frequency=freq, status=status.astype(np.int8))


def delay_text(seconds: float, digits: int = 4) -> str:
    """A delay as text with its unit: ms below 1 s, s from 1 s; inf 'unbounded (delay-independent)', NaN 'none'.

    The one way every report of the reflex prints a delay or a delay margin.

    Parameters
    ----------
    seconds : float
        The delay [s].
    digits : int, optional
        Significant digits.

    Returns
    -------
    str
        E.g. '120 ms', '329.8 s'.
    """
    if np.isnan(seconds):
        return "none"
    if np.isinf(seconds):
        return "unbounded (delay-independent)"
    return f"{seconds:.{digits}g} s" if seconds >= 1.0 else f"{seconds * 1000:.{digits}g} ms"


def undefined_inputs(*values):
    """Where any input is NaN, broadcast: the points whose margin is undefined.

    Parameters
    ----------
    *values : array_like
        Broadcastable arrays.

    Returns
    -------
    numpy.ndarray of bool
        True where any input is NaN; the broadcast shape of the inputs.
    """
    return np.any(np.isnan(np.stack(as_arrays(*values))), axis=0)


def pure_gain(inertia, damping, kd, lag):
    """Where the loop is a pure gain with delay, 1 + K exp(-s tau), K = -kp/S.

    P = -S is then a constant (theta = D = T_a = 0) and so is Q = kp (kd = 0); its roots lie at
    Re s = ln abs(K) / tau for every tau > 0 (docs/reflex.md, "Boundary cases").

    Parameters
    ----------
    inertia, damping, kd, lag : array_like
        theta [kg m^2], D [N m s/rad], kd [N m s/rad], T_a [s].

    Returns
    -------
    numpy.ndarray of bool
        The broadcast shape of the inputs.
    """
    theta, d, kd, lag = as_arrays(inertia, damping, kd, lag)
    return (theta == 0) & (d == 0) & (kd == 0) & (lag == 0)


@validated(zero_inertia=True)
def delay_margin(stiffness, damping, inertia, kp, kd, lag=0.0) -> DelayMargin:
    """Exact delay margin from the quasi-polynomial (docs/reflex.md, "Crossing frequencies and the exact delay margin").

    If the loop is stable at tau = 0 the first root to reach the imaginary axis as
    tau grows does so at the smallest critical delay phi/w over the crossings;
    without crossings the loop is stable for every delay (margin inf). The pure gain
    (theta = D = T_a = kd = 0), 1 + K exp(-s tau) with K = -kp/S, has its roots at
    Re s = ln abs(K) / tau: margin inf if abs(K) < 1, else 0 (status ``finite``: stable at
    tau = 0, unstable for every tau > 0).

    Parameters
    ----------
    stiffness, damping, inertia, kp, kd : array_like
        S [N m/rad], D [N m s/rad], theta [kg m^2], kp [N m/rad], kd [N m s/rad].
    lag : array_like, optional
        Activation time constant T_a [s] of the force generation after the delay; 0 is the pure delay.

    Returns
    -------
    DelayMargin
        tau_m [s] (inf, 0 or NaN by :data:`STATUS`), the frequency at which stability
        is lost [rad/s] and the status code, each of the broadcast shape of the inputs.

    Raises
    ------
    ParameterError
        Naming ``kd``, for a loop of neutral type (:func:`check_retarded`).

    Notes
    -----
    The crossings and their directions are those of :func:`crossings`, after Cooke
    and Grossman [1]_ and Cooke and van den Driessche [2]_.

    References
    ----------
    .. [1] Cooke KL, Grossman Z (1982). Discrete delay, distributed delay and stability
       switches. J Math Anal Appl 86:592-627.
    .. [2] Cooke KL, van den Driessche P (1986). On zeroes of some transcendental
       equations. Funkcialaj Ekvacioj 29:77-90.

    Examples
    --------
    A segment 100 N m/rad short of self-stability under kp = 150 N m/rad, kd = 20 N m s/rad:

    >>> from spinectl.reflex import delay_margin
    >>> found = delay_margin(stiffness=100.0, damping=-5.0, inertia=1.0, kp=150.0, kd=20.0)
    >>> round(float(found.margin) * 1e3, 1)  # [ms]
    88.3
    """
    check_retarded(inertia, damping, kd, lag)
    s, d, theta, kp, kd, lag = as_arrays(stiffness, damping, inertia, kp, kd, lag)
    free = without_delay(s, d, theta, kp, kd, lag)
    return delay_margin_of(s, d, theta, kp, kd, lag, free, crossings_of(s, d, theta, kp, kd, lag, free))


def delay_margin_of(s, d, theta, kp, kd, lag, free: WithoutDelay, cr: Crossings) -> DelayMargin:
    """:func:`delay_margin` from the delay-free loop and the crossings (:func:`crossings_of`).

    Parameters
    ----------
    s, d, theta, kp, kd, lag : numpy.ndarray
        As :func:`delay_margin`, float arrays of one shape, checked (:func:`check_retarded`).
    free : WithoutDelay
        Their :func:`without_delay`.
    cr : Crossings
        Their :func:`crossings_of`.

    Returns
    -------
    DelayMargin
        As :func:`delay_margin`.
    """
    undefined = undefined_inputs(s, d, theta, kp, kd, lag)
    result = margin_from_delays(cr.first_delay, cr.frequency, free.stable, undefined)
    gain = pure_gain(theta, d, kd, lag) & ~undefined & free.stable
    if not np.any(gain):
        return result
    small = np.abs(kp) < np.abs(s)
    return DelayMargin(
        margin=np.where(gain, np.where(small, np.inf, 0.0), result.margin),
        frequency=np.where(gain, np.nan, result.frequency),
        status=np.where(gain, np.where(small, DELAY_INDEPENDENT, FINITE), result.status).astype(np.int8),
    )
