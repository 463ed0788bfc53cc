"""Delayed PD reflex of one segment: default gains, exact and Padé delay margins, critical gains.

Pure vectorised numpy functions of arrays (any broadcastable shapes) of the
segment's stiffness S = dM/dalpha [N m/rad], damping D = dM/domega
[N m s/rad], inertia theta [kg m^2] and the reflex gains kp [N m/rad],
kd [N m s/rad]; no python-control object per point (the loop and the derivations
are in docs/reflex.md, "The loop" and "Crossing frequencies and the exact delay
margin"). The reflex is beyond the paper, which discusses it in words only.

The linearised segment theta alpha'' = S alpha + D alpha' + u with the delayed
reflex u(t) = -(kp alpha + kd alpha')(t - tau) has the characteristic
quasi-polynomial

    Delta(s, tau) = P(s) + Q(s) exp(-s tau),  P(s) = theta s^2 - D s - S,  Q(s) = kp + kd s.

A root crosses the imaginary axis at s = j w only where abs(Q(jw)) = abs(P(jw)), i.e.
F(w^2) = 0 with F(x) = theta^2 x^2 + (2 S theta + D^2 - kd^2) x + S^2 - kp^2,
and then only at the delays tau = (phi + 2 pi k) / w, phi = arg(-Q/P) mod 2 pi.
The sign of F'(w^2) is the direction of the crossing (Cooke and Grossman 1982 [1]_;
Cooke and van den Driessche 1986 [2]_): + destabilising, - stabilising.

theta = 0 with kd = 0 is accepted by :func:`delay_margin` and :func:`phase_margin`
too: the first-order-plus-delay loop of the textbooks (a retarded equation);
theta = 0 with kd != 0 would be of neutral type and is not covered, and the root
counting (:func:`right_half_plane_roots`, :func:`critical_gains`) assumes theta > 0.

References
----------
.. [1] Cooke KL, Grossman Z (1982). Discrete delay, distributed delay and stability
   switches. J Math Anal Appl 86:592-627.
.. [2] Cooke KL, van den Driessche P (1986). On zeroes of some transcendental
   equations. Funkcialaj Ekvacioj 29:77-90.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .inputs import validated

STATUS = ("finite", "delay_independent", "unstable_without_delay", "undefined")
"""Meaning of :attr:`DelayMargin.status` codes 0..3.

- ``finite``: stable without delay; it loses stability at the finite delay margin.
- ``delay_independent``: stable without delay and no root can reach the imaginary
  axis (abs(Q(jw)) != abs(P(jw)) for every w > 0): stable for every delay, margin = inf.
  This is where self-stability makes the delay irrelevant.
- ``unstable_without_delay``: not stable even at tau = 0 (kp <= S or kd <= D):
  margin = 0, the largest tau_m with stability on all of [0, tau_m) being none.
