"""Delayed, lagged PD reflex of one segment: exact delay margins, root counting, critical gains.

Pure vectorised numpy functions of arrays (any broadcastable shapes) of the
segment's stiffness S = dM/dalpha [N m/rad], damping D = dM/domega
[N m s/rad], inertia theta [kg m^2] and the reflex gains kp [N m/rad],
kd [N m s/rad], and the activation time constant T_a [s] of the force generation
(``lag``, 0 by default: the pure delay); no python-control object per point (the loop
and the derivations are in docs/reflex.md, "The loop", "Force generation: the
activation lag" and "Crossing frequencies and the exact delay margin"). The reflex
is beyond the paper, which discusses it in words only.

The linearised segment theta alpha'' = S alpha + D alpha' + u with the delayed reflex
command -(kp alpha + kd alpha')(t - tau), turned into the torque u by the lag
T_a u' + u = command, has the characteristic quasi-polynomial

    Delta(s, tau) = P(s) + Q(s) exp(-s tau),  P(s) = (T_a s + 1)(theta s^2 - D s - S),  Q(s) = kp + kd s.

A root crosses the imaginary axis at s = j w only where abs(Q(jw)) = abs(P(jw)), i.e.
F(w^2) = 0 with F(x) = (1 + T_a^2 x)(theta^2 x^2 + (2 S theta + D^2) x + S^2) - kp^2 - kd^2 x
(quadratic in x for T_a = 0, cubic otherwise), and then only at the delays
tau = (phi + 2 pi k) / w, phi = arg(-Q/P) mod 2 pi. The sign of F'(w^2) is the direction
of the crossing (Cooke and Grossman 1982 [1]_; Cooke and van den Driessche 1986 [2]_):
+ destabilising, - stabilising. With T_a = 0 every function returns what it did before
the lag existed, bit for bit.

Boundary cases (docs/reflex.md, "Boundary cases"): the delay-free loop is classified from
the signs of its coefficients after making the leading one positive, so a first-order
loop (theta = 0) does not depend on the sign convention; a pair on the imaginary axis at
tau = 0 (kd = D) is followed to the side it leaves to; the pure gain (theta = D = T_a =
kd = 0) has a closed form; loops of neutral type (kd != 0 with deg P <= 1) are refused.

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

from ..errors import ParameterError
from .inputs import validated

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

BISECTIONS = 60
"""Halvings of a bracket in the vectorised root finders: 2^-60 of the bracket, below float resolution."""

SLOTS = 3
"""Crossing slots per point: F is at most cubic in w^2 (quadratic without the activation lag)."""

_TANGENT = 1e-7
"""Relative distance below which two roots of the cubic F are one double root (a tangency, direction 0)."""


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


def check_retarded(inertia, damping, kd, lag=0.0) -> None:
    """Refuse the loops that are not of retarded type: deg Q >= deg P (docs/reflex.md, "Boundary cases").

    deg P = 2 (theta > 0), 1 (theta = 0, D != 0) or 0 (theta = D = 0), plus 1 with the
    activation lag; deg Q = 1 where kd != 0. deg Q = deg P >= 1 is of neutral type (roots
    can come from infinity), deg Q > deg P advanced: neither is covered. The pure gain
    (deg P = deg Q = 0) is, in closed form (:func:`delay_margin`).

    Parameters
    ----------
    inertia, damping, kd, lag : array_like
        theta [kg m^2], D [N m s/rad], kd [N m s/rad], T_a [s].

    Raises
    ------
    ParameterError
        Naming ``kd``, where some point has kd != 0 and deg P <= 1.
    """
    theta, d, kd, lag = as_arrays(inertia, damping, kd, lag)
    degree_p = np.where(theta != 0, 2, np.where(d != 0, 1, 0)) + (lag != 0)
    if np.any((kd != 0) & (degree_p <= 1)):
        raise ParameterError(
            "kd",
            "must be 0 where inertia = 0 and activation_time_constant = 0: with a derivative reflex the loop "
            "is then of neutral type, which the delay margin does not cover",
        )


def without_delay_coefficients(stiffness, damping, inertia, kp, kd, lag=0.0):
    """Coefficients of the delay-free closed loop R(s) = (T_a s + 1)(theta s^2 - D s - S) + kp + kd s.

    Parameters
    ----------
    stiffness, damping, inertia, kp, kd, lag : array_like
        S [N m/rad], D [N m s/rad], theta [kg m^2], kp [N m/rad], kd [N m s/rad], T_a [s].

    Returns
    -------
    r3, r2, r1, r0 : numpy.ndarray
        theta T_a, theta - D T_a, kd - D - S T_a, kp - S [N m/rad times s^k]; with T_a = 0 exactly
        0, theta, kd - D and kp - S.
    """
    s, d, theta, kp, kd, lag = as_arrays(stiffness, damping, inertia, kp, kd, lag)
    return theta * lag, theta - d * lag, kd - d - s * lag, kp - s


@dataclass(frozen=True)
class WithoutDelay:
    """The delay-free closed loop R(s) of :func:`without_delay_coefficients`, per point.

    Attributes
    ----------
    unstable : numpy.ndarray
        Roots of R in Re s > 0, counted exactly from the signs of its coefficients (Routh).
    axis_frequency : numpy.ndarray
        w0 > 0 where R has the pair +-j w0 on the imaginary axis [rad/s]; NaN elsewhere.
    zero_root : numpy.ndarray of bool
        R(0) = kp - S = 0: s = 0 is a root for every delay.
    departure : numpy.ndarray
        Where the axis pair leaves to as tau grows from 0: +1 right, -1 left, 0 it stays on
        the axis (no reflex); NaN without an axis pair.
    """

    unstable: np.ndarray
    axis_frequency: np.ndarray
    zero_root: np.ndarray
    departure: np.ndarray

    @property
    def stable(self) -> np.ndarray:
        """Every root of R in Re s < 0."""
        return (self.unstable == 0) & np.isnan(self.axis_frequency) & ~self.zero_root


def _routh(r3, r2, r1, r0):
    """Roots in Re s > 0 and the axis pair of r3 s^3 + r2 s^2 + r1 s + r0 (any leading zeros), exactly."""
    lead = np.where(r3 != 0, r3, np.where(r2 != 0, r2, np.where(r1 != 0, r1, 1.0)))
    r3, r2, r1, r0 = (np.sign(lead) * c for c in (r3, r2, r1, r0))  # leading coefficient > 0
    nan = np.full(np.shape(r0), np.nan)
    with np.errstate(divide="ignore", invalid="ignore"):
        # degree 1 and 2
        linear = (r0 < 0).astype(float)
        quadratic = np.where(r0 < 0, 1.0, np.where(r0 == 0, (r1 < 0) * 1.0, np.where(r1 < 0, 2.0, 0.0)))
        axis2 = np.where((r1 == 0) & (r0 > 0), np.sqrt(r0 / r2), nan)
        # degree 3: Routh's first column r3, r2, h / r2, r0 with h = r2 r1 - r3 r0
        h = r2 * r1 - r3 * r0
        column = np.sign(np.stack([r3, r2, h / r2, r0]))
        changes = np.sum(column[1:] != column[:-1], axis=0).astype(float)
        zero = np.where(r1 < 0, 1.0, np.where(r2 < 0, np.where(r1 > 0, 2.0, 1.0), 0.0))  # s (r3 s^2 + r2 s + r1)
        split = (r2 < 0) * 1.0 + (r1 < 0) * 1.0  # h = 0: R = (r3 s + r2)(s^2 + r1 / r3)
        cubic = np.where(r0 == 0, zero, np.where(r2 == 0, np.where(r0 > 0, 2.0, 1.0), np.where(h == 0, split, changes)))
        axis3 = np.where((h == 0) & (r2 != 0) & (r1 > 0) & (r0 != 0), np.sqrt(r1 / r3), nan)
    unstable = np.where(r3 != 0, cubic, np.where(r2 != 0, quadratic, np.where(r1 != 0, linear, 0.0)))
    axis = np.where(r3 != 0, axis3, np.where(r2 != 0, axis2, nan))
    return unstable, axis


def without_delay(stiffness, damping, inertia, kp, kd, lag=0.0) -> WithoutDelay:
    """The delay-free closed loop: its unstable roots, an axis pair and where that pair goes as tau grows.

    An axis pair +-j w0 of R (e.g. kd = D and kp > S without the lag) is a crossing at tau = 0.
    It leaves to the side of Re ds/dtau = Re s0 Q(s0) / R'(s0) (the first order of
    Delta(s(tau), tau) = 0 in tau, which has the sign of F'(w0^2)); where that vanishes (a
    tangency, e.g. kp = 0, kd = D) the second order decides,
    s2 = [(sQ)'(s0) s1 - R''(s0) s1^2 / 2 - s0^2 Q(s0) / 2] / R'(s0), and with Q = 0 (no reflex)
    the pair stays on the axis for every delay (docs/reflex.md, "Boundary cases").

    Parameters
    ----------
    stiffness, damping, inertia, kp, kd, lag : array_like
        S [N m/rad], D [N m s/rad], theta [kg m^2], kp [N m/rad], kd [N m s/rad], T_a [s].

    Returns
    -------
    WithoutDelay
        Counts, axis frequency [rad/s], zero-root flags and departures, each of the
        broadcast shape of the inputs.
    """
    s, d, theta, kp, kd, lag = as_arrays(stiffness, damping, inertia, kp, kd, lag)
    unstable, w0 = _routh(*without_delay_coefficients(s, d, theta, kp, kd, lag))
    axis = np.isfinite(w0)
    departure = np.full(w0.shape, np.nan)
    if np.any(axis):  # only at the points with an axis pair, rare in a landscape
        departure[axis] = _departure(*(v[axis] for v in (s, d, theta, kp, kd, lag, w0)))
    return WithoutDelay(unstable=unstable, axis_frequency=w0, zero_root=kp == s, departure=departure)


def _departure(s, d, theta, kp, kd, lag, w0):
    """Where the axis pair +-j w0 goes as tau grows from 0 (:func:`without_delay`): +1, -1 or 0."""
    s0 = 1j * w0
    with np.errstate(all="ignore"):
        p2, dp2 = theta * s0**2 - d * s0 - s, 2.0 * theta * s0 - d
        r1 = lag * p2 + (lag * s0 + 1.0) * dp2 + kd  # R'(s0)
        r2 = 2.0 * lag * dp2 + 2.0 * theta * (lag * s0 + 1.0)  # R''(s0)
        q0, sq1 = kp + kd * s0, kp + 2.0 * kd * s0
        s1 = s0 * q0 / r1
        s2 = (sq1 * s1 - 0.5 * r2 * s1**2 - 0.5 * s0**2 * q0) / r1
        first = np.where(np.abs(s1.real) > 1e-12 * np.abs(s1), np.sign(s1.real), 0.0)
        second = np.where(np.abs(s2.real) > 1e-12 * np.abs(s2), np.sign(s2.real), 0.0)
    return np.where(first != 0, first, second)


@validated(zero_inertia=True)
def stable_without_delay(stiffness, damping, inertia, kp, kd, lag=0.0):
    """True where the delay-free closed loop R(s) of :func:`without_delay_coefficients` is Hurwitz.

    Without the lag and with theta > 0: kd > D and kp > S. Decided from the signs of
    R's coefficients after making the leading one positive, so that a first-order loop
    (theta = 0) does not depend on the sign convention of P and Q.

    Parameters
    ----------
    stiffness, damping, inertia : array_like
        S [N m/rad], D [N m s/rad], theta [kg m^2].
    kp, kd : array_like
        Reflex gains [N m/rad], [N m s/rad].
    lag : array_like, optional
        Activation time constant T_a [s].

    Returns
    -------
    numpy.ndarray of bool
        True where the delay-free closed loop is asymptotically stable; the broadcast
        shape of the inputs.
    """
    return without_delay(stiffness, damping, inertia, kp, kd, lag).stable


@dataclass(frozen=True)
class Crossings:
    """Where roots of the closed loop can cross the imaginary axis; :data:`SLOTS` slots per point.

    Slots hold the positive roots x = w^2 of F, largest first; empty slots are NaN.
    Without the lag F is quadratic: slot 0 holds x+ (destabilising), slot 1 x-
    (stabilising) and slot 2 is empty.

    Attributes
    ----------
    frequency : numpy.ndarray, shape (..., 3)
        w > 0 with abs(Q(jw)) = abs(P(jw)), the gain crossover of the loop [rad/s].
    phase : numpy.ndarray, shape (..., 3)
        phi = arg(-Q(jw)/P(jw)) in [0, 2 pi) [rad]: the delay must add w tau = phi (mod 2 pi);
        exactly 0 for a pair that sits on the axis at tau = 0.
    direction : numpy.ndarray, shape (..., 3)
        sign F'(w^2): +1 roots move right as tau grows, -1 left, 0 a tangency.
    """

    frequency: np.ndarray
    phase: np.ndarray
    direction: np.ndarray

    @property
    def first_delay(self) -> np.ndarray:
        """The smallest critical delay of each crossing, phi / w [s], shape (..., 3)."""
        return self.phase / self.frequency


def crossing_polynomial(stiffness, damping, inertia, kp, kd, lag=0.0):
    """Coefficients of F(x) = abs(P(jw))^2 - abs(Q(jw))^2 in x = w^2, P = (T_a s + 1)(theta s^2 - D s - S).

    F(x) = (1 + T_a^2 x)(theta^2 x^2 + (2 S theta + D^2) x + S^2) - kp^2 - kd^2 x (docs/reflex.md,
    "Crossing frequencies and the exact delay margin").

    Parameters
    ----------
    stiffness, damping, inertia, kp, kd, lag : array_like
        S [N m/rad], D [N m s/rad], theta [kg m^2], kp [N m/rad], kd [N m s/rad], T_a [s].

    Returns
    -------
    f3, f2, f1, f0 : numpy.ndarray
        The coefficients of x^3 .. x^0; f3 = 0 and f2 = theta^2 without the lag.
    """
    s, d, theta, kp, kd, lag = as_arrays(stiffness, damping, inertia, kp, kd, lag)
    t2 = lag**2
    middle = 2.0 * s * theta + d**2
    return t2 * theta**2, theta**2 + t2 * middle, middle - kd**2 + t2 * s**2, s**2 - kp**2


def _positive_roots(f3, f2, f1, f0):
    """Positive roots x of F, largest first, :data:`SLOTS` slots, and sign F'(x) at each (0: double root)."""
    cubic_points = f3 != 0
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        if np.all(cubic_points):  # every point has the lag (a landscape): no quadratic to solve
            x, tangent = _cubic_roots(f3, f2, f1, f0)
        else:
            x, tangent = _quadratic_roots(f2, f1, f0)
            if np.any(cubic_points):
                cubic, cubic_tangent = _cubic_roots(f3, f2, f1, f0)
                x = np.where(cubic_points[..., None], cubic, x)
                tangent = np.where(cubic_points[..., None], cubic_tangent, tangent)
    x = np.where(np.isfinite(x) & (x > 0), x, np.nan)
    order = np.argsort(-np.nan_to_num(x, nan=-np.inf), axis=-1, kind="stable")  # larger first, NaN last
    x = np.take_along_axis(x, order, axis=-1)
    tangent = np.take_along_axis(tangent, order, axis=-1)
    with np.errstate(invalid="ignore", over="ignore"):
        slope = 2.0 * f2[..., None] * x + f1[..., None] + 3.0 * f3[..., None] * x**2
    return x, np.where(tangent, 0.0, np.sign(slope))


def _quadratic_roots(a, b, c):
    """Roots of a x^2 + b x + c by the cancellation-free formula in :data:`SLOTS` slots (the third NaN; a = 0,
    a first-order F, leaves x = c / q only), and double-root flags (discriminant 0)."""
    disc = b**2 - 4.0 * a * c
    q = -0.5 * (b + np.copysign(np.sqrt(np.where(disc >= 0, disc, np.nan)), b))
    x = np.stack([q / a, c / q, np.full(q.shape, np.nan)], axis=-1)
    return x, np.broadcast_to(disc[..., None] == 0, x.shape)


def _cubic_roots(f3, f2, f1, f0):
    """Real roots of f3 x^3 + f2 x^2 + f1 x + f0 (f3 != 0; NaN where not real), and double-root flags.

    In closed form (:func:`_cubic_candidates`); the real ones (:func:`_is_real`) polished by one Newton step
    (:func:`_newton_polish`); two roots within :data:`_TANGENT` of each other are one double root (a
    tangency): one of them is kept (docs/reflex.md, "Crossing frequencies and the exact delay margin").
    """
    real_part, imag_part = _cubic_candidates(f3, f2, f1, f0)
    real = np.where(_is_real(real_part, imag_part), real_part, np.nan)
    x = _newton_polish(real, f3, f2, f1, f0, steps=1, longest=1e-6)
    x0, x1, x2 = x[..., 0], x[..., 1], x[..., 2]
    with np.errstate(invalid="ignore"):
        c01, c02, c12 = np.abs(x0 - x1), np.abs(x0 - x2), np.abs(x1 - x2)
        t0, t1, t2 = _TANGENT * np.abs(x0), _TANGENT * np.abs(x1), _TANGENT * np.abs(x2)
    # x_i is a twin of x_j if |x_i - x_j| <= _TANGENT |x_i| (as seen from x_i); the first of each pair stays
    later1, later2 = c01 <= t1, (c02 <= t2) | (c12 <= t2)
    twins = np.stack([(c01 <= t0) | (c02 <= t0), later1 | (c12 <= t1), later2], axis=-1)
    return np.stack([x0, np.where(later1, np.nan, x1), np.where(later2, np.nan, x2)], axis=-1), twins


def _cubic_roots_companion(f3, f2, f1, f0):
    """:func:`_cubic_roots` from the eigenvalues of the companion matrix, batched, three Newton steps and the
    pairing spelled out over all pairs: the form the closed form replaced, kept as the reference of its
    tests and of ``benchmarks/bench_reflex.py``."""
    lead = np.where(f3 != 0, f3, 1.0)
    companion = np.zeros(f3.shape + (3, 3))
    companion[..., 0, :] = -np.stack([f2, f1, f0], axis=-1) / lead[..., None]
    companion[..., 1, 0] = companion[..., 2, 1] = 1.0
    companion = np.where(np.isfinite(companion), companion, 0.0)
    roots = np.linalg.eigvals(companion)
    x = _newton_polish(roots.real, f3, f2, f1, f0, steps=3)
    x = np.where(_is_real(roots.real, roots.imag), x, np.nan)
    close = np.abs(x[..., :, None] - x[..., None, :]) <= _TANGENT * np.abs(x[..., :, None])
    twins = np.sum(close, axis=-1) > 1
    first = np.argmax(close, axis=-1) == np.arange(SLOTS)  # keep one of each double root
    return np.where(twins & ~first, np.nan, x), twins


def _is_real(real_part, imag_part):
    """A root counts as real where its imaginary part is within :data:`_TANGENT` of its modulus: a double root
    splits by about sqrt(eps) into a complex pair."""
    return np.abs(imag_part) <= _TANGENT * np.maximum(np.hypot(real_part, imag_part), np.finfo(float).tiny)


def _newton_polish(x, f3, f2, f1, f0, steps: int, longest: float = 0.1):
    """``steps`` Newton steps on the roots ``x`` (..., 3) of the cubic; a step longer than ``longest`` times the
    root is not taken: near a double root the slope is rounding noise and so is the step.

    The closed form is within about 1e-14 of a simple root, so it takes ``longest`` = 1e-6; the companion
    matrix's eigenvalues took 0.1, which let an exact double root at 4 move to 4.087 (x^3 - 7x^2 + 8x + 16).
    """
    cf = [c[..., None] for c in (f3, f2, f1, f0)]
    for _ in range(steps):
        value = ((cf[0] * x + cf[1]) * x + cf[2]) * x + cf[3]
        slope = (3.0 * cf[0] * x + 2.0 * cf[1]) * x + cf[2]
        step = np.where(slope != 0, value / np.where(slope != 0, slope, 1.0), 0.0)
        x = x - np.where(np.abs(step) < longest * np.abs(x) + 1e-300, step, 0.0)
    return x


def _cubic_candidates(f3, f2, f1, f0):
    """The three roots of f3 x^3 + f2 x^2 + f1 x + f0 (f3 != 0) in closed form: real and imaginary parts, (..., 3).

    Monic and scaled by a power of two, x = 2^k z, so that the coefficients of z are at most about 1
    (exact, and no overflow when f3 is tiny). One real root r by the trigonometric or Cardano form
    (Press et al. [1]_, section 5.6: the root of largest modulus when all three are real), two Newton
    steps, then the deflation z^3 + a z^2 + b z + c = (z - r)(z^2 + beta z + gamma): backward
    (gamma = -c / r, beta = (gamma - b) / r) when r is the root of largest modulus, forward
    (beta = a + r, gamma = b + r beta) when it is the smallest, the stable direction of each
    (Wilkinson [2]_), and the quadratic by the cancellation-free formula. NaN where a coefficient
    is not finite.

    References
    ----------
    .. [1] Press WH, Teukolsky SA, Vetterling WT, Flannery BP (2007). Numerical Recipes, 3rd ed.
       Cambridge University Press. ISBN 978-0-521-88068-8.
    .. [2] Wilkinson JH (1963). Rounding Errors in Algebraic Processes. Prentice-Hall; chapter 2.
    """
    with np.errstate(all="ignore"):
        lead = np.where(f3 != 0, f3, 1.0)
        a, b, c, k = _scaled_monic(lead, f2, f1, f0)
        # f0 = 0 (S^2 = kp^2: the reflex just cancels gravity) makes z = 0 a root: exact, and deflated forward;
        # Cardano's form gives it as rounding noise, which backward deflation would divide by
        r = np.where(c == 0, 0.0, _one_real_root(a, b, c))
        for _ in range(2):
            value, slope = ((r + a) * r + b) * r + c, (3.0 * r + 2.0 * a) * r + b
            step = np.where(slope != 0, value / np.where(slope != 0, slope, 1.0), 0.0)
            r = r - np.where(np.abs(step) < 1e-6 * np.abs(r) + 1e-300, step, 0.0)
        backward = (np.abs(r) ** 3 >= np.abs(c)) & (r != 0)  # |r| at least the modulus of the other two
        gamma = np.where(backward, -c / r, b + r * (a + r))
        beta = np.where(backward, (gamma - b) / r, a + r)
        scale = np.ldexp(1.0, np.frexp(np.maximum(np.abs(beta), np.sqrt(np.abs(gamma))))[1])  # no underflow
        beta_, gamma_ = beta / scale, gamma / scale / scale
        disc = beta_ * beta_ - 4.0 * gamma_
        root = scale * np.sqrt(np.abs(disc))
        q = -0.5 * (beta + np.copysign(root, beta))
        pair = disc >= 0
        second = np.where(pair, q, -0.5 * beta)
        third = np.where(pair, np.where(q != 0, gamma / q, 0.0), -0.5 * beta)
        imag = np.where(pair, 0.0, 0.5 * root)
        finite = np.isfinite(f3) & np.isfinite(f2) & np.isfinite(f1) & np.isfinite(f0)
        real_part = np.ldexp(np.stack([r, second, third], axis=-1), k[..., None])
        imag_part = np.ldexp(np.stack([np.zeros_like(r), imag, -imag], axis=-1), k[..., None])
    nan = ~(finite[..., None] & np.isfinite(real_part) & np.isfinite(imag_part))
    return np.where(nan, np.nan, real_part), np.where(nan, np.nan, imag_part)


def _scaled_monic(f3, f2, f1, f0):
    """a, b, c of z^3 + a z^2 + b z + c with x = 2^k z, and k: 2^k within a factor of 2 of the largest of
    |f_j / f3|^(1 / (3 - j)), a bound on the roots' moduli (Fujiwara), from the binary exponents alone."""
    exponent = [np.where(f != 0, np.frexp(f)[1], -4096) for f in (f3, f2, f1, f0)]
    shift = [e - exponent[0] for e in exponent[1:]]
    k = np.maximum(np.maximum(shift[0], shift[1] // 2), shift[2] // 3)
    k = np.clip(k, -1100, 1100)  # f2 = f1 = f0 = 0 gives -4096: z^3, any scale does
    return np.ldexp(f2, -k) / f3, np.ldexp(f1, -2 * k) / f3, np.ldexp(f0, -3 * k) / f3, k


def _one_real_root(a, b, c):
    """A real root of z^3 + a z^2 + b z + c: of largest modulus if all three are real (trigonometric form),
    else the only one (Cardano's, with the sign that avoids cancellation); Press et al. 2007, section 5.6."""
    q = (a * a - 3.0 * b) / 9.0
    r = ((2.0 * a * a - 9.0 * b) * a + 27.0 * c) / 54.0
    q3 = q * q * q
    three = r * r < q3
    sq = np.sqrt(np.where(three, q, 0.0))
    angle = np.arccos(np.clip(r / np.where(three, sq * q, 1.0), -1.0, 1.0)) / 3.0
    shift = a / 3.0
    smallest = -2.0 * sq * np.cos(angle) - shift
    largest = -2.0 * sq * np.cos(angle + 2.0 * np.pi / 3.0) - shift
    trig = np.where(smallest + largest < 0, smallest, largest)
    big = -np.copysign(np.cbrt(np.abs(r) + np.sqrt(np.where(three, 0.0, r * r - q3))), r)
    cardano = big + np.where(big != 0, q / np.where(big != 0, big, 1.0), 0.0) - shift
    return np.where(three, trig, cardano)


@validated(zero_inertia=True)
def crossings(stiffness, damping, inertia, kp, kd, lag=0.0) -> Crossings:
    """Crossing frequencies, phases and directions of the delayed, lagged reflex loop.

    The positive roots x = w^2 of F (:func:`crossing_polynomial`): without the lag a quadratic,
    solved in closed form; with it a cubic (eigenvalues of its companion matrix, polished).
    w = 0 is never a crossing for kp != S: there exp(0) = 1 and Delta(0) = kp - S. The direction
    of a crossing is sign F'(w^2) [1]_ [2]_. A pair on the imaginary axis at tau = 0 (e.g.
    kd = D) crosses there: its phase is set to exactly 0.

    Parameters
    ----------
    stiffness, damping, inertia : array_like
        S [N m/rad], D [N m s/rad], theta [kg m^2].
    kp, kd : array_like
        Reflex gains [N m/rad], [N m s/rad].
    lag : array_like, optional
        Activation time constant T_a [s]; 0 is the pure delay.

    Returns
    -------
    Crossings
        Frequency [rad/s], phase [rad] and direction [1], each of shape (..., 3) with
        ``...`` the broadcast shape of the inputs; NaN in empty slots.

    References
    ----------
    .. [1] Cooke KL, Grossman Z (1982). Discrete delay, distributed delay and stability
       switches. J Math Anal Appl 86:592-627.
    .. [2] Cooke KL, van den Driessche P (1986). On zeroes of some transcendental
       equations. Funkcialaj Ekvacioj 29:77-90.
    """
    s, d, theta, kp, kd, lag = as_arrays(stiffness, damping, inertia, kp, kd, lag)
    return crossings_of(s, d, theta, kp, kd, lag, without_delay(s, d, theta, kp, kd, lag))


def crossings_of(s, d, theta, kp, kd, lag, free: WithoutDelay) -> Crossings:
    """:func:`crossings` of arrays of one shape, with their delay-free loop ``free`` (:func:`without_delay`) given.

    The vectorised maps (:func:`spinectl.reflex.maps.landscape`) find the crossings and the
    delay-free loop once per point and derive the exact margin, the Padé margin and the
    verdict at the delay from them.

    Parameters
    ----------
    s, d, theta, kp, kd, lag : numpy.ndarray
        As :func:`crossings`, float arrays of one shape (:func:`as_arrays`).
    free : WithoutDelay
        ``without_delay(s, d, theta, kp, kd, lag)``.

    Returns
    -------
    Crossings
        As :func:`crossings`.
    """
    x, direction = _positive_roots(*crossing_polynomial(s, d, theta, kp, kd, lag))
    with np.errstate(invalid="ignore"):
        w = np.sqrt(x)
    found = ~np.isnan(w)
    point = np.nonzero(found)[:-1]  # the phase only at the crossings, often a third of the slots
    theta_, d_, s_, lag_, kp_, kd_ = (v[point] for v in (theta, d, s, lag, kp, kd))
    jw = 1j * w[found]
    p = theta_ * jw**2 - d_ * jw - s_
    p = np.where(lag_ == 0, p, p * (1.0 + lag_ * jw))
    qq = kp_ + kd_ * jw
    phase = np.full(w.shape, np.nan)
    with np.errstate(divide="ignore", invalid="ignore"):
        phase[found] = np.mod(np.angle(-qq / p), 2.0 * np.pi)
    phase = np.where(_axis_slot(w, free.axis_frequency), 0.0, phase)
    return Crossings(frequency=w, phase=phase, direction=np.where(np.isnan(w), np.nan, direction))


def _axis_slot(frequency, axis_frequency):
    """The slot of each point whose crossing is the delay-free axis pair (at tau = 0), as a mask."""
    if not np.any(np.isfinite(axis_frequency)):  # no axis pair: the usual landscape
        return np.zeros(frequency.shape, bool)
    gap = np.abs(frequency - axis_frequency[..., None])
    gap = np.where(np.isnan(gap), np.inf, gap)
    nearest = np.argmin(gap, axis=-1)[..., None] == np.arange(frequency.shape[-1])
    return nearest & (gap <= 1e-6 * axis_frequency[..., None])


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
