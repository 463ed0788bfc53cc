"""Exact delay margin of any SISO loop L(s) exp(-s tau) under unity negative feedback.

The closed loop 1 + L(s) exp(-s tau) = 0 with L = N/D rational and proper has the
characteristic quasi-polynomial D(s) + N(s) exp(-s tau), the segment's
P + Q exp(-s tau) of :mod:`spinectl.reflex.delay` with P = D and Q = N. Roots can reach
the imaginary axis only at the gain crossovers, the positive roots x = w^2 of the
polynomial F(x) = abs(D(jw))^2 - abs(N(jw))^2, and only at the delays
(phi + 2 pi k) / w with phi = arg(-L(jw)) mod 2 pi; the sign of F'(w^2) is the direction in
which they cross (Cooke and van den Driessche 1986 [1]_). The margin is the first
destabilising critical delay of a loop that is stable without delay (docs/reflex.md,
"The exact delay margin of any SISO loop").

A strictly proper L is of retarded type. A biproper one is of neutral type: covered
where abs(L(inf)) < 1 (the roots' asymptotic chains stay in the left half plane),
refused otherwise.

References
----------
.. [1] Cooke KL, van den Driessche P (1986). On zeroes of some transcendental
   equations. Funkcialaj Ekvacioj 29:77-90.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from .delay import DELAY_INDEPENDENT, FINITE, STATUS, UNDEFINED, UNSTABLE_WITHOUT_DELAY, delay_text

MAX_SPAN = 1e100
"""Largest ratio of the loop's coefficients in magnitude (the largest nonzero over the smallest).

