"""Exact delay margin of the chain under a delayed multi-input PD reflex (docs/chain.md, "The delayed reflex").

The chain M q'' = K q + D q' + u (:func:`spinectl.model.chain.state_matrix`) under the reflex
command -(K_p q + K_d q')(t - tau), turned into the torque u by the force-generation lag
T_a u' + u = command at every joint, has the characteristic equation

    det(P(s) + Q(s) exp(-s tau)) = 0,   P(s) = (T_a s + 1)(M s^2 - D s - K),   Q(s) = K_p + K_d s,

the matrix form of the segment's P + Q exp(-s tau) (:mod:`spinectl.reflex.delay`); T_a = 0 is
the issue's det(M s^2 - D s - K + (K_p + K_d s) exp(-s tau)). A root lies on the imaginary
axis, s = j w, exactly where z = exp(-j w tau) is a generalised eigenvalue of the pencil
(P(jw), -Q(jw)) on the unit circle. The frequency sweep finds every such (w, z) independently
of tau: the number of eigenvalues w' = 1/z of -P(jw)^-1 Q(jw) outside the unit circle changes
exactly at a crossing, so bisection on that count brackets each crossing to rounding. The
delays are then tau = (-arg z + 2 pi k) / w, and the direction of each crossing is the sign
of Re ds/dtau from the null vectors of the characteristic matrix (implicit differentiation;
Michiels and Niculescu 2014, ch. 4 [1]_). The delay margin is the first destabilising critical
delay of a loop that is stable without delay, as for one segment (:mod:`spinectl.reflex.siso`,
whose result type :class:`~spinectl.reflex.siso.LoopDelayMargin` is returned).

The same crossings give the margin of the loop with the delay replaced by its [n/n] Padé
approximant: an all-pass whose phase lag :func:`~spinectl.reflex.pade.pade_phase_lag` (w tau)
must reach -arg z (:func:`pade_margin`).

References
----------
.. [1] Michiels W, Niculescu S-I (2014). Stability, Control, and Computation for Time-Delay
   Systems. An Eigenvalue-Based Approach. 2nd ed., SIAM, Philadelphia.
   doi:10.1137/1.9781611973631.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from ..errors import ParameterError
from ..model.linear_chain import LinearChain
from .delay import STATUS, UNDEFINED, UNSTABLE_WITHOUT_DELAY
from .pade import pade_inverse_lag
from .siso import LoopDelayMargin, from_crossings

DECADES = 7
"""Decades of frequency the sweep spans below the highest possible crossing (:func:`highest_crossing`)."""

POINTS_PER_DECADE = 1500
"""Sweep points per decade: 0.15 % apart, finer than the resonance of a mode with damping ratio 0.001."""


def _matrices(mass, stiffness, damping, kp, kd):
    """M, K, D as (n, n) float arrays and K_p, K_d as diagonal (n, n) ones; ParameterError naming a bad one."""
    mass, stiffness, damping = (np.asarray(x, float) for x in (mass, stiffness, damping))
    n = mass.shape[-1] if mass.ndim == 2 else -1
    for name, x in (("mass", mass), ("stiffness", stiffness), ("damping", damping)):
        if x.shape != (n, n):
            raise ParameterError(name, f"must be a square matrix like mass, {n} x {n} (got shape {x.shape})")
    gains = []
    for name, x in (("kp", kp), ("kd", kd)):
        x = np.asarray(x, float)
        x = np.full(n, float(x)) if x.ndim == 0 else x
        if x.shape != (n,):
            raise ParameterError(name, f"must be one gain per joint, {n} values (got shape {np.shape(x)})")
        gains.append(np.diag(x))
    return mass, stiffness, damping, gains[0], gains[1]


def characteristic_matrices(mass, stiffness, damping, kp, kd, omega, lag=0.0):
    """P(jw) = (T_a jw + 1)(-M w^2 - D jw - K) and Q(jw) = K_p + K_d jw.

    Parameters
    ----------
    mass, stiffness, damping : array_like, shape (n, n)
        M [kg m^2], K [N m/rad], D [N m s/rad].
    kp, kd : array_like, shape (n,)
        Diagonal reflex gains [N m/rad], [N m s/rad].
    omega : array_like, shape (m,)
        Frequencies [rad/s].
    lag : float, optional
        Activation time constant T_a [s].

    Returns
    -------
    p, q : numpy.ndarray, shape (m, n, n), complex
        [N m/rad].
    """
    mass, stiffness, damping, kp, kd = _matrices(mass, stiffness, damping, kp, kd)
    s = 1j * np.asarray(omega, float)[:, None, None]
    return (lag * s + 1.0) * (mass * s**2 - damping * s - stiffness), kp + kd * s


def delay_free_poles(mass, stiffness, damping, kp, kd, lag=0.0):
    """Roots of det(P(s) + Q(s)) = 0: the closed loop without delay [1/s].

    States (q, q', u) with M q'' = K q + D q' + u and T_a u' = -u - K_p q - K_d q'; without the
    lag (T_a = 0, u = -K_p q - K_d q') the eigenvalues of :func:`spinectl.model.chain.state_matrix`
    with K - K_p and D - K_d.

    Parameters
    ----------
    mass, stiffness, damping : array_like, shape (n, n)
        M [kg m^2], K [N m/rad], D [N m s/rad].
    kp, kd : array_like, shape (n,)
        Diagonal reflex gains [N m/rad], [N m s/rad].
    lag : float, optional
        Activation time constant T_a [s].

    Returns
    -------
    numpy.ndarray, shape (2 n,) or (3 n,), complex
        [1/s]: the finite generalised eigenvalues of the pencil (A, E) of the descriptor form
        E x' = A x, E = diag(I, M, T_a I), so that a tiny T_a needs no division by it.
    """
    mass, stiffness, damping, kp, kd = _matrices(mass, stiffness, damping, kp, kd)
    n = mass.shape[0]
    zero, one = np.zeros((n, n)), np.eye(n)
    a = np.block([[zero, one, zero], [stiffness, damping, one], [-kp, -kd, -one]])
    e = np.block([[one, zero, zero], [zero, mass, zero], [zero, zero, lag * one]])
    roots = scipy.linalg.eigvals(a, e)  # T_a = 0: n infinite eigenvalues, the lag's absent states
    return roots[np.isfinite(roots)]


def highest_crossing(mass, stiffness, damping, kp, kd) -> float:
    """An upper bound on every crossing frequency [rad/s].

    A crossing needs P(jw) v = -z Q(jw) v with abs(z) = 1, so sigma_min(P) <= sigma_max(Q);
    with sigma_min(P) >= lambda_min(M) w^2 - norm(D) w - norm(K) (spectral norms; abs(T_a jw + 1) >= 1)
    and sigma_max(Q) <= max k_p + max k_d w, no crossing lies above the positive root of
    lambda_min(M) w^2 - (norm(D) + max k_d) w - (norm(K) + max k_p).

    Parameters
    ----------
    mass, stiffness, damping : array_like, shape (n, n)
        M [kg m^2] (positive definite), K [N m/rad], D [N m s/rad].
    kp, kd : array_like, shape (n,)
        Diagonal reflex gains [N m/rad], [N m s/rad].

    Returns
    -------
    float
        [rad/s].
    """
    mass, stiffness, damping, kp, kd = _matrices(mass, stiffness, damping, kp, kd)
    a = np.linalg.eigvalsh(mass)[0]
    b = np.linalg.norm(damping, 2) + np.max(np.abs(kd))
    c = np.linalg.norm(stiffness, 2) + np.max(np.abs(kp))
    return float((b + np.sqrt(b * b + 4.0 * a * c)) / (2.0 * a))


def _inverse_eigenvalues(p, q):
    """Eigenvalues w' = 1/z of -P^-1 Q (finite where a joint has no reflex, unlike z), per frequency."""
    return np.linalg.eigvals(-np.linalg.solve(p, q))


def _crossings(mass, stiffness, damping, kp, kd, lag):
    """Every (w, z) with det(P(jw) + Q(jw) z) = 0, abs(z) = 1, w > 0: bisection on the count outside the circle."""
    top = highest_crossing(mass, stiffness, damping, kp, kd)
    grid = np.logspace(np.log10(top) - DECADES, np.log10(top), DECADES * POINTS_PER_DECADE + 1)

    def outside(omega):
        p, q = characteristic_matrices(mass, stiffness, damping, kp, kd, omega, lag)
        return np.sum(np.abs(_inverse_eigenvalues(p, q)) > 1.0, axis=-1)

    counts = outside(grid)
    found = []
    for i in np.flatnonzero(np.diff(counts)):
        lo, hi, below = grid[i], grid[i + 1], counts[i]
        while hi - lo > 4.0 * np.finfo(float).eps * hi:  # to rounding: about 50 halvings
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if outside(np.array([mid]))[0] == below else (lo, mid)
        w = 0.5 * (lo + hi)
        p, q = characteristic_matrices(mass, stiffness, damping, kp, kd, [w], lag)
        inverse = _inverse_eigenvalues(p, q)[0]
        near = np.abs(np.abs(inverse) - 1.0)
        # as many eigenvalues as the count changed by, nearest the circle first
        for j in np.argsort(near)[: max(1, abs(int(counts[i + 1]) - int(below)))]:
            found.append((w, 1.0 / inverse[j]))
    return found


def _direction(mass, stiffness, damping, kp, kd, lag, w, z) -> int:
    """sign Re ds/dtau at the root s = jw, tau = -arg z / w: +1 to the right as tau grows.

    T(s, tau) = P(s) + Q(s) e^{-s tau} is singular there with left and right null vectors u, v;
    ds/dtau = -(u^H dT/dtau v) / (u^H dT/ds v) (implicit differentiation of a simple eigenvalue).
    """
    mass, stiffness, damping, kp, kd = _matrices(mass, stiffness, damping, kp, kd)
    s = 1j * w
    tau = np.mod(-np.angle(z), 2.0 * np.pi) / w
    delay = np.exp(-s * tau)
    plant = mass * s**2 - damping * s - stiffness
    q = kp + kd * s
    t = (lag * s + 1.0) * plant + q * delay
    u_svd, _, vh = np.linalg.svd(t)
    left, right = u_svd[:, -1], vh[-1].conj()
    d_s = lag * plant + (lag * s + 1.0) * (2.0 * mass * s - damping) + (kd - tau * q) * delay
    d_tau = -s * q * delay
    rate = -(left.conj() @ d_tau @ right) / (left.conj() @ d_s @ right)
    return int(np.sign(np.round(rate.real, 12)))


def chain_delay_margin(mass, stiffness, damping, kp, kd, lag=0.0) -> LoopDelayMargin:
    """The exact delay margin of the chain under the delayed, lagged reflex (see the module).

    Parameters
    ----------
    mass, stiffness, damping : array_like, shape (n, n)
        M [kg m^2] (positive definite), K [N m/rad] and D [N m s/rad] of
        :func:`spinectl.model.chain.chain_coefficients` and :func:`~spinectl.model.chain.mass_matrix`.
    kp, kd : array_like, shape (n,)
        Diagonal reflex gains per joint [N m/rad], [N m s/rad].
    lag : float, optional
        Activation time constant T_a [s]; 0 the pure delay.

    Returns
    -------
    LoopDelayMargin
        ``margin`` [s] (inf, 0 or NaN as :data:`spinectl.reflex.STATUS`), ``frequency`` [rad/s] at
        which stability is lost, and every crossing: ``crossovers`` w [rad/s] (largest first),
        ``phases`` -arg z = w tau mod 2 pi [rad], ``directions`` (+1 destabilising).

    Raises
    ------
    ParameterError
        A matrix is not n x n, or the gains are not one per joint.

    References
    ----------
    .. [1] Michiels W, Niculescu S-I (2014). Stability, Control, and Computation for Time-Delay
       Systems. An Eigenvalue-Based Approach. 2nd ed., SIAM. doi:10.1137/1.9781611973631.
    """
    mass, stiffness, damping, kp_m, kd_m = _matrices(mass, stiffness, damping, kp, kd)
    empty = np.empty(0)
    values = (mass, stiffness, damping, kp_m, kd_m, lag)
    if not all(np.all(np.isfinite(x)) for x in values) or np.linalg.eigvalsh(mass)[0] <= 0:
        return LoopDelayMargin(np.nan, np.nan, STATUS[UNDEFINED], empty, empty, empty, False)
    kp, kd = np.diag(kp_m), np.diag(kd_m)
    poles = delay_free_poles(mass, stiffness, damping, kp, kd, lag)
    stable = bool(np.all(poles.real < -1e-12 * max(1.0, float(np.max(np.abs(poles))))))
    found = sorted(_crossings(mass, stiffness, damping, kp, kd, lag), key=lambda c: -c[0])
    w = np.array([c[0] for c in found])
    phases = np.array([np.mod(-np.angle(c[1]), 2.0 * np.pi) for c in found])
    directions = np.array([_direction(mass, stiffness, damping, kp, kd, lag, *c) for c in found], float)
    return from_crossings(w, phases, directions, stable)


def delay_margin_of(chain: LinearChain, kp, kd, lag=0.0, u=()) -> LoopDelayMargin:
    """:func:`chain_delay_margin` of any linearised chain at the controls ``u``: M, K(u), D(u).

    Parameters
    ----------
    chain : LinearChain
        The chain (:mod:`spinectl.model.linear_chain`); one fixed at an activation
        (:meth:`LinearChain.at`) has no controls, and ``u`` is then empty.
    kp, kd : array_like, shape (n,)
        Diagonal reflex gains per joint [N m/rad], [N m s/rad].
    lag : float, optional
        Activation time constant T_a [s]; 0 the pure delay.
    u : array_like, shape (m,)
        The controls [control unit].

    Returns
    -------
    LoopDelayMargin
        As :func:`chain_delay_margin`.

    References
    ----------
    .. [1] Michiels W, Niculescu S-I (2014). Stability, Control, and Computation for Time-Delay
       Systems. An Eigenvalue-Based Approach. 2nd ed., SIAM. doi:10.1137/1.9781611973631.
    """
    return chain_delay_margin(chain.mass_matrix, chain.stiffness(u), chain.damping(u), kp, kd, lag)


def pade_margin(exact: LoopDelayMargin, order: int) -> float:
    """The delay margin of the same loop with the delay as its [n/n] Padé approximant [s].

    The Padé all-pass has modulus 1, so its loop has the same crossings (w, z) as the true
    delay; it crosses where its phase lag reaches -arg z, at w tau =
    :func:`~spinectl.reflex.pade.pade_inverse_lag` (phi), never if phi >= n pi.

    Parameters
    ----------
    exact : LoopDelayMargin
        The crossings of :func:`chain_delay_margin` (or :func:`spinectl.reflex.siso.delay_margin`).
    order : int
        Order n of the approximant.

    Returns
    -------
    float
        [s]; 0 if unstable without delay, inf if no destabilising crossing is reached, NaN if undefined.
    """
    if exact.status in (STATUS[UNDEFINED], STATUS[UNSTABLE_WITHOUT_DELAY]):
        return float(exact.margin)
    destabilising = exact.directions > 0
    if not destabilising.any():
        return np.inf
    delays = pade_inverse_lag(exact.phases[destabilising], order) / exact.crossovers[destabilising]
    return float(np.min(delays))
