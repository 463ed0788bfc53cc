"""The rightmost characteristic root of the chain under the delayed reflex: the design's independent check.

The exact delay margin (:func:`spinectl.reflex.mimo.chain_delay_margin`) decides whether a design meets a delay;
the rightmost root at that delay, found by Newton's method from seeds (the delay-free poles and, for the single
design's certificate, a spectral discretisation of the delay equation), is a second method on the same question
that shares none of its steps, reported beside it (docs/reflex.md, "The design question").
"""

from __future__ import annotations

import numpy as np

from ..mimo import delay_free_poles

MAX_EXPONENT = 700.0
"""Largest -Re(s) tau at which Newton's method on the characteristic determinant goes on: e^700 is near the
largest float (e^709.8); a root further left is never the rightmost."""

SPECTRAL_NODES = 24
"""Chebyshev nodes of the delay interval in the certificate's :func:`rightmost_root` (converged to 1e-12
against 96 nodes on the subject of docs/reflex.md, "The design question"); the search seeds it from poles alone."""


def rightmost_root(mass, stiffness, damping, kp, kd, delay: float, lag: float = 0.0, nodes: int = 0) -> complex:
    """The rightmost root of det((T_a s + 1)(M s^2 - D s - K) + (K_p + K_d s) e^{-s tau}) = 0 [1/s].

    Newton's method on the determinant (f / f' = 1 / trace(T^-1 T')) from seeds: the poles of
    the open loop and of the closed loop without delay (the roots a weak or slow reflex
    perturbs) and, with ``nodes`` > 0, the rightmost eigenvalues of the delayed chain
    x' = A_0 x(t) + A_1 x(t - tau), x = (q, q', u) (the lag's states u where T_a > 0),
    discretised by its infinitesimal generator on ``nodes`` Chebyshev nodes of [-tau, 0]
    (Breda, Maset and Vermiglio 2005). Each seed converges to a true root; the rightmost is returned.

    Parameters
    ----------
    mass, stiffness, damping : array_like, shape (n, n)
        M [kg m^2], K [N m/rad], D [N m s/rad].
    kp, kd : array_like, shape (n,)
        Diagonal gains [N m/rad], [N m s/rad].
    delay : float
        tau [s]; 0: the closed loop's poles without delay.
    lag : float
        T_a [s].
    nodes : int
        Chebyshev nodes of the discretisation; 0: the poles' seeds alone.

    Returns
    -------
    complex
        [1/s]; NaN where no seed converges.

    References
    ----------
    Breda D, Maset S, Vermiglio R (2005). Pseudospectral differencing methods for characteristic
    roots of delay differential equations. SIAM J Sci Comput 27(2):482-495.
    """
    m, k, d = (np.asarray(x, float) for x in (mass, stiffness, damping))
    if not delay > 0:  # no delay: the delay-free closed loop's poles
        poles = delay_free_poles(m, k, d, kp, kd, lag)
        return complex(poles[np.argmax(poles.real)])
    kp_m, kd_m = np.diag(np.asarray(kp, float)), np.diag(np.asarray(kd, float))
    n = m.shape[0]
    minv = np.linalg.inv(m)
    z = np.zeros((n, n))
    if lag > 0:
        a0 = np.block([[z, np.eye(n), z], [minv @ k, minv @ d, minv], [z, z, -np.eye(n) / lag]])
        a1 = np.block([[z, z, z], [z, z, z], [-kp_m / lag, -kd_m / lag, z]])
    else:
        a0 = np.block([[z, np.eye(n)], [minv @ k, minv @ d]])
        a1 = np.block([[z, z], [-minv @ kp_m, -minv @ kd_m]])
    none = np.zeros(n)
    seeds = [delay_free_poles(m, k, d, kp, kd, lag), delay_free_poles(m, k, d, none, none, lag)]
    if nodes > 0:
        dim = a0.shape[0]
        generator = np.kron(_chebyshev(nodes) * (2.0 / delay), np.eye(dim))  # theta_j = tau (x_j - 1) / 2
        generator[:dim, :] = 0.0
        generator[:dim, :dim] = a0
        generator[:dim, -dim:] = a1
        eigs = np.linalg.eigvals(generator)
        seeds.append(eigs[np.argsort(-eigs.real)][: 2 * dim])
    roots = [_newton(m, k, d, kp_m, kd_m, delay, lag, s) for s in np.concatenate(seeds)]
    roots = [r for r in roots if np.isfinite(r)]
    return complex(max(roots, key=lambda r: r.real)) if roots else complex(np.nan, np.nan)


def _chebyshev(n: int) -> np.ndarray:
    """Chebyshev differentiation matrix on x_j = cos(j pi / n), j = 0..n (Trefethen 2000, cheb)."""
    x = np.cos(np.pi * np.arange(n + 1) / n)
    c = np.ones(n + 1)
    c[0] = c[-1] = 2.0
    c *= (-1.0) ** np.arange(n + 1)
    dx = x[:, None] - x[None, :] + np.eye(n + 1)
    dmat = np.outer(c, 1.0 / c) / dx
    return dmat - np.diag(dmat.sum(axis=1))


def _newton(m, k, d, kp, kd, tau, lag, s, steps: int = 30):
    """Newton's method on det T(s) from ``s``; NaN if it does not converge.

    NaN too where it runs so far left that e^{-s tau} would overflow (Re s < -700 / tau): such a root,
    from a fast seed (the heavily damped modes of local muscles), is never the rightmost.
    """
    for _ in range(steps):
        if (-s * tau).real > MAX_EXPONENT:
            return complex(np.nan, np.nan)
        e = np.exp(-s * tau)
        plant = m * s**2 - d * s - k
        t = (lag * s + 1.0) * plant + (kp + kd * s) * e
        dt = lag * plant + (lag * s + 1.0) * (2.0 * m * s - d) + (kd - tau * (kp + kd * s)) * e
        try:
            step = 1.0 / np.trace(np.linalg.solve(t, dt))
        except np.linalg.LinAlgError:
            return s
        s = s - step
        if abs(step) <= 1e-12 * max(1.0, abs(s)):
            return s
    return complex(np.nan, np.nan)