- ``undefined``: an input is NaN (e.g. an infeasible optimum): margin = NaN.
"""
FINITE, DELAY_INDEPENDENT, UNSTABLE_WITHOUT_DELAY, UNDEFINED = range(len(STATUS))

BISECTIONS = 60
"""Halvings of a bracket in the vectorised root finders: 2^-60 of the bracket, below float resolution."""


def as_arrays(*values):
    """The inputs as float arrays broadcast against each other (shared by the vectorised reflex functions).

    Parameters
    ----------
    *values : array_like
        Broadcastable arrays.

    Returns
    -------
    list of numpy.ndarray
        Float views of one common shape.
    """
    return np.broadcast_arrays(*(np.asarray(x, float) for x in values))


@validated
def stable_without_delay(stiffness, damping, kp, kd):
    """True where theta s^2 + (kd - D) s + (kp - S) is Hurwitz: kd > D and kp > S (theta > 0).

    Parameters
    ----------
    stiffness, damping : array_like
        S [N m/rad], D [N m s/rad].
    kp, kd : array_like
        Reflex gains [N m/rad], [N m s/rad].

    Returns
    -------
    numpy.ndarray of bool
        True where the delay-free closed loop is asymptotically stable; the broadcast
        shape of the inputs.
    """
    s, d, kp, kd = as_arrays(stiffness, damping, kp, kd)
    return (kd > d) & (kp > s)


@dataclass(frozen=True)
class Crossings:
    """Where roots of the closed loop can cross the imaginary axis; two slots per point.

    Slot 0 holds the larger root x+ of F (destabilising), slot 1 the smaller x-
    (stabilising); empty slots are NaN.

    Attributes
    ----------
    frequency : numpy.ndarray, shape (..., 2)
        w > 0 with abs(Q(jw)) = abs(P(jw)), the gain crossover of the loop [rad/s].
    phase : numpy.ndarray, shape (..., 2)
        phi = arg(-Q(jw)/P(jw)) in [0, 2 pi) [rad]: the delay must add w tau = phi (mod 2 pi).
    direction : numpy.ndarray, shape (..., 2)
        sign F'(w^2): +1 roots move right as tau grows, -1 left, 0 a tangency.
    """

    frequency: np.ndarray
    phase: np.ndarray
    direction: np.ndarray

    @property
    def first_delay(self) -> np.ndarray:
        """The smallest critical delay of each crossing, phi / w [s], shape (..., 2)."""
        return self.phase / self.frequency


@validated(zero_inertia=True)
def crossings(stiffness, damping, inertia, kp, kd) -> Crossings:
    """Crossing frequencies, phases and directions of the delayed reflex loop.

    Solves F(x) = theta^2 x^2 + (2 S theta + D^2 - kd^2) x + (S^2 - kp^2) = 0,
    from abs(kp + j kd w)^2 = (S + theta w^2)^2 + D^2 w^2 (``docs/reflex.md``), for x = w^2 > 0.
    w = 0 is never a crossing for kp != S: there exp(0) = 1 and Delta(0) = kp - S.
    The direction of a crossing is sign F'(w^2) [1]_ [2]_.

    Parameters
    ----------
    stiffness, damping, inertia : array_like
        S [N m/rad], D [N m s/rad], theta [kg m^2].
    kp, kd : array_like
        Reflex gains [N m/rad], [N m s/rad].

    Returns
    -------
    Crossings
        Frequency [rad/s], phase [rad] and direction [1], each of shape (..., 2) with
        ``...`` the broadcast shape of the inputs; NaN in empty slots.

    References
    ----------
    .. [1] Cooke KL, Grossman Z (1982). Discrete delay, distributed delay and stability
       switches. J Math Anal Appl 86:592-627.
    .. [2] Cooke KL, van den Driessche P (1986). On zeroes of some transcendental
       equations. Funkcialaj Ekvacioj 29:77-90.
    """
    s, d, theta, kp, kd = as_arrays(stiffness, damping, inertia, kp, kd)
    a, b, c = theta**2, 2.0 * s * theta + d**2 - kd**2, s**2 - kp**2
    disc = b**2 - 4.0 * a * c
    with np.errstate(divide="ignore", invalid="ignore"):
        # the cancellation-free pair of roots; a = 0 (first order) leaves x = c / q only
        q = -0.5 * (b + np.copysign(np.sqrt(np.where(disc >= 0, disc, np.nan)), b))
        x = np.stack([q / a, c / q], axis=-1)
        x = np.where(np.isfinite(x) & (x > 0), x, np.nan)
        x = -np.sort(-x, axis=-1)  # larger first, NaN last
        w = np.sqrt(x)
        slope = 2.0 * a[..., None] * x + b[..., None]
    direction = np.where(disc[..., None] == 0, 0.0, np.sign(slope))
    jw = 1j * np.nan_to_num(w)
    p = theta[..., None] * jw**2 - d[..., None] * jw - s[..., None]
    qq = kp[..., None] + kd[..., None] * jw
    with np.errstate(divide="ignore", invalid="ignore"):
        phase = np.mod(np.angle(-qq / p), 2.0 * np.pi)
    phase = np.where(np.isnan(w), np.nan, phase)
    return Crossings(frequency=w, phase=phase, direction=np.where(np.isnan(w), np.nan, direction))


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


@validated(zero_inertia=True)
def delay_margin(stiffness, damping, inertia, kp, kd) -> DelayMargin:
    """Exact delay margin from the quasi-polynomial (docs/reflex.md, "Crossing frequencies and the exact delay margin").

    If the loop is stable at tau = 0 the first root to reach the imaginary axis as
    tau grows does so at the smallest critical delay phi/w over the crossings;
    without crossings the loop is stable for every delay (margin inf).

    Parameters
    ----------
    stiffness, damping, inertia, kp, kd : array_like
        S [N m/rad], D [N m s/rad], theta [kg m^2], kp [N m/rad], kd [N m s/rad].

    Returns
    -------
    DelayMargin
        tau_m [s] (inf, 0 or NaN by :data:`STATUS`), the frequency at which stability
        is lost [rad/s] and the status code, each of the broadcast shape of the inputs.

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
    """
    cr = crossings(stiffness, damping, inertia, kp, kd)
    stable0 = stable_without_delay(stiffness, damping, kp, kd)
    undefined = undefined_inputs(stiffness, damping, inertia, kp, kd)
    return margin_from_delays(cr.first_delay, cr.frequency, stable0, undefined)


@validated
def right_half_plane_roots(stiffness, damping, inertia, kp, kd, delay):
    """Number of closed-loop roots with Re s > 0 at the delay ``delay`` [s], exactly.

    N(tau) = N(0) + 2 sum over crossings of direction * #{k >= 0: phi/w + 2 pi k/w < tau}:
    every crossing moves a conjugate pair (retarded type: no root comes from
    infinity). N(0) counts the roots of theta s^2 + (kd - D) s + (kp - S).

    Parameters
    ----------
    stiffness, damping, inertia : array_like
        S [N m/rad], D [N m s/rad], theta [kg m^2].
    kp, kd : array_like
        Reflex gains [N m/rad], [N m s/rad].
    delay : array_like
        tau [s].

    Returns
    -------
    numpy.ndarray
        The count, as floats (NaN where an input is NaN).
    """
    s, d, theta, kp, kd, tau = as_arrays(stiffness, damping, inertia, kp, kd, delay)
    c0, c1 = kp - s, kd - d
    n0 = np.where(c0 < 0, 1.0, np.where(c1 < 0, 2.0, 0.0))
    cr = crossings(s, d, theta, kp, kd)
    with np.errstate(invalid="ignore"):
        passed = np.floor((tau[..., None] - cr.first_delay) * cr.frequency / (2.0 * np.pi)) + 1.0
    passed = np.where(np.isnan(passed), 0.0, np.maximum(passed, 0.0))
    count = n0 + 2.0 * np.sum(np.nan_to_num(cr.direction) * passed, axis=-1)
    return np.where(undefined_inputs(s, d, theta, kp, kd, tau), np.nan, count)


@validated
def stable_at_delay(stiffness, damping, inertia, kp, kd, delay):
    """True where the closed loop with the true delay [s] has every root in Re s < 0.

    Exact for every delay, also beyond the delay margin (stability switches). A root
    fixed at s = 0 (kp = S) or on the axis at tau = 0 (kd = D) counts as unstable.

    Parameters
    ----------
    stiffness, damping, inertia : array_like
        S [N m/rad], D [N m s/rad], theta [kg m^2].
    kp, kd : array_like
        Reflex gains [N m/rad], [N m s/rad].
    delay : array_like
        tau [s].

    Returns
    -------
    numpy.ndarray of bool
        True where the closed loop with delay tau is asymptotically stable; the broadcast
        shape of the inputs (False where an input is NaN).
    """
    s, d, theta, kp, kd, tau = as_arrays(stiffness, damping, inertia, kp, kd, delay)
    count = right_half_plane_roots(s, d, theta, kp, kd, tau)
    on_axis = (kp == s) | ((tau == 0) & (kd <= d))
    return (count == 0) & ~on_axis


@validated(zero_inertia=True)
def phase_margin(stiffness, damping, inertia, kp, kd, delay):
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

    Returns
    -------
    phase_margin, crossover : numpy.ndarray
        PM [rad] and w_c [rad/s], each of the broadcast shape of the inputs.
    """
    cr = crossings(stiffness, damping, inertia, kp, kd)
    tau = np.asarray(delay, float)
    delays = np.where(np.isnan(cr.first_delay), np.inf, cr.first_delay)
    slot = np.argmin(delays, axis=-1)[..., None]
    w = np.take_along_axis(cr.frequency, slot, axis=-1)[..., 0]
    phi = np.take_along_axis(cr.phase, slot, axis=-1)[..., 0]
    pm = np.mod(phi - w * tau + np.pi, 2.0 * np.pi) - np.pi
    return np.where(np.isnan(w), np.inf, pm), w


