"""Padé estimates of the delay margin: the rational approximation of the delay, its phase lag and its margin.

The Padé approximant of order n of exp(-s tau) has unit gain on the imaginary axis and
the phase lag -2 sum arctan(...) of its poles; replacing the exact lag w tau by it gives the
delay margin that a Padé loop predicts (docs/reflex.md, "Padé estimate"), vectorised like
:mod:`spinectl.reflex.delay`. The approximant's coefficients are the classical ones [1]_.

References
----------
.. [1] Baker GA Jr, Graves-Morris P (1996). Padé Approximants, 2nd ed. Encyclopedia of
   Mathematics and its Applications 59. Cambridge University Press.
"""

from __future__ import annotations

from fractions import Fraction
from functools import cache
from math import factorial

import numpy as np

from .delay import (
    BISECTIONS,
    Crossings,
    DelayMargin,
    WithoutDelay,
    as_arrays,
    check_retarded,
    crossings_of,
    delay_margin,
    delay_margin_of,
    margin_from_delays,
    pure_gain,
    undefined_inputs,
    without_delay,
)
from .inputs import validated


@validated
def pade_coefficients(order: int) -> np.ndarray:
    """Coefficients c_0..c_n of the [n/n] Padé approximant exp(-x) ~ q(-x) / q(x), q(x) = sum c_k x^k.

    c_k = (2n - k)! n! / ((2n)! k! (n - k)!) (Baker and Graves-Morris [1]_; e.g. n = 1:
    q = 1 + x/2; n = 2: q = 1 + x/2 + x^2/12), lowest power first, c_0 = 1.

    Parameters
    ----------
    order : int
        n >= 1.

    Returns
    -------
    numpy.ndarray, shape (n + 1,)
        c_0..c_n [1], lowest power first.

    References
    ----------
    .. [1] Baker GA Jr, Graves-Morris P (1996). Padé Approximants, 2nd ed. Encyclopedia of
       Mathematics and its Applications 59. Cambridge University Press.
    """
    n = int(order)
    return np.array(
        [
            float(Fraction(factorial(2 * n - k) * factorial(n), factorial(2 * n) * factorial(k) * factorial(n - k)))
            for k in range(n + 1)
        ]
    )


@validated
def pade_phase_lag(y, order: int):
    """Phase lag [rad] of the Padé all-pass q(-jy)/q(jy) at y = w tau, unwrapped.

    Equals 2 arg q(jy) = 2 sum_i atan((y - Im r_i) / -Re r_i) over the roots r_i of q
    (all in Re < 0, so every term is continuous): increases from 0 to n pi, where the
    true delay's lag y grows without bound. Its magnitude is exactly 1: the Padé
    loop has the same crossover frequencies as the true one.

    Parameters
    ----------
    y : array_like
        w tau [rad].
    order : int
        Order n of the approximant.

    Returns
    -------
    numpy.ndarray
        The lag [rad], in [0, n pi); the shape of ``y``.
    """
    return _phase_lag(y, _roots(order))


@cache
def _roots(order: int) -> np.ndarray:
    """The roots of q (:func:`pade_coefficients`), all in Re < 0; computed once per order, read-only."""
    roots = np.roots(pade_coefficients(order)[::-1])
    roots.flags.writeable = False
    return roots


def _phase_lag(y, roots):
    """:func:`pade_phase_lag` with the roots of q given: the bisection finds them once, not at every step."""
    y = np.asarray(y, float)[..., None]
    return 2.0 * np.sum(np.arctan((y - roots.imag) / -roots.real), axis=-1)


