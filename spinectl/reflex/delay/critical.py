"""Critical gains: the proportional gains kp at which the delayed, lagged loop is marginally stable.

Roots in kp bracketed on a grid per lobe and bisected (:data:`BISECTIONS` halvings),
each checked by :func:`~spinectl.reflex.delay.counting.stable_at_delay`.
"""

from __future__ import annotations

import numpy as np

from ..inputs import validated
from .counting import stable_at_delay
from .free import as_arrays, check_retarded

BISECTIONS = 60
"""Halvings of a bracket in the vectorised root finders: 2^-60 of the bracket, below float resolution."""


def _bracketed_roots(func, grid):
    """Every sign change of ``func`` between neighbours of ``grid`` (last axis), bisected.

    Returns an array of shape (..., len(grid) - 1): the root in each bracket, NaN where none.
    """
    values = func(grid)
    lo, hi = grid[..., :-1], grid[..., 1:]
    f_lo = values[..., :-1]
    has = np.sign(f_lo) * np.sign(values[..., 1:]) < 0
    lo, hi = np.broadcast_to(lo, has.shape), np.broadcast_to(hi, has.shape)
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        same = np.sign(func(mid)) == np.sign(f_lo)
        lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
    return np.where(has, 0.5 * (lo + hi), np.nan)


@validated
def critical_gains(stiffness, damping, inertia, kd, delay, lobes: int = 8, points_per_lobe: int = 48, lag=0.0):
    """Range (kp_min, kp_max) of proportional gains that stabilise the segment at ``delay``, given kd.

    D-subdivision (``docs/reflex.md``, "Critical gains"): stability can change only at
    kp = S (a root at s = 0) or where a root sits at s = j w, i.e. where
    h(w) = A sin(w tau) + B cos(w tau) - kd w = 0, at kp(w) = A cos(w tau) - B sin(w tau), with
    A + j B = (1 + j w T_a)((theta w^2 + S) + j D w) (A = theta w^2 + S, B = D w without the lag).
    The roots of h are searched for
    w tau in (0, lobes pi]; between consecutive candidate gains the number of unstable
    roots is constant and :func:`right_half_plane_roots` tells which interval is stable.
    The lowest stable interval is returned; NaN, NaN where none is.

    Parameters
    ----------
    stiffness, damping, inertia, kd, delay : array_like
        S [N m/rad], D [N m s/rad], theta [kg m^2], kd [N m s/rad], tau [s].
    lobes, points_per_lobe : int
        Search range (in half-periods of the delay) and its sampling.
    lag : array_like, optional
        Activation time constant T_a [s].

    Returns
    -------
    kp_min, kp_max : numpy.ndarray
        [N m/rad], each of the broadcast shape of the inputs; kp_max = inf at tau = 0.

    Raises
    ------
    ParameterError
        Naming ``kd``, for a loop of neutral type (:func:`check_retarded`).
    """
    check_retarded(inertia, damping, kd, lag)
    s, d, theta, kd, tau, lag = as_arrays(stiffness, damping, inertia, kd, delay, lag)
    y = np.linspace(0.0, lobes * np.pi, lobes * points_per_lobe + 1)
    t = np.where(tau > 0, tau, 1.0)[..., None]
    s_, d_, th_, kd_, lag_ = (x[..., None] for x in (s, d, theta, kd, lag))

    def parts(a, w):  # A and B / w from a = theta w^2 + S; B / w stays finite at w = 0
        return a - d_ * lag_ * w**2, d_ + lag_ * a

    def h_over_w(yy):  # h(w) / w as a function of y = w tau, finite at y = 0 (sinc), so the grid starts there
        big_a, b_over_w = parts(th_ * yy**2 / t**2 + s_, yy / t)
        return big_a * t * np.sinc(yy / np.pi) + b_over_w * np.cos(yy) - kd_

    roots = _bracketed_roots(h_over_w, np.broadcast_to(y, s.shape + y.shape))
    w = roots / t
    big_a, b_over_w = parts(th_ * w**2 + s_, w)
    kp_roots = big_a * np.cos(roots) - b_over_w * w * np.sin(roots)
    candidates = np.sort(np.concatenate([s[..., None], kp_roots], axis=-1), axis=-1)  # NaN last
    finite = np.where(np.isnan(candidates), np.inf, candidates)
    lows = np.concatenate([np.full(s.shape + (1,), -np.inf), finite], axis=-1)
    highs = np.concatenate([finite, np.full(s.shape + (1,), np.inf)], axis=-1)
    # a gain inside each interval: the middle, or one step beyond the end of an unbounded one
    low_f, high_f = np.where(np.isinf(lows), highs - 1.0, lows), np.where(np.isinf(highs), np.nan, highs)
    probe = np.where(np.isnan(high_f), low_f + np.abs(low_f) + 1.0, 0.5 * (low_f + high_f))
    ok = stable_at_delay(s_, d_, th_, probe, kd_, tau[..., None], lag_) & (lows < highs)
    first = np.argmax(ok, axis=-1)[..., None]
    found = np.any(ok, axis=-1)
    kp_min = np.where(found, np.take_along_axis(lows, first, axis=-1)[..., 0], np.nan)
    kp_max = np.where(found, np.take_along_axis(highs, first, axis=-1)[..., 0], np.nan)
    # tau = 0: no jw crossing moves with the delay; the search above ran at a stand-in delay of 1 s
    low, high = _delay_free_gains(s, d, theta, kd, lag)
    return np.where(tau == 0, low, kp_min), np.where(tau == 0, high, kp_max)


def _delay_free_gains(stiffness, damping, inertia, kd, lag=0.0):
    """Range (kp_min, kp_max) of proportional gains that stabilise the segment without delay, given kd.

    Routh-Hurwitz on the delay-free characteristic polynomial (docs/reflex.md, "Critical gains")
    T_a theta s^3 + (theta - T_a D) s^2 + (kd - D - T_a S) s + (kp - S): with T_a > 0 every
    coefficient positive and (theta - T_a D)(kd - D - T_a S) > T_a theta (kp - S), so
    kp in (S, S + (theta - T_a D)(kd - D - T_a S) / (T_a theta)); without the lag the quadratic
    theta s^2 + (kd - D) s + (kp - S) needs kd > D and kp > S only.

    Parameters
    ----------
    stiffness, damping, inertia, kd : array_like
        S [N m/rad], D [N m s/rad], theta [kg m^2], kd [N m s/rad].
    lag : array_like, optional
        Activation time constant T_a [s].

    Returns
    -------
    kp_min, kp_max : numpy.ndarray
        [N m/rad], of the broadcast shape; kp_max = inf without the lag (or with theta = 0), NaN, NaN
        where no kp stabilises.

    References
    ----------
    .. [1] Hurwitz A (1895). Ueber die Bedingungen, unter welchen eine Gleichung nur Wurzeln mit
       negativen reellen Theilen besitzt. Math Ann 46:273-284. doi:10.1007/BF01446812
    """
    s, d, theta, kd, lag = as_arrays(stiffness, damping, inertia, kd, lag)
    second, first = theta - lag * d, kd - d - lag * s  # coefficients of s^2 and s
    with np.errstate(divide="ignore", invalid="ignore"):
        room = np.where(lag * theta > 0, second * first / np.where(lag * theta > 0, lag * theta, 1.0), np.inf)
    ok = np.where(lag > 0, (second > 0) & (first > 0), kd > d)
    return np.where(ok, s, np.nan), np.where(ok, s + room, np.nan)


# --- the landscape over a grid ---------------------------------------------------------------
