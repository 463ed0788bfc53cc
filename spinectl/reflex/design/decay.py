"""A least decay rate as a design requirement: every characteristic root at the delay has Re s <= -sigma.

The chain under the delayed, lagged reflex has the characteristic equation det(P(s) + Q(s) e^{-s tau}) = 0 with
P(s) = (T_a s + 1)(M s^2 - D s - K) and Q(s) = K_p + K_d s (:mod:`spinectl.reflex.mimo`). Its roots with
Re s < -sigma are those of the same equation in z = s + sigma with Re z < 0, and that equation has the same
form::

    T_a s + 1          = c (T_a' z + 1),                  c = 1 - sigma T_a,  T_a' = T_a / c
    M s^2 - D s - K    = M z^2 - D' z - K',               D' = D + 2 sigma M,  K' = K - sigma^2 M - sigma D
    Q(s) e^{-s tau}    = c (K_p' + K_d' z) e^{-z tau},    K_p' = (K_p - sigma K_d) e^{sigma tau} / c,
                                                          K_d' = K_d e^{sigma tau} / c

(:func:`shifted_loop`). So the requirement "every root at tau has Re s < -sigma" is "the shifted loop is
stable at tau", and the design's own certificate (the exact delay margin with no critical delay crossed below
tau, and the rightmost root) decides it on the shifted loop unchanged: the decay rate is certified as the delay
is. The shift needs c > 0, sigma < 1 / T_a (:func:`decay_bound`).
"""

from __future__ import annotations

import numpy as np

from ...errors import ParameterError

MAX_SHIFT_EXPONENT = 30.0
"""The largest sigma tau [1]: the shifted gains are e^{sigma tau} times the reflex's (e^30, about 1e13, is
already far beyond any gain the chain's numbers resolve)."""


def decay_bound(delay: float, lag: float) -> float:
    """The largest decay rate the shift certifies [1/s]: below 1 / T_a, and sigma tau <= :data:`MAX_SHIFT_EXPONENT`.

    Parameters
    ----------
    delay, lag : float
        tau [s] and T_a [s].

    Returns
    -------
    float
        [1/s]; inf with neither a lag nor a delay.
    """
    bounds = [np.inf]
    if lag > 0:
        bounds.append(1.0 / lag)
    if delay > 0:
        bounds.append(MAX_SHIFT_EXPONENT / delay)
    return float(min(bounds))


def checked_decay_rate(option: str, sigma: float, delay: float, lag: float) -> float:
    """``sigma`` [1/s] in [0, :func:`decay_bound`) (0 at most where the bound is 0), or one line naming the bound.

    Parameters
    ----------
    option : str
        The option's name, e.g. ``"--decay-rate"``.
    sigma : float
        The asked decay rate [1/s].
    delay, lag : float
        tau [s] and T_a [s].

    Returns
    -------
    float

    Raises
    ------
    ParameterError
        sigma negative, not finite, or at or beyond the bound.
    """
    from ..._validate import non_negative

    sigma = non_negative(option, sigma)
    high = decay_bound(delay, lag)
    if not sigma < high:
        why = f"1/T_a = {1.0 / lag:.4g} 1/s, the activation lag's own rate" if lag > 0 and high == 1.0 / lag else (
            f"{MAX_SHIFT_EXPONENT:g}/tau = {high:.4g} 1/s"
        )  # fmt: skip
        raise ParameterError(option, f"must be a decay rate in [0, {high:.4g}) 1/s, below {why} (got {sigma:g})")
    return sigma


def shifted_loop(mass, stiffness, damping, kp, kd, lag: float, delay: float, sigma: float):
    """The loop whose characteristic roots are the chain's moved right by sigma (see the module).

    Parameters
    ----------
    mass, stiffness, damping : array_like, shape (n, n)
        M [kg m^2], K [N m/rad], D [N m s/rad] (M q'' = K q + D q' + u).
    kp, kd : array_like, shape (n,)
        Diagonal reflex gains [N m/rad], [N m s/rad].
    lag, delay : float
        T_a [s] and tau [s].
    sigma : float
        The decay rate [1/s], 0 <= sigma < :func:`decay_bound`.

    Returns
    -------
    stiffness, damping : numpy.ndarray, shape (n, n)
        K' [N m/rad], D' [N m s/rad].
    kp, kd : numpy.ndarray, shape (n,)
        K_p', K_d'.
    lag : float
        T_a' [s].
    """
    m, k, d = (np.asarray(x, float) for x in (mass, stiffness, damping))
    kp, kd = np.asarray(kp, float), np.asarray(kd, float)
    gain = np.exp(sigma * delay) / (1.0 - sigma * lag)
    shifted_gains = (kp - sigma * kd) * gain, kd * gain
    return k - sigma**2 * m - sigma * d, d + 2.0 * sigma * m, *shifted_gains, shifted_lag(lag, sigma)


def shifted_lag(lag: float, sigma: float) -> float:
    """T_a' = T_a / (1 - sigma T_a) [s], the shifted loop's lag (see the module).

    Parameters
    ----------
    lag : float
        T_a [s].
    sigma : float
        The decay rate [1/s], below 1 / T_a.

    Returns
    -------
    float
    """
    return lag / (1.0 - sigma * lag)
