"""Exact delay margin of the chain under a delayed multi-input PD reflex (docs/chain.md, "The delayed reflex").

The chain M q'' = K q + D q' + u (:func:`spinectl.model.chain.state_matrix`) under the reflex
command -(K_p q + K_d q')(t - tau), turned into the torque u by the force-generation lag
T_a u' + u = command at every joint, has the characteristic equation

    det(P(s) + Q(s) exp(-s tau)) = 0,   P(s) = (T_a s + 1)(M s^2 - D s - K),   Q(s) = K_p + K_d s,

the matrix form of the segment's P + Q exp(-s tau) (:mod:`spinectl.reflex.delay`); T_a = 0 is
the issue's det(M s^2 - D s - K + (K_p + K_d s) exp(-s tau)). A root lies on the imaginary
axis, s = j w, exactly where z = exp(-j w tau) is a generalised eigenvalue of the pencil
(P(jw), -Q(jw)) on the unit circle. Every such w is an eigenvalue of an eigenvalue problem
that does not involve tau (Louisell 2001 [2]_, :func:`axis_candidates`): no frequency grid, so
no crossing band is too narrow to be found; each candidate is checked and refined on the
n x n pencil (an eigenvalue 1/z of -P(jw)^-1 Q(jw) of modulus 1 to :data:`UNIT_TOLERANCE`). The
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
.. [2] Louisell J (2001). A matrix method for determining the imaginary axis eigenvalues of a
   delay system. IEEE Trans Autom Control 46(12):2008-2012. doi:10.1109/9.975511.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from ..errors import ParameterError
from ..model.linear_chain import LinearChain
from .delay import STATUS, UNDEFINED, UNSTABLE_WITHOUT_DELAY
from .pade import pade_inverse_lag
from .siso import LoopDelayMargin, from_crossings

CANDIDATE_TOLERANCE = 1e-3
"""Eigenvalues s^2 of the squared Louisell matrix kept as candidates -w^2: abs(Im) <= this times abs(s^2), Re < 0."""

UNIT_TOLERANCE = 1e-9
"""A refined candidate is a crossing where some abs(z) is 1 to this (abs(log abs(z)))."""

SQUARED_ACCURACY = 1e-4
"""The squared problem is used where its relative error at the floor, eps rho^2 / w^2 (rho^2 its largest
abs(s^2)), is below this."""

FLOOR = 1e-7
"""Crossings are sought above this fraction of :func:`highest_crossing` (w -> 0 is a root at s = 0 for every tau)."""


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


def descriptor(mass, stiffness, damping, kp, kd, lag=0.0):
    """E, A_0, A_1 of the delayed chain E x' = A_0 x(t) + A_1 x(t - tau), x = (q, q', u) (u only if T_a > 0).

    M q'' = K q + D q' + u with T_a u' = -u - K_p q(t - tau) - K_d q'(t - tau); without the lag
    u = -K_p q(t - tau) - K_d q'(t - tau) and x = (q, q').

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
    e, a0, a1 : numpy.ndarray, shape (3 n, 3 n) or (2 n, 2 n)
        E [1, kg m^2, s], A_0 and A_1 [1/s, N m/rad, N m s/rad] by block.
    """
    mass, stiffness, damping, kp, kd = _matrices(mass, stiffness, damping, kp, kd)
    n = mass.shape[0]
    zero, one = np.zeros((n, n)), np.eye(n)
    if lag > 0:
        e = np.block([[one, zero, zero], [zero, mass, zero], [zero, zero, lag * one]])
        a0 = np.block([[zero, one, zero], [stiffness, damping, one], [zero, zero, -one]])
        a1 = np.block([[zero, zero, zero], [zero, zero, zero], [-kp, -kd, zero]])
    else:
        e = np.block([[one, zero], [zero, mass]])
        a0 = np.block([[zero, one], [stiffness, damping]])
        a1 = np.block([[zero, zero], [-kp, -kd]])
    return e, a0, a1


def axis_candidates(e, a0, a1, floor: float = 0.0) -> np.ndarray:
    """Every w > ``floor`` at which det(j w E - A_0 - z A_1) = 0 for some abs(z) = 1, among others [rad/s].

    If E v j w = (A_0 + z A_1) v with abs(z) = 1, the conjugate gives -j w E conj(v) =
    (A_0 + A_1 / z) conj(v) (A_0, A_1, E real), so x_1 = v (x) conj(v), x_2 = z x_1 solve
    s (E (x) I) x_1 = (A_0 (x) I) x_1 + (A_1 (x) I) x_2 and s (I (x) E) x_2 = -(I (x) A_1) x_1 - (I (x) A_0) x_2
    at s = j w: j w is an eigenvalue of Louisell's 2 m^2 pencil (Louisell 2001, [1]_). Its
    spectrum is symmetric, s and -s: J = [[0, Pi], [Pi, 0]] (Pi the vec-transpose permutation)
    anticommutes with it, so its square maps the vectors (y, Pi y) to themselves, where it is
    G H with H = B_0 (x) I + (B_1 (x) I) Pi, G = B_0 (x) I - (B_1 (x) I) Pi, B_i = E^-1 A_i: an
    m^2 eigenvalue problem for s^2 = -w^2, about ten times cheaper. Squaring squares the
    relative error, eps rho^2 / w^2; where that exceeds :data:`SQUARED_ACCURACY` at ``floor``
    (a tiny T_a: rho >= 1/T_a), the pencil itself by QZ (error eps rho / w). Candidates are the
    eigenvalues within :data:`CANDIDATE_TOLERANCE` of the axis; not every one is a crossing
    (the pencil holds every s with s and -s eigenvalues of A_0 + z A_1 and A_0 + A_1 / z for
    any complex z), which :func:`_crossings` checks.

    Parameters
    ----------
    e, a0, a1 : array_like, shape (m, m)
        E (nonsingular), A_0, A_1 of :func:`descriptor`.
    floor : float, optional
        The lowest frequency sought [rad/s].

    Returns
    -------
    numpy.ndarray
        Candidate frequencies w > ``floor`` [rad/s], ascending.

    References
    ----------
    .. [1] Louisell J (2001). A matrix method for determining the imaginary axis eigenvalues of a
       delay system. IEEE Trans Autom Control 46(12):2008-2012. doi:10.1109/9.975511.
    """
    e, a0, a1 = (np.asarray(x, float) for x in (e, a0, a1))
    m = e.shape[0]
    one = np.eye(m)
    b0, b1 = np.linalg.solve(e, a0), np.linalg.solve(e, a1)
    flip = np.arange(m * m).reshape(m, m).T.ravel()  # Pi: vec(X) -> vec(X^T)
    k0, k1 = np.kron(b0, one), np.kron(b1, one)[:, flip]
    mu = np.linalg.eigvals((k0 - k1) @ (k0 + k1))
    if np.finfo(float).eps * np.max(np.abs(mu)) <= SQUARED_ACCURACY * floor**2:
        keep = (mu.real < 0) & (np.abs(mu.imag) <= CANDIDATE_TOLERANCE * np.abs(mu))
        w = np.sqrt(-mu[keep].real)
    else:
        pencil = np.block([[np.kron(a0, one), np.kron(a1, one)], [-np.kron(one, a1), -np.kron(one, a0)]])
        s = scipy.linalg.eigvals(pencil, scipy.linalg.block_diag(np.kron(e, one), np.kron(one, e)))
        s = s[np.isfinite(s)]
        w = s[(s.imag > 0) & (np.abs(s.real) <= 0.5 * CANDIDATE_TOLERANCE * np.abs(s))].imag
    return np.sort(w[w > floor])


def _refine(moduli, w, target, steps: int = 12):
    """Secant on log abs(w') of the eigenvalue nearest ``target`` from w: (w, w') or None if it does not reach 1."""

    def g(x):
        values = moduli(x)
        nearest = values[np.argmin(np.abs(values - target))]
        return np.log(max(abs(nearest), 1e-300)), nearest

    x0, (g0, _) = w, g(w)
    x1 = w * (1.0 + 1e-9)
    g1, v1 = g(x1)
    for _ in range(steps):
        if g1 == g0 or abs(g1) < 1e-15:
            break
        x2 = x1 - g1 * (x1 - x0) / (g1 - g0)
        if not abs(x2 - w) <= 1e-3 * w:  # left the candidate's neighbourhood
            return None
        x0, g0 = x1, g1
        x1 = x2
        g1, v1 = g(x1)
        target = v1
    return (x1, v1) if abs(g1) <= UNIT_TOLERANCE else None


def _crossings(mass, stiffness, damping, kp, kd, lag):
    """Every (w, z) with det(P(jw) + Q(jw) z) = 0, abs(z) = 1, w > 0: Louisell's candidates, each refined."""
    floor = FLOOR * highest_crossing(mass, stiffness, damping, kp, kd)
    candidates = axis_candidates(*descriptor(mass, stiffness, damping, kp, kd, lag), floor)

    def moduli(w):
        p, q = characteristic_matrices(mass, stiffness, damping, kp, kd, [w], lag)
        return _inverse_eigenvalues(p, q)[0]

    found = []
    distinct = candidates[np.r_[True, np.diff(candidates) > 1e-9 * candidates[1:]]] if candidates.size else candidates
    for w in distinct:
        values = moduli(w)
        for v in values[np.abs(np.abs(values) - 1.0) < 0.05]:  # near the circle (0 where a joint has no reflex)
            hit = _refine(moduli, w, v)
            if hit is None or any(abs(hit[0] - f[0]) <= 1e-9 * f[0] and abs(hit[1] - f[1]) <= 1e-6 for f in found):
                continue
            # as many root pairs as eigenvalues there (a repeated crossing, e.g. two equal joints)
            copies = int(np.sum(np.abs(moduli(hit[0]) - hit[1]) <= 1e-6))
            found.extend([hit] * max(copies, 1))
    return [(w, 1.0 / v) for w, v in found]


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


