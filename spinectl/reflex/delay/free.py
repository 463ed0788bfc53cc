"""The segment's loop without delay: its coefficients, Routh-Hurwitz verdict and the refusal of neutral loops.

The inputs broadcast to arrays, the check that the loop is of retarded type, and the
delay-free loop P + Q classified from the signs of its coefficients (docs/reflex.md,
"Boundary cases"); a pair on the imaginary axis at tau = 0 is followed to the side it leaves to.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import ParameterError
from ..inputs import validated


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