@validated
def pade_inverse_lag(phase, order: int):
    """The y >= 0 with :func:`pade_phase_lag` (y) = ``phase`` [rad]; inf where phase >= n pi.

    Newton's method on the lag, which is increasing in y, from y = ``phase`` (the approximant's lag equals
    y to order y^(2n + 1), Baker and Graves-Morris [1]_), inside a bracket that every evaluation narrows;
    a step that would leave the bracket bisects it in u = (2/pi) atan(y) instead (docs/reflex.md,
    "Padé estimate"). The root is found to rounding: equal, to 1e-12 relative, to the bisection it
    replaced where that bisection's own resolution in u allows (y below about 1e3).

    Parameters
    ----------
    phase : array_like
        Lag to reach [rad].
    order : int
        Order n of the approximant.

    Returns
    -------
    numpy.ndarray
        y = w tau [rad], the shape of ``phase``; inf where ``phase`` >= n pi.

    References
    ----------
    .. [1] Baker GA Jr, Graves-Morris P (1996). Padé Approximants, 2nd ed. Encyclopedia of
       Mathematics and its Applications 59. Cambridge University Press.
    """
    phase = np.asarray(phase, float)
    reached = phase < order * np.pi  # False for NaN: the empty crossing slots of a landscape cost nothing
    y = np.full(phase.shape, np.inf)
    y[reached] = _inverse_lag_newton(phase[reached], _roots(order))
    return y


def _inverse_lag_newton(target, roots):
    """y with lag(y) = ``target`` (1-d, in [0, n pi)) by safeguarded Newton steps on the points not yet done.

    A point is done when Newton's step is below 1e-10 of y (the convergence is quadratic and the lag's
    curvature is at most about its slope, every root of q having Re r <= -2: the step after it would be
    below rounding), when the residual is at the rounding of the lag's n arctangents, or when the
    bracket has shrunk to rounding.
    """
    a, b = -roots.real, roots.imag
    eps = np.finfo(float).eps
    noise = 8.0 * eps * np.pi * roots.size
    y = np.maximum(target, 0.0)  # a negative phase has no y >= 0: it ends at 0, as the bisection did
    lo, hi = np.zeros_like(target), np.full_like(target, np.tan(0.5 * np.pi))  # the bisection's range of y
    todo = np.arange(target.size)
    for _ in range(2 * BISECTIONS):  # a bisection step at worst halves u's bracket: done long before
        if not todo.size:
            break
        yy, goal = y[todo], target[todo]
        z = (yy[:, None] - b) / a
        residual = goal - 2.0 * np.sum(np.arctan(z), axis=-1)  # _phase_lag, and its derivative below
        step = residual / (2.0 * np.sum(1.0 / (a * (1.0 + z * z)), axis=-1))
        below = residual > 0
        low, high = np.where(below, yy, lo[todo]), np.where(below, hi[todo], yy)
        lo[todo], hi[todo] = low, high
        new = yy + step
        inside = (new >= low) & (new <= high)
        outside = np.flatnonzero(~inside)
        new[outside] = np.tan(0.5 * (np.arctan(low[outside]) + np.arctan(high[outside])))  # u's midpoint
        y[todo] = new
        converged = (np.abs(step) <= 1e-10 * yy) | (np.abs(residual) <= noise)
        todo = todo[~((inside & converged) | (high - low <= 4.0 * eps * high))]
    return y


def _inverse_lag_bisection(phase, order: int):
    """:func:`pade_inverse_lag` by a vectorised bisection on u = (2/pi) atan(y) in [0, 1), where the lag is
    monotone, :data:`~spinectl.reflex.delay.critical.BISECTIONS` halvings: the form Newton's method replaced, kept as
    the reference of its tests and of ``benchmarks/bench_reflex.py``."""
    phase = np.asarray(phase, float)
    reached = phase < order * np.pi
    target = phase[reached]
    roots = _roots(order)
    lo, hi = np.zeros_like(target), np.ones_like(target)
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        below = _phase_lag(np.tan(0.5 * np.pi * mid), roots) < target
        lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
    y = np.full(phase.shape, np.inf)
    y[reached] = np.tan(0.5 * np.pi * 0.5 * (lo + hi))
    return y