def linear_chain_delay_margin(chain: LinearChain, kp, kd, lag=0.0, u=()) -> LoopDelayMargin:
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

    Examples
    --------
    The chain of :func:`spinectl.model.operating_point.chain_at`'s example, statically stable with local
    stiffness: without a reflex no delay destabilises it, a PD reflex on every joint does within 2 ms:

    >>> import numpy as np
    >>> from spinectl import load_preset
    >>> from spinectl.model.operating_point import OperatingPoint, chain_at
    >>> from spinectl.optimise.active_set import solve_point
    >>> from spinectl.reflex.mimo import linear_chain_delay_margin
    >>> model = load_preset("wagner2012")
    >>> point = OperatingPoint(model, 0.03, 0.04, solve_point(model, 0.03, 0.04).pcsa, 100.0, slip_check=False)
    >>> chain = chain_at(point)
    >>> linear_chain_delay_margin(chain, np.zeros(5), np.zeros(5)).status
    'delay_independent'
    >>> found = linear_chain_delay_margin(chain, np.full(5, 50.0), np.full(5, 5.0))
    >>> found.status, round(found.margin * 1e3, 1)  # [ms]
    ('finite', 1.4)
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
        The crossings of :func:`chain_delay_margin` (or :func:`spinectl.reflex.siso.loop_delay_margin`).
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