The coefficients are scaled to at most 1 before any product (L = N/D is unchanged);
F(w^2) multiplies them in pairs, so a span of 1e100 keeps every product above 1e-200, far
from underflow. A wider span is a loop in units many orders of magnitude off."""

_REAL = 1e-8
"""Relative imaginary part below which a root of F counts as real (a double root splits by about sqrt(eps))."""


@dataclass(frozen=True)
class LoopDelayMargin:
    """The exact delay margin of a SISO loop, with every gain crossover.

    Attributes
    ----------
    margin : float
        The largest tau_m with the closed loop stable for every delay in [0, tau_m) [s]: inf
        (delay-independent), 0 (unstable without delay) or NaN (undefined), as :data:`STATUS`.
    frequency : float
        The crossover at which stability is lost [rad/s]; NaN if none.
    status : str
        One of :data:`spinectl.reflex.STATUS`.
    crossovers : numpy.ndarray
        Every w > 0 with abs(L(jw)) = 1 [rad/s], largest first.
    phases : numpy.ndarray
        phi = arg(-L(jw)) in [0, 2 pi) at each crossover [rad]: the delay adds w tau = phi (mod 2 pi).
    directions : numpy.ndarray
        sign F'(w^2) at each: +1 roots cross to the right as tau grows, -1 to the left, 0 a tangency.
    stable_without_delay : bool
        Every root of D + N in Re s < 0.
    """

    margin: float
    frequency: float
    status: str
    crossovers: np.ndarray
    phases: np.ndarray
    directions: np.ndarray
    stable_without_delay: bool

    def critical_delays(self, bound: float | None = None) -> list[tuple[float, float, int]]:
        """Every critical delay (phi + 2 pi k)/w below ``bound``, in increasing order.

        Parameters
        ----------
        bound : float, optional
            Largest delay [s]; four times the margin by default (ten seconds if it is not finite).

        Returns
        -------
        list of (float, float, int)
            (delay [s], crossover [rad/s], direction) for each passage of a root pair
            through the imaginary axis.
        """
        if bound is None:
            bound = 4.0 * self.margin if np.isfinite(self.margin) and self.margin > 0 else 10.0
        found = []
        for w, phi, direction in zip(self.crossovers, self.phases, self.directions, strict=True):
            k = np.arange(int(np.floor((bound * w - phi) / (2.0 * np.pi))) + 1) if bound * w >= phi else []
            found += [(float((phi + 2.0 * np.pi * i) / w), float(w), int(direction)) for i in k]
        return sorted(found)

    def to_dict(self) -> dict:
        """The result as a JSON-ready dict, the unit in each key's name.

        Returns
        -------
        dict
            ``delay_margin_s``, ``frequency_rad_s``, ``status``, ``stable_without_delay``, and
            ``crossovers`` (one dict each: ``frequency_rad_s``, ``phase_rad``, ``direction``).
        """
        return {
            "delay_margin_s": float(self.margin),
            "frequency_rad_s": float(self.frequency),
            "status": self.status,
            "stable_without_delay": self.stable_without_delay,
            "crossovers": [
                {"frequency_rad_s": float(w), "phase_rad": float(p), "direction": int(d)}
                for w, p, d in zip(self.crossovers, self.phases, self.directions, strict=True)
            ],
        }

    def table(self, bound: float | None = None) -> str:
        """The margin, its crossover and the critical delays below ``bound``, as text.

        Parameters
        ----------
        bound : float, optional
            As in :meth:`critical_delays`.

        Returns
        -------
        str
            A few lines, no final newline.
        """
        margin = delay_text(self.margin, 6)
        where = f" at {self.frequency:.6g} rad/s" if np.isfinite(self.frequency) else ""
        lines = [f"delay margin {margin}{where} ({self.status})"]
        delays = self.critical_delays(bound)
        lines += ["critical delays: none" if not delays else "critical delays [s]  crossover [rad/s]  direction"]
        lines += [
            f"{t:18.6g}  {w:17.6g}  {'+1 (destabilising)' if d > 0 else '-1 (stabilising)'}" for t, w, d in delays
        ]
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.table()


def _coefficients(loop):
    """Numerator and denominator of a SISO continuous-time loop, highest power first, leading zeros trimmed."""
    import control as ct  # here, not at import: python-control loads matplotlib

    if not isinstance(loop, (ct.TransferFunction, ct.StateSpace)):
        raise ParameterError(
            "loop", f"must be a python-control TransferFunction or StateSpace (got {type(loop).__name__})"
        )
    if loop.ninputs != 1 or loop.noutputs != 1:
        raise ParameterError("loop", f"must be SISO (got {loop.noutputs} outputs x {loop.ninputs} inputs)")
    if not loop.isctime():
        raise ParameterError("loop", "must be continuous-time (dt = 0)")
    tf = ct.tf(loop) if isinstance(loop, ct.StateSpace) else loop
    num, den = (np.trim_zeros(_real(c), "f") for c in (tf.num[0][0], tf.den[0][0]))
    if den.size == 0:
        raise ParameterError("loop", "has a zero denominator")
    if num.size > den.size:
        raise ParameterError("loop", f"must be proper, deg N <= deg D (got {num.size - 1} > {den.size - 1})")
    if num.size == den.size and abs(num[0]) >= abs(den[0]):
        raise ParameterError(
            "loop",
            f"is biproper with abs(L(inf)) = {abs(num[0] / den[0]):g} >= 1: of neutral type with root chains on or "
            "right of the imaginary axis for every delay > 0, not covered",
        )
    return num, den


def _real(coefficients) -> np.ndarray:
    """Coefficients as floats; complex ones refused (numpy would drop the imaginary part)."""
    c = np.atleast_1d(np.asarray(coefficients))
    if np.iscomplexobj(c):
        if np.any(c.imag != 0):
            raise ParameterError("loop", f"must have real coefficients (got {c.tolist()})")
        c = c.real
    try:
        return c.astype(float)
    except (TypeError, ValueError):
        raise ParameterError("loop", f"must have real numbers as coefficients (got {coefficients!r})") from None


def _scaled(num: np.ndarray, den: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """N and D divided by their largest coefficient (L unchanged), once their span is checked (:data:`MAX_SPAN`)."""
    both = np.abs(np.concatenate([num, den]))
    largest, smallest = both.max(), both[both > 0].min()
    if np.log10(largest) - np.log10(smallest) > np.log10(MAX_SPAN):  # in decades: a ratio could overflow
        raise ParameterError(
            "loop",
            f"has coefficients from {smallest:.3g} to {largest:.3g} in magnitude, a span over {MAX_SPAN:.0e}: "
            "are its time or gain units many orders of magnitude off?",
        )
    return num / largest, den / largest


def _magnitude_squared(p):
    """Coefficients in x = w^2 (highest first) of abs(p(jw))^2 = p(s) p(-s) at s = jw."""
    degree = p.size - 1
    mirrored = p * (-1.0) ** (degree - np.arange(p.size))  # p(-s)
    even = np.polymul(p, mirrored)[::-1][::2]  # coefficients of s^0, s^2, s^4, ...
    return (even * (-1.0) ** np.arange(even.size))[::-1]  # s^2m = (-x)^m


def crossover_polynomial(num, den):
    """F(x) = abs(D(jw))^2 - abs(N(jw))^2 in x = w^2, highest power first.

    Parameters
    ----------
    num, den : array_like
        N and D, highest power first.

    Returns
    -------
    numpy.ndarray
        The coefficients of F.
    """
    return np.polysub(_magnitude_squared(np.asarray(den, float)), _magnitude_squared(np.asarray(num, float)))


def _positive_roots(f):
    """Positive real roots of F (polished, largest first) and sign F' at each (0 for a double root)."""
    f = np.trim_zeros(f, "f")
    if f.size < 2:
        return np.empty(0), np.empty(0)
    roots = np.roots(f)
    x = roots.real[(np.abs(roots.imag) <= _REAL * np.abs(roots)) & (roots.real > 0)]
    slope = np.polyder(f)
    for _ in range(3):  # Newton polish of what the companion eigenvalues give
        d = np.polyval(slope, x)
        x = x - np.where(d != 0, np.polyval(f, x) / np.where(d != 0, d, 1.0), 0.0)
    x = np.sort(x)[::-1]
    double = np.abs(np.diff(x)) <= 1e-7 * x[1:]
    keep = np.concatenate([[True], ~double]) if x.size else x.astype(bool)
    tangent = np.concatenate([double, [False]]) if x.size else x.astype(bool)
    return x[keep], np.where(tangent[keep], 0.0, np.sign(np.polyval(slope, x[keep])))


