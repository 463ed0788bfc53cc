"""Crossing frequencies: the positive roots w^2 of F, where abs(Q(jw)) = abs(P(jw)).

F is quadratic in w^2 without the activation lag and cubic with it; its roots come from
the closed form polished by Newton steps (the companion matrix kept as the reference),
and the sign of F'(w^2) is the direction of the crossing [1]_ (docs/reflex.md, "Crossing
frequencies and the exact delay margin").

References
----------
.. [1] Cooke KL, Grossman Z (1982). Discrete delay, distributed delay and stability
   switches. J Math Anal Appl 86:592-627.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..inputs import validated
from .free import WithoutDelay, as_arrays, without_delay

SLOTS = 3
"""Crossing slots per point: F is at most cubic in w^2 (quadratic without the activation lag)."""

_TANGENT = 1e-7
"""Relative distance below which two roots of the cubic F are one double root (a tangency, direction 0)."""


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