# --- Padé approximants of the delay ----------------------------------------------------------


# --- critical gains ------------------------------------------------------------------------


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
def critical_gains(stiffness, damping, inertia, kd, delay, lobes: int = 8, points_per_lobe: int = 48):
    """Range (kp_min, kp_max) of proportional gains that stabilise the segment at ``delay``, given kd.

    D-subdivision (``docs/reflex.md``, "Critical gains"): stability can change only at
    kp = S (a root at s = 0) or where a root sits at s = j w, i.e. where
    h(w) = (theta w^2 + S) sin(w tau) + D w cos(w tau) - kd w = 0, at
    kp(w) = (theta w^2 + S) cos(w tau) - D w sin(w tau). The roots of h are searched for
    w tau in (0, lobes pi]; between consecutive candidate gains the number of unstable
    roots is constant and :func:`right_half_plane_roots` tells which interval is stable.
    The lowest stable interval is returned; NaN, NaN where none is.

    Parameters
    ----------
    stiffness, damping, inertia, kd, delay : array_like
        S [N m/rad], D [N m s/rad], theta [kg m^2], kd [N m s/rad], tau [s].
    lobes, points_per_lobe : int
        Search range (in half-periods of the delay) and its sampling.

    Returns
    -------
    kp_min, kp_max : numpy.ndarray
        [N m/rad], each of the broadcast shape of the inputs; kp_max = inf at tau = 0.
    """
    s, d, theta, kd, tau = as_arrays(stiffness, damping, inertia, kd, delay)
    y = np.linspace(0.0, lobes * np.pi, lobes * points_per_lobe + 1)
    t = np.where(tau > 0, tau, 1.0)[..., None]
    s_, d_, th_, kd_ = (x[..., None] for x in (s, d, theta, kd))

    def h_over_w(yy):  # h(w) / w as a function of y = w tau, finite at y = 0 (sinc), so the grid starts there
        return (th_ * yy**2 / t**2 + s_) * t * np.sinc(yy / np.pi) + d_ * np.cos(yy) - kd_

    roots = _bracketed_roots(h_over_w, np.broadcast_to(y, s.shape + y.shape))
    w = roots / t
    kp_roots = (th_ * w**2 + s_) * np.cos(roots) - d_ * w * np.sin(roots)
    candidates = np.sort(np.concatenate([s[..., None], kp_roots], axis=-1), axis=-1)  # NaN last
    finite = np.where(np.isnan(candidates), np.inf, candidates)
    lows = np.concatenate([np.full(s.shape + (1,), -np.inf), finite], axis=-1)
    highs = np.concatenate([finite, np.full(s.shape + (1,), np.inf)], axis=-1)
    # a gain inside each interval: the middle, or one step beyond the end of an unbounded one
    low_f, high_f = np.where(np.isinf(lows), highs - 1.0, lows), np.where(np.isinf(highs), np.nan, highs)
    probe = np.where(np.isnan(high_f), low_f + np.abs(low_f) + 1.0, 0.5 * (low_f + high_f))
    ok = stable_at_delay(s_, d_, th_, probe, kd_, tau[..., None]) & (lows < highs)
    first = np.argmax(ok, axis=-1)[..., None]
    found = np.any(ok, axis=-1)
    kp_min = np.where(found, np.take_along_axis(lows, first, axis=-1)[..., 0], np.nan)
    kp_max = np.where(found, np.take_along_axis(highs, first, axis=-1)[..., 0], np.nan)
    no_delay = tau == 0
    kp_min = np.where(no_delay, np.where(kd > d, s, np.nan), kp_min)
    kp_max = np.where(no_delay, np.where(kd > d, np.inf, np.nan), kp_max)
    return kp_min, kp_max


# --- the landscape over a grid ---------------------------------------------------------------