def loop_delay_margin(loop) -> LoopDelayMargin:
    """Exact delay margin of a SISO loop L(s) in the loop L(s) exp(-s tau), unity negative feedback.

    Every gain crossover from F(x) = abs(D(jw))^2 - abs(N(jw))^2 = 0, the phase
    phi = arg(-L(jw)) mod 2 pi and the direction sign F'(w^2) at each; stability without
    delay from the roots of D + N; the margin is the first destabilising critical delay
    phi / w (docs/reflex.md, "The exact delay margin of any SISO loop"). Agrees with the
    closed form of a segment, :func:`spinectl.reflex.delay_margin`.

    Parameters
    ----------
    loop : control.TransferFunction or control.StateSpace
        L(s), SISO, continuous-time, proper (biproper only with abs(L(inf)) < 1).

    Returns
    -------
    LoopDelayMargin
        The margin [s], the crossover at it [rad/s], the status and every crossover with
        its phase [rad] and direction.

    Raises
    ------
    ParameterError
        Naming ``loop``: not a python-control system, not SISO, discrete-time, improper,
        of neutral type with abs(L(inf)) >= 1, with complex coefficients, or with coefficients
        spanning more than :data:`MAX_SPAN` in magnitude (finite ones are scaled first, so a
        loop of uniformly huge or tiny coefficients is computed).

    References
    ----------
    .. [1] Cooke KL, van den Driessche P (1986). On zeroes of some transcendental
       equations. Funkcialaj Ekvacioj 29:77-90.

    Examples
    --------
    The segment of :func:`spinectl.reflex.delay_margin`'s example as a loop, L(s) = (kd s + kp) / (theta s^2 - D s - S):

    >>> import control
    >>> from spinectl import loop_delay_margin
    >>> found = loop_delay_margin(control.tf([20.0, 150.0], [1.0, 5.0, -100.0]))
    >>> found.status, round(found.margin * 1e3, 1)  # [ms]
    ('finite', 88.3)
    """
    num, den = _coefficients(loop)
    empty = np.empty(0)
    if not (np.all(np.isfinite(num)) and np.all(np.isfinite(den))):
        return LoopDelayMargin(np.nan, np.nan, STATUS[UNDEFINED], empty, empty, empty, False)
    num, den = _scaled(num, den)
    closed = np.polyadd(den, num)
    poles = np.roots(closed)
    scale = max(1.0, float(np.max(np.abs(poles)))) if poles.size else 1.0
    stable = bool(np.all(poles.real < -1e-12 * scale))
    if num.size == 0:  # no loop: D alone, whatever the delay
        status = DELAY_INDEPENDENT if stable else UNSTABLE_WITHOUT_DELAY
        return LoopDelayMargin(np.inf if stable else 0.0, np.nan, STATUS[status], empty, empty, empty, stable)
    x, directions = _positive_roots(crossover_polynomial(num, den))
    w = np.sqrt(x)
    phases = np.mod(np.angle(-np.polyval(num, 1j * w) / np.polyval(den, 1j * w)), 2.0 * np.pi)
    return from_crossings(w, phases, directions, stable)


def from_crossings(crossovers, phases, directions, stable: bool) -> LoopDelayMargin:
    """The margin from the crossings: the first destabilising critical delay phi / w of a loop stable without delay.

    Shared by the SISO loop and the chain (:func:`spinectl.reflex.mimo.chain_delay_margin`).

    Parameters
    ----------
    crossovers : array_like, shape (m,)
        Crossing frequencies w > 0 [rad/s].
    phases : array_like, shape (m,)
        w tau mod 2 pi at each [rad].
    directions : array_like, shape (m,)
        +1 destabilising, -1 stabilising, 0 tangent.
    stable : bool
        Stable without delay.

    Returns
    -------
    LoopDelayMargin
    """
    w, phases, directions = (np.asarray(x, float).reshape(-1) for x in (crossovers, phases, directions))
    destabilising = directions > 0
    if not stable:
        margin, at, status = 0.0, np.nan, UNSTABLE_WITHOUT_DELAY
    elif not destabilising.any():
        margin, at, status = np.inf, np.nan, DELAY_INDEPENDENT
    else:
        first = np.where(destabilising, phases / np.where(w > 0, w, 1.0), np.inf)
        margin, at, status = float(first.min()), float(w[np.argmin(first)]), FINITE
    return LoopDelayMargin(margin, at, STATUS[status], w, phases, directions, stable)