@validated(zero_inertia=True)
def pade_delay_margin(stiffness, damping, inertia, kp, kd, order: int, lag=0.0) -> DelayMargin:
    """Delay margin of the loop with the delay replaced by its [n/n] Padé approximant.

    Same crossings as the exact loop (the approximant is all-pass); only the phase
    differs, so the critical delay of a crossing is y/w with lag(y) = phi, and none
    when phi >= n pi. Converges to :func:`delay_margin` as the order grows.

    Parameters
    ----------
    stiffness, damping, inertia : array_like
        S [N m/rad], D [N m s/rad], theta [kg m^2].
    kp, kd : array_like
        Reflex gains [N m/rad], [N m s/rad].
    order : int
        Order n of the approximant.
    lag : array_like, optional
        Activation time constant T_a [s]; its phase is part of phi.

    Returns
    -------
    DelayMargin
        As :func:`~spinectl.reflex.delay.delay_margin`, with the Padé loop's critical
        delays [s]; inf (delay-independent) also where every crossing's phase is >= n pi.

    Raises
    ------
    ParameterError
        Naming ``kd``, for a loop of neutral type (:func:`~spinectl.reflex.delay.check_retarded`).
    """
    check_retarded(inertia, damping, kd, lag)
    s, d, theta, kp, kd, lag = as_arrays(stiffness, damping, inertia, kp, kd, lag)
    free = without_delay(s, d, theta, kp, kd, lag)
    return pade_delay_margin_of(s, d, theta, kp, kd, order, lag, free, crossings_of(s, d, theta, kp, kd, lag, free))


def pade_delay_margin_of(s, d, theta, kp, kd, order: int, lag, free: WithoutDelay, cr: Crossings) -> DelayMargin:
    """:func:`pade_delay_margin` from the delay-free loop and the crossings (:func:`.delay.crossings_of`).

    Parameters
    ----------
    s, d, theta, kp, kd, lag : numpy.ndarray
        As :func:`pade_delay_margin`, float arrays of one shape, checked
        (:func:`~spinectl.reflex.delay.check_retarded`).
    order : int
        Order n of the approximant.
    free : WithoutDelay
        Their :func:`~spinectl.reflex.delay.without_delay`.
    cr : Crossings
        Their crossings.

    Returns
    -------
    DelayMargin
        As :func:`pade_delay_margin`.
    """
    first = pade_inverse_lag(cr.phase, order) / cr.frequency
    undefined = undefined_inputs(s, d, theta, kp, kd, lag)
    pade = margin_from_delays(first, cr.frequency, free.stable, undefined)
    gain = pure_gain(theta, d, kd, lag) & ~undefined
    if not np.any(gain):
        return pade
    exact = delay_margin_of(s, d, theta, kp, kd, lag, free, cr)  # no crossings: the closed form holds for Padé too
    fields = ("margin", "frequency", "status")
    return DelayMargin(*(np.where(gain, getattr(exact, f), getattr(pade, f)) for f in fields))


@validated(zero_inertia=True)
def pade_convergence(stiffness, damping, inertia, kp, kd, orders, lag=0.0):
    """Padé delay margins and their errors against the exact margin, for several orders.

    Parameters
    ----------
    stiffness, damping, inertia : array_like
        S [N m/rad], D [N m s/rad], theta [kg m^2].
    kp, kd : array_like
        Reflex gains [N m/rad], [N m s/rad].
    orders : sequence of int
        Orders n of the approximants.
    lag : array_like, optional
        Activation time constant T_a [s].

    Returns
    -------
    margins, errors : numpy.ndarray, shape (len(orders), ...)
        Padé delay margin [s] and its error (Padé - exact) [s]; 0 where both are inf.
    """
    exact = delay_margin(stiffness, damping, inertia, kp, kd, lag).margin
    margins = np.stack([pade_delay_margin(stiffness, damping, inertia, kp, kd, n, lag).margin for n in orders])
    with np.errstate(invalid="ignore"):
        errors = np.where(margins == exact, 0.0, margins - exact)
    return margins, errors
