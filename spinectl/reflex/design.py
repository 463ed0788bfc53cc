"""The design question: how much intrinsic stiffness does a given reflex delay need? (``spinectl design``).

Two answers at one (E, Lambda), one per criterion (docs/reflex.md, "The design question"):

1. **joint by joint** (each CoR alone, the others fixed; the paper's criterion): the least
   co-contraction, the activation a (a fraction of the minimum stabilising PCSA, as
   ``margins --activation`` takes it), for which every segment's exact delay margin with
   the lag (:func:`spinectl.reflex.delay.delay_margin`) under the reflex rule at that
   activation is at least the delay. The margins are first scanned over a in [0, 1]
   (:data:`SCAN`); where every segment's margin is non-decreasing on the scan the search is a
   bisection in the bracket of the first scanned activation that meets the delay, and says
   so ('bisection: monotone on the scan'); otherwise the same bracket is refined by bisection and
   the method is 'scan and refine: not monotone'.
2. **the chain** (every CoR free): at the global activation ``reflex.activation`` (the
   operating point of ``spinectl margins``; ``--activation``), the
   least local stiffness f k* (k* the least local stiffness for static stability,
   problem (a) of docs/chain.md; the local muscles of "Local muscles as joint stiffness and
   damping", which damp the joint by c_loc f k*: with ``local.damping`` = 0 the global muscles
   give the chain's only damping, and activation 0 leaves it undamped)
   for which the chain under the delayed reflex is stable at the delay. The reflex is the
   rule on the chain (:func:`spinectl.reflex.gains.chain_gains`) scaled by the deficit left,
   (1 - f)+ times its gains (:func:`chain_loop_at`), or the explicit gains. The certificate:
   the exact multivariable delay margin (:func:`spinectl.reflex.mimo.chain_delay_margin`) at
   the returned design is at least the delay, and the rightmost characteristic root at the
   delay (:func:`rightmost_root`, a second method: a spectral discretisation of the delay
   equation) lies in the left half-plane. Both are required: the margin's frequency sweep
   (0.15 % steps) can step over the band of a crossing of a nearly undamped mode under a weak
   reflex (0.05 % wide at f = 0.9999 for the subject of docs/reflex.md, "The design
   question", without the local muscles' damping), which the spectral root does not miss. The
   search scans f, then bisects the bracket of the first f that meets the delay (exact for a set
   of designs that, once met, stays met for every larger f; the method says whether the scan
   showed that).

No design meets the delay: status 'infeasible' and the largest delay that the scan meets.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._threads import with_one_blas_thread
from ..model import chain, geometry
from ..model.checks import arithmetic_guard, checked_coefficients
from ..model.params import Model
from ..model.stability import criterion
from ..optimise.coupled import least_local_stiffness_stacked
from ..optimise.reference import solve_point
from ..units import m2_to_cm2
from . import gains
from .chain_margins import stable_at
from .delay import delay_margin
from .mimo import chain_delay_margin, delay_free_poles
from .siso import from_crossings

SCAN = 41
"""Activations scanned in [0, 1] (and local-stiffness fractions in [0, :data:`LOCAL_MAX`]) before the bisection."""

BISECTIONS = 20
"""Halvings of the bracket: the answer to 1e-6 of the scanned step above the least design."""

MAX_EXPONENT = 700.0
"""Largest -Re(s) tau at which Newton's method on the characteristic determinant goes on: e^700 is near the
largest float (e^709.8); a root further left is never the rightmost."""

LOCAL_MAX = 2.0
"""Largest local stiffness searched with explicit gains, as a multiple of the least for static stability k*
(the rule's reflex vanishes at 1 k*, where the search ends)."""

CHAIN_SCAN = 11
"""Local-stiffness fractions scanned in [0, :data:`LOCAL_MAX`] (each a rightmost root and an exact margin)."""

SPECTRAL_NODES = 24
"""Chebyshev nodes of the delay interval in the certificate's :func:`rightmost_root` (converged to 1e-12
against 96 nodes on the subject of docs/reflex.md, "The design question"); the search seeds it from poles alone."""


@dataclass(frozen=True)
class SegmentDesign:
    """One segment's least co-contraction, joint by joint.

    Attributes
    ----------
    name : str
    activation : float
        The least fraction of the minimum stabilising PCSA [1]; NaN if none in [0, 1].
    pcsa : float
        The total PCSA at that activation [m^2].
    delay_margin : float
        The segment's exact delay margin there [s].
    monotone : bool
        The margin is non-decreasing in the activation on the scan.
    """

    name: str
    activation: float
    pcsa: float
    delay_margin: float
    monotone: bool

    def to_dict(self) -> dict:
        """``name``, ``activation``, ``pcsa_cm2``, ``delay_margin_s``, ``monotone``.

        Returns
        -------
        dict
        """
        return {
            "name": self.name,
            "activation": self.activation,
            "pcsa_cm2": float(m2_to_cm2(self.pcsa)),
            "delay_margin_s": self.delay_margin,
            "monotone": self.monotone,
        }


@dataclass(frozen=True)
class ChainDesign:
    """The chain's least local stiffness at a global activation.

    Attributes
    ----------
    activation : float
        The global activation [1] (``reflex.activation``).
    fraction : float
        f: the local stiffness as a multiple of k* [1]; NaN if none up to :data:`LOCAL_MAX`.
    local_stiffness : numpy.ndarray, shape (n_cor,)
        f k* per joint [N m/rad].
    least_static : numpy.ndarray, shape (n_cor,)
        k* per joint [N m/rad].
    delay_margin : float
        The exact multivariable delay margin at the design [s].
    max_root_real : float
        Re of the rightmost characteristic root at the delay [1/s] (:func:`rightmost_root`).
    largest_delay : float
        The largest delay met by any local stiffness the search tried [s]: the largest exact margin
        there (with the design's own); inf (JSON null, "unbounded") when one is stable at every delay, e.g. the
        rule's f = 1, which has no reflex. The same meaning as :attr:`Design.largest_delay` joint by joint.
    method : str
    """

    activation: float
    fraction: float
    local_stiffness: np.ndarray
    least_static: np.ndarray
    delay_margin: float
    max_root_real: float
    largest_delay: float
    method: str

    def to_dict(self) -> dict:
        """``criterion``, ``activation``, ``local_stiffness_fraction``, ``local_stiffness_Nm_per_rad``, ....

        Returns
        -------
        dict
            Also ``least_static_local_stiffness_Nm_per_rad``, ``delay_margin_s``,
            ``max_root_real_per_s``, ``largest_delay_met_s`` and ``method``.
        """
        return {
            "criterion": criterion("chain", len(self.local_stiffness)),
            "activation": self.activation,
            "local_stiffness_fraction": self.fraction,
            "local_stiffness_Nm_per_rad": self.local_stiffness.tolist(),
            "least_static_local_stiffness_Nm_per_rad": self.least_static.tolist(),
            "delay_margin_s": self.delay_margin,
            "max_root_real_per_s": self.max_root_real,
            "largest_delay_met_s": self.largest_delay,
            "method": self.method,
        }


@dataclass(frozen=True)
class Design:
    """Both answers to the design question at one (E, Lambda) and delay.

    Attributes
    ----------
    eccentricity, lordosis : float
        E and Lambda [m].
    delay, activation_time_constant : float
        tau [s] and T_a [s].
    activation : float
        The least activation for every segment at once [1]; NaN if infeasible.
    pcsa : float
        Total PCSA at it [m^2].
    segments : tuple of SegmentDesign
    chain : ChainDesign
    status : str
        'ok'; 'infeasible' (joint by joint: no activation in [0, 1] meets the delay); 'chain_infeasible'
        (no local stiffness up to :data:`LOCAL_MAX` k*); or the optimum's status.
    largest_delay : float
        Joint by joint, the largest delay met by any activation on the scan of [0, 1] [s]: the largest over
        the scan of the smallest segment margin; inf (JSON null, "unbounded") when every segment is stable at
        every delay there. The chain's is :attr:`ChainDesign.largest_delay`.
    method : str
        How the activation was searched (see the module).
    model : dict
        The model's provenance and header line.
    """

    eccentricity: float
    lordosis: float
    delay: float
    activation_time_constant: float
    activation: float
    pcsa: float
    segments: tuple[SegmentDesign, ...]
    chain: ChainDesign
    status: str
    largest_delay: float
    method: str
    model: dict

    def to_dict(self) -> dict:
        """The document of ``spinectl design --json``.

        Returns
        -------
        dict
            The model's provenance, ``E_m``, ``Lambda_m``, ``delay_s``, ``activation_time_constant_s``,
            ``status``, ``criterion`` (joint by joint), ``activation``, ``pcsa_cm2``, ``method``,
            ``largest_delay_met_s``, ``segments`` (:meth:`SegmentDesign.to_dict`) and ``chain``
            (:meth:`ChainDesign.to_dict`).
        """
        model = {k: v for k, v in self.model.items() if k != "header"}
        return model | {
            "E_m": self.eccentricity,
            "Lambda_m": self.lordosis,
            "delay_s": self.delay,
            "activation_time_constant_s": self.activation_time_constant,
            "status": self.status,
            "criterion": criterion("joint", len(self.segments)),
            "activation": self.activation,
            "pcsa_cm2": float(m2_to_cm2(self.pcsa)),
            "method": self.method,
            "largest_delay_met_s": self.largest_delay,
            "segments": [s.to_dict() for s in self.segments],
            "chain": self.chain.to_dict(),
        }

    def table(self) -> str:
        """The design as readable text: both criteria, each with its answer and certificate.

        Returns
        -------
        str
            No final newline.
        """
        c = self.chain
        lines = [
            self.model.get("header", "preset unknown"),
            f"E = {self.eccentricity * 100:.2f} cm, Lambda = {self.lordosis * 100:.2f} cm, delay "
            f"{_delay(self.delay)}, activation lag {self.activation_time_constant * 1000:.4g} ms; "
            f"status {self.status}",
            "",
            f"{criterion('joint', len(self.segments))}: least co-contraction ({self.method})",
            f"{'segment':8} {'activation':>10} {'PCSA[cm2]':>10} {'tau_m[s]':>10}",
        ]
        lines += [
            f"{s.name:8} {_word(s.activation, 10, '.4f')} {_word(m2_to_cm2(s.pcsa), 10, '.2f')} "
            f"{_word(s.delay_margin, 10, '.4f')}"
            for s in self.segments
        ]
        lines += [
            (
                f"every segment at once: activation {self.activation:.4f} x minimum PCSA "
                f"({m2_to_cm2(self.pcsa):.2f} cm^2)"
                if np.isfinite(self.activation)
                else f"no activation in [0, 1] meets the delay at every segment; the largest delay met: "
                f"{_delay(self.largest_delay)}"
            ),
            "",
            f"{criterion('chain', len(c.local_stiffness))}: least local stiffness at activation "
            f"{_word(c.activation, 0, '.4f')} ({c.method})",
        ]
        if np.isfinite(c.fraction):
            lines += [
                "local stiffness [N m/rad]: "
                + ", ".join(f"{s.name} {k:.2f}" for s, k in zip(self.segments, c.local_stiffness, strict=True))
                + f"  ({c.fraction:.4f} x the least for static stability, total {np.sum(c.local_stiffness):.1f})",
                f"certificate: exact delay margin {_delay(c.delay_margin)} >= {_delay(self.delay)}; "
                f"rightmost root at the delay Re s = {_word(c.max_root_real, 0, '.4g')} 1/s",
            ]
        else:
            lines.append(f"no local stiffness meets the delay; the largest delay met: {_delay(c.largest_delay)}")
        return "\n".join(lines)

    def __bool__(self):
        raise TypeError(
            "the truth value of a Design is ambiguous: use design.status == 'ok' (both criteria met), or "
            "design.activation / design.chain.fraction (NaN where none meets the delay)"
        )


def _word(value: float, width: int, fmt: str) -> str:
    """A number, or 'none' (NaN) / 'unbounded' (inf), right-aligned in ``width``."""
    text = "none" if np.isnan(value) else ("unbounded" if np.isinf(value) else format(value, fmt))
    return f"{text:>{width}}"


def _delay(seconds: float) -> str:
    """A delay with its unit: ms below 1 s, s from 1 s; 'unbounded (delay-independent)' (inf), 'none' (NaN)."""
    if np.isnan(seconds):
        return "none"
    if np.isinf(seconds):
        return "unbounded (delay-independent)"
    return f"{seconds:.4g} s" if seconds >= 1.0 else f"{seconds * 1000:.4g} ms"


def segment_margins_at(model: Model, coefficients, optimum_pcsa, activations, kp=None, kd=None) -> np.ndarray:
    """Every segment's exact delay margin with the lag at each activation, shape (n_activations, n_cor) [s].

    Parameters
    ----------
    model : Model
        ``model.reflex``: gains (rule or explicit) and the lag T_a.
    coefficients : spinectl.model.mechanics.SegmentCoefficients
        At the position.
    optimum_pcsa : numpy.ndarray, shape (n_muscles,)
        The minimum stabilising PCSA [m^2].
    activations : array_like, shape (m,)
        Fractions of it [1].
    kp, kd : float, optional
        Explicit gains [N m/rad], [N m s/rad].

    Returns
    -------
    numpy.ndarray, shape (m, n_cor)
        [s]; inf where any delay is stable, 0 where unstable without delay.
    """
    a = np.asarray(activations, float)[:, None]
    pcsa = a * optimum_pcsa[None, :]
    s = np.stack([coefficients.stiffness(p) for p in pcsa])
    d = np.stack([coefficients.damping(p) for p in pcsa])
    theta = np.broadcast_to(coefficients.inertia, s.shape)
    kps, kds = gains.resolve_gains(s, d, theta, model.reflex, kp, kd)
    return np.asarray(delay_margin(s, d, theta, kps, kds, model.reflex.activation_time_constant).margin)


def _least(meets, scan: np.ndarray, ok: np.ndarray) -> float:
    """The least x with meets(x): the first scanned x that meets it (``ok``), refined by bisection in its bracket.

    NaN if no scanned x meets it.
    """
    if not ok.any():
        return np.nan
    i = int(np.argmax(ok))
    if i == 0:
        return float(scan[0])
    lo, hi = scan[i - 1], scan[i]
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if meets(mid) else (mid, hi)
    return float(hi)


def _nondecreasing(values: np.ndarray) -> np.ndarray:
    """True per column where the scanned values never fall (inf equal to inf), shape (n,)."""
    with np.errstate(invalid="ignore"):
        steps = np.diff(values, axis=0)
    return np.all((steps >= 0) | (values[1:] == values[:-1]), axis=0)


def joint_design(model: Model, eccentricity: float, lordosis: float, kp=None, kd=None):
    """Joint by joint: each segment's and the common least activation whose margins meet ``reflex.delay``.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    kp, kd : float, optional
        Explicit gains [N m/rad], [N m s/rad].

    Returns
    -------
    activation : float
        The least for every segment at once [1]; NaN if none in [0, 1].
    segments : tuple of SegmentDesign
    optimum_pcsa : numpy.ndarray
        The minimum stabilising PCSA [m^2] (NaN without an optimum).
    status : str
        'ok', 'infeasible' or the optimum's status.
    largest_delay : float
        The largest common delay met on the scan [s].
    method : str
    """
    e, lam = float(eccentricity), float(lordosis)
    coefficients = checked_coefficients(model, e, lam)
    optimum = solve_point(model, e, lam)
    names = model.geometry.cor_names
    delay = model.reflex.delay
    if not np.all(np.isfinite(optimum.pcsa)):
        nan = tuple(SegmentDesign(n, np.nan, np.nan, np.nan, False) for n in names)
        return np.nan, nan, optimum.pcsa, optimum.status, np.nan, "none: no optimum"
    p = np.asarray(optimum.pcsa, float)
    scan = np.linspace(0.0, 1.0, SCAN)
    with arithmetic_guard(e, lam):
        margins = segment_margins_at(model, coefficients, p, scan, kp, kd)
        monotone = _nondecreasing(margins)

        def meets(a, k=None):
            m = segment_margins_at(model, coefficients, p, [a], kp, kd)[0]
            return bool(np.all(m >= delay)) if k is None else bool(m[k] >= delay)

        segments = []
        for k, name in enumerate(names):
            a = _least(lambda x, k=k: meets(x, k), scan, margins[:, k] >= delay)
            margin = np.nan if np.isnan(a) else segment_margins_at(model, coefficients, p, [a], kp, kd)[0, k]
            total = a * p.sum() if np.isfinite(a) else np.nan
            segments.append(SegmentDesign(name, a, total, float(margin), bool(monotone[k])))
        activation = _least(meets, scan, np.all(margins >= delay, axis=1))
        feasible = np.isfinite(activation)
    method = "bisection: monotone on the scan" if monotone.all() else "scan and refine: not monotone"
    largest = float(np.max(np.min(margins, axis=1)))
    return activation, tuple(segments), p, ("ok" if feasible else "infeasible"), largest, method


def chain_matrices(model: Model, eccentricity: float, lordosis: float, pcsa):
    """M, K and D of the chain at a global PCSA [kg m^2], [N m/rad], [N m s/rad] (docs/chain.md).

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    pcsa : array_like, shape (n_muscles,)
        Global PCSA [m^2].

    Returns
    -------
    mass, stiffness, damping : numpy.ndarray, shape (n_cor, n_cor)
    """
    with arithmetic_guard(eccentricity, lordosis):
        coefficients = chain.chain_coefficients(model, eccentricity, lordosis)
        mass = chain.mass_matrix(model, geometry.cor_positions(eccentricity, lordosis, model.geometry))
        return mass, coefficients.stiffness(pcsa), coefficients.damping(pcsa)


def chain_loop_at(model: Model, mass, stiffness, damping, least_static, fraction, kp=None, kd=None):
    """The chain with local stiffness f k* and its damping, and its reflex gains: (1 - f)+ times the rule's.

    The rule on the chain (:func:`spinectl.reflex.gains.chain_gains`) at f = 0 compensates the
    whole deficit k*; as the local muscles take over a fraction f of it, the reflex keeps the
    rest, (1 - f)+ times both gains, so that at f >= 1 the chain holds itself without reflex.
    The local muscles damp what they stiffen: c_loc f k* on the diagonal of D
    (:func:`spinectl.model.chain.local_damping_per_stiffness`; docs/chain.md).

    Parameters
    ----------
    model : Model
    mass, stiffness, damping : numpy.ndarray, shape (n, n)
        M, K (global muscles, gravity, passive), D (global muscles).
    least_static : numpy.ndarray, shape (n,)
        k* [N m/rad].
    fraction : float
        f [1].
    kp, kd : float, optional
        Explicit gains for every joint.

    Returns
    -------
    stiffness : numpy.ndarray, shape (n, n)
        K - f diag(k*) [N m/rad].
    damping : numpy.ndarray, shape (n, n)
        D - c_loc f diag(k*) [N m s/rad].
    kp, kd : numpy.ndarray, shape (n,)
        [N m/rad], [N m s/rad].
    """
    k = stiffness - fraction * np.diag(least_static)
    d = damping - np.diag(chain.local_damping(fraction * np.asarray(least_static, float), model))
    scale = max(1.0 - fraction, 0.0)  # the reflex hands over to the local muscles: (1 - f)+ times the rule's gains
    p, dd = gains.resolve_chain_gains(model.reflex, mass, stiffness, damping, least_static, kp, kd, scale)
    return k, d, p, dd


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


def chain_design(model: Model, eccentricity: float, lordosis: float, pcsa, activation: float, kp=None, kd=None):
    """The chain: the least local stiffness f k* for which the delayed chain is stable at ``reflex.delay``.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    pcsa : numpy.ndarray, shape (n_muscles,)
        The global PCSA [m^2] (NaN: no design).
    activation : float
        Its fraction of the minimum stabilising PCSA [1], for the report.
    kp, kd : float, optional
        Explicit gains for every joint.

    Returns
    -------
    ChainDesign
    """
    n = len(model.geometry.cor_names)
    delay, lag = model.reflex.delay, model.reflex.activation_time_constant
    if not np.all(np.isfinite(pcsa)):
        nan = np.full(n, np.nan)
        return ChainDesign(activation, np.nan, nan, nan, np.nan, np.nan, np.nan, "none: no global activation")
    mass, stiffness, damping = chain_matrices(model, eccentricity, lordosis, pcsa)
    _, least = least_local_stiffness_stacked(stiffness[None], model.optimisation.stability_margin)
    least = least[0]
    margins = []  # the exact margins judge finds; a design that fails the delay has one below it

    def judge(f):
        """(meets, rightmost root, exact margin or None): the spectral root first, the exact margin where it is left.

        Each exact margin found is kept in ``margins`` for the largest delay met.
        """
        k, dl, p, dd = chain_loop_at(model, mass, stiffness, damping, least, f, kp, kd)
        with arithmetic_guard(eccentricity, lordosis):
            root = rightmost_root(mass, k, dl, p, dd, delay, lag)
            if not root.real < 0:
                return False, root, None
            if not (np.any(p) or np.any(dd)):  # no reflex: stable at every delay (no crossing to find)
                margins.append(np.inf)
                return True, root, from_crossings(np.empty(0), np.empty(0), np.empty(0), True)
            exact = chain_delay_margin(mass, k, dl, p, dd, lag)
        margins.append(float(exact.margin))
        return bool(stable_at(exact, delay) and exact.margin >= delay), root, exact

    top = 1.0 if model.reflex.gains == "rule" and kp is None and kd is None else LOCAL_MAX  # f >= 1: no reflex
    scan = np.linspace(0.0, top, CHAIN_SCAN)
    ok = np.array([judge(f)[0] for f in scan])
    upper = bool(np.all(ok[np.argmax(ok) :])) if ok.any() else True  # once met, met for every larger f
    method = "bisection: met for every larger fraction on the scan" if upper else "scan and refine: not monotone"
    fraction = _least(lambda f: judge(f)[0], scan, ok)
    if np.isnan(fraction):
        method = f"no fraction up to {top:g} met on the scan"
        largest = max(_chain_margin(model, mass, stiffness, damping, least, f, kp, kd, lag) for f in scan)
        nan = np.full(n, np.nan)
        return ChainDesign(activation, np.nan, nan, least, np.nan, np.nan, float(largest), method)
    _, _, exact = judge(fraction)
    k, dl, p, dd = chain_loop_at(model, mass, stiffness, damping, least, fraction, kp, kd)
    root = rightmost_root(mass, k, dl, p, dd, delay, lag, SPECTRAL_NODES)
    return ChainDesign(
        activation,
        fraction,
        fraction * least,
        least,
        float(exact.margin),
        float(root.real),
        float(max(margins)),  # met at the design, so at least its margin; larger fractions may meet more
        method,
    )


def _chain_margin(model, mass, stiffness, damping, least, fraction, kp, kd, lag) -> float:
    """The chain's exact delay margin at local stiffness f k* [s]; 0 if unstable without delay."""
    k, dl, p, dd = chain_loop_at(model, mass, stiffness, damping, least, fraction, kp, kd)
    exact = chain_delay_margin(mass, k, dl, p, dd, lag)
    return float(exact.margin) if exact.stable_without_delay else 0.0


@with_one_blas_thread
def design(model: Model, eccentricity: float, lordosis: float, kp=None, kd=None) -> Design:
    """Both answers to the design question at ``model.reflex.delay`` (see the module).

    Parameters
    ----------
    model : Model
        ``model.reflex``: delay, lag, gains (rule or explicit).
    eccentricity, lordosis : float
        E and Lambda [m].
    kp, kd : float, optional
        Explicit gains for every segment and joint [N m/rad], [N m s/rad].

    Returns
    -------
    Design

    Raises
    ------
    ParameterError
        E or Lambda out of range.
    """
    from ..model.source import header, provenance

    activation, segments, optimum, status, largest, method = joint_design(model, eccentricity, lordosis, kp, kd)
    pcsa = activation * optimum if np.isfinite(activation) else np.full_like(np.asarray(optimum, float), np.nan)
    at = model.reflex.activation  # the chain at the operating point of spinectl margins
    chain_answer = chain_design(
        model, float(eccentricity), float(lordosis), at * np.asarray(optimum, float), at, kp, kd
    )
    if status == "ok" and np.isnan(chain_answer.fraction):
        status = "chain_infeasible"
    return Design(
        eccentricity=float(eccentricity),
        lordosis=float(lordosis),
        delay=model.reflex.delay,
        activation_time_constant=model.reflex.activation_time_constant,
        activation=activation,
        pcsa=float(np.sum(pcsa)),
        segments=segments,
        chain=chain_answer,
        status=status,
        largest_delay=largest,
        method=method,
        model=provenance(model) | {"header": header(model)},
    )


CRISCO_LOAD = 88.0
"""The critical load of the ligamentous lumbar spine (L1 to the sacrum, no muscles) measured by Crisco et al.
(1992) [N]; the load stood on L1, at the top of the modelled spine."""

PAPER_PASSIVE = 15.0
"""The paper's passive stiffness per joint [N m/rad] (Wagner et al. 2012), marked on the passive-stiffness curve."""

THRESHOLD_TOLERANCE = 0.01
"""Width of the bracket of the least passive stiffness at which global muscles alone suffice [N m/rad]."""


def crisco_stiffness(model: Model, eccentricity: float, lordosis: float, load: float = CRISCO_LOAD) -> float:
    """The passive stiffness per joint at which the chain without muscles buckles under ``load`` at the spine's top.

    The passive chain (no muscles, no other weight) under a vertical load W on the top of the spine
    (y = ``geometry.spine_length``, L1, where Crisco et al. 1992 loaded their specimens) has
    K = K_g(W) - k I with the gravity stiffness K_g of docs/chain.md; it is statically stable
    iff k I - K_g is positive definite, so it buckles at k = lambda_max(K_g(W)), the same k at
    every joint (the physical convention).

    Parameters
    ----------
    model : Model
        Supplies the geometry and the gravity sign.
    eccentricity, lordosis : float
        E and Lambda [m].
    load : float
        W [N].

    Returns
    -------
    float
        [N m/rad] per joint.

    References
    ----------
    Crisco JJ, Panjabi MM, Yamamoto I, Oxland TR (1992). Euler stability of the human ligamentous
    lumbar spine. Part II: Experiment. Clin Biomech 7(1):27-32. doi:10.1016/0268-0033(92)90004-N.
    """
    loaded = passive_chain_model(model, load)
    gravity = chain.chain_coefficients(loaded, float(eccentricity), float(lordosis)).gravity_stiffness
    return float(np.linalg.eigvalsh(gravity)[-1])


def passive_chain_model(model: Model, load: float = CRISCO_LOAD, stiffness: float = 0.0) -> Model:
    """The model of Crisco's specimen: the load W on the spine's top, the levels weightless, passive stiffness k.

    Parameters
    ----------
    model : Model
    load : float
        W [N].
    stiffness : float
        k per joint [N m/rad], physical convention.

    Returns
    -------
    Model
    """
    from ..model import config

    return config.set_parameters(
        model,
        {
            "body.mass": load / model.body.gravity,
            "body.mass_height": model.geometry.spine_length,
            "levels.weight_in_gravity": 0.0,
            "passive.stiffness": stiffness,
            "passive.convention": "physical",
        },
    )


@dataclass(frozen=True)
class PassiveCurve:
    """The chain's verdicts against the passive stiffness per joint, at one (E, Lambda).

    Attributes
    ----------
    eccentricity, lordosis : float
        E and Lambda [m].
    passive_stiffness : numpy.ndarray, shape (m,)
        K per joint [N m/rad] (``passive.stiffness``, physical convention).
    global_pcsa : numpy.ndarray, shape (m,)
        The least total global PCSA for the chain's static stability without local muscles,
        problem (b) of docs/chain.md [m^2]; NaN where none can.
    global_status : tuple of str
    local_stiffness : numpy.ndarray, shape (m, n_cor)
        The least local stiffness per joint at the fixed global PCSA ``paper_pcsa``, problem (a)
        [N m/rad]; NaN without an optimum or a solution.
    paper_pcsa : float
        The global PCSA held fixed: the paper's (joint-by-joint) minimum at the model's own passive
        stiffness [m^2], so that the curve shows the passive stiffness alone.
    fixed_pcsa : numpy.ndarray, shape (n_muscles,)
        Its distribution over the muscles [m^2]. ``global_pcsa`` has another, problem (b)'s own at each K:
        the two columns are not at the same muscles (:meth:`columns_note`).
    threshold : float
        The least K at which global muscles alone stabilise the chain [N m/rad], by bisection on
        the feasibility of (b) to :data:`THRESHOLD_TOLERANCE`; NaN if not in the scanned range.
    crisco : float
        The K at which the passive chain buckles under Crisco et al.'s 88 N (:func:`crisco_stiffness`) [N m/rad].
    crisco_global_pcsa : float
        The least global PCSA alone at K = ``crisco`` [m^2]; NaN if none.
    model : dict
        Provenance and header line.
    """

    eccentricity: float
    lordosis: float
    passive_stiffness: np.ndarray
    global_pcsa: np.ndarray
    global_status: tuple[str, ...]
    local_stiffness: np.ndarray
    paper_pcsa: float
    fixed_pcsa: np.ndarray
    threshold: float
    crisco: float
    crisco_global_pcsa: float
    model: dict

    def to_dict(self) -> dict:
        """The document of ``spinectl design --passive ... --json``.

        Returns
        -------
        dict
            Provenance, ``criterion`` (the chain), ``E_m``, ``Lambda_m``, ``passive_stiffness_Nm_per_rad``,
            ``global_pcsa_cm2``, ``global_status``, ``local_stiffness_Nm_per_rad`` (per point, per joint),
            ``local_stiffness_total_Nm_per_rad``, ``local_at_global_pcsa_cm2``, ``global_alone_from_Nm_per_rad``,
            ``crisco_stiffness_Nm_per_rad``, ``crisco_load_N``, ``crisco_global_pcsa_cm2``,
            ``local_at_pcsa_per_muscle_cm2`` (muscle name -> PCSA) and ``columns_note`` (:meth:`columns_note`).
        """
        model = {k: v for k, v in self.model.items() if k not in ("header", "muscles")}
        return model | {
            "criterion": criterion("chain", self.local_stiffness.shape[1]),
            "E_m": self.eccentricity,
            "Lambda_m": self.lordosis,
            "passive_stiffness_Nm_per_rad": self.passive_stiffness.tolist(),
            "global_pcsa_cm2": m2_to_cm2(self.global_pcsa).tolist(),
            "global_status": list(self.global_status),
            "local_stiffness_Nm_per_rad": self.local_stiffness.tolist(),
            "local_stiffness_total_Nm_per_rad": self.local_stiffness.sum(axis=1).tolist(),
            "local_at_global_pcsa_cm2": float(m2_to_cm2(self.paper_pcsa)),
            "global_alone_from_Nm_per_rad": self.threshold,
            "crisco_stiffness_Nm_per_rad": self.crisco,
            "crisco_load_N": CRISCO_LOAD,
            "crisco_global_pcsa_cm2": float(m2_to_cm2(self.crisco_global_pcsa)),
            "local_at_pcsa_per_muscle_cm2": dict(
                zip(self.model.get("muscles", ()), m2_to_cm2(self.fixed_pcsa).tolist(), strict=False)
            ),
            "columns_note": self.columns_note(),
        }

    def columns_note(self) -> str:
        """Which global PCSA, in which distribution, each column is at.

        Returns
        -------
        str
            One line: the global-alone column is problem (b)'s least distribution at each K, the local
            column the paper's joint-by-joint minimum held fixed, which is not the chain's best.
        """
        return (
            "note: 'global alone' is problem (b)'s own least distribution at each K (its total); 'sum local k' "
            f"is at the paper's joint-by-joint minimum, {_word(m2_to_cm2(self.paper_pcsa), 0, '.2f')} cm^2 held "
            "fixed in its own distribution, which is not the chain's best: a larger total can need local stiffness "
            "where a smaller one alone suffices"
        )

    def table(self) -> str:
        """The curve as rows, with the threshold and Crisco's stiffness.

        Returns
        -------
        str
            No final newline.
        """
        n = self.local_stiffness.shape[1]
        lines = [
            self.model.get("header", "preset unknown"),
            f"{criterion('chain', n)}: static stability against the passive stiffness per joint, "
            f"E = {self.eccentricity * 100:.2f} cm, Lambda = {self.lordosis * 100:.2f} cm",
            f"least local stiffness at a fixed global PCSA of {_word(m2_to_cm2(self.paper_pcsa), 0, '.2f')} cm^2 "
            "(the paper's minimum at the model's passive stiffness)",
            self.columns_note(),
            f"{'K[N m/rad]':>10} {'global alone[cm2]':>17} {'sum local k[N m/rad]':>20}",
        ]
        lines += [
            f"{k:10.2f} {_word(m2_to_cm2(g), 17, '.2f')} {_word(float(np.sum(loc)), 20, '.1f')}"
            for k, g, loc in zip(self.passive_stiffness, self.global_pcsa, self.local_stiffness, strict=True)
        ]
        lines += [
            f"global muscles alone stabilise the chain from K = {_word(self.threshold, 0, '.2f')} N m/rad per joint"
            + ("" if np.isfinite(self.threshold) else " (not in the scanned range)"),
            f"Crisco et al. 1992 ({CRISCO_LOAD:g} N buckles the passive chain): K = {self.crisco:.2f} N m/rad per "
            f"joint; there "
            + (
                f"global muscles alone need {m2_to_cm2(self.crisco_global_pcsa):.2f} cm^2"
                if np.isfinite(self.crisco_global_pcsa)
                else "no global PCSA alone stabilises the chain"
            ),
        ]
        return "\n".join(lines)


@with_one_blas_thread
def passive_curve(model: Model, eccentricity: float, lordosis: float, stiffnesses) -> PassiveCurve:
    """The least global PCSA and the least local stiffness for the chain against the passive stiffness.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    stiffnesses : array_like, shape (m,)
        Passive stiffness per joint [N m/rad], >= 0 (physical convention).

    Returns
    -------
    PassiveCurve

    Raises
    ------
    ParameterError
        A stiffness negative or not finite; E or Lambda out of range.
    """
    from ..errors import ParameterError
    from ..model.source import origin, provenance

    ks = np.asarray(stiffnesses, float).ravel()
    if ks.size == 0 or not np.all(np.isfinite(ks) & (ks >= 0)):
        raise ParameterError("--passive", f"must be finite stiffnesses >= 0 N m/rad (got {ks.tolist()})")
    e, lam = float(eccentricity), float(lordosis)
    optimum = np.asarray(solve_point(model, e, lam).pcsa, float)
    points = [_passive_point(model, e, lam, k, optimum) for k in ks]
    feasible = np.array([np.isfinite(p[0]) for p in points])
    threshold = _threshold(model, e, lam, ks, feasible)
    crisco = crisco_stiffness(model, e, lam)
    return PassiveCurve(
        eccentricity=e,
        lordosis=lam,
        passive_stiffness=ks,
        global_pcsa=np.array([p[0] for p in points]),
        global_status=tuple(p[1] for p in points),
        local_stiffness=np.array([p[2] for p in points]),
        paper_pcsa=float(np.sum(optimum)),
        fixed_pcsa=optimum,
        threshold=threshold,
        crisco=crisco,
        crisco_global_pcsa=_global_alone(model, e, lam, crisco).total_pcsa,
        # K is swept: the header names the origin, not the model's own K
        model=provenance(model)
        | {"header": f"{origin(model)}; K swept, physical convention", "muscles": tuple(model.muscle_names)},
    )


def _physical(model: Model, k: float) -> Model:
    """``model`` with passive stiffness k per joint, physical convention."""
    from ..model import config

    return config.set_parameters(model, {"passive.stiffness": float(k), "passive.convention": "physical"})


def _global_alone(model: Model, e: float, lam: float, k: float):
    """Problem (b) at passive stiffness k."""
    from ..optimise.coupled.global_pcsa import min_global_pcsa

    return min_global_pcsa(_physical(model, k), e, lam)


def _passive_point(model: Model, e: float, lam: float, k: float, optimum: np.ndarray):
    """(global PCSA alone [m^2], its status, least local stiffness at the global PCSA ``optimum`` [N m/rad])."""
    from ..optimise.coupled.local import least_local_stiffness

    alone = _global_alone(model, e, lam, k)
    local = np.full(len(model.geometry.cor_names), np.nan)
    if np.all(np.isfinite(optimum)):
        local = least_local_stiffness(_physical(model, k), e, lam, optimum, given=False).local_stiffness
    return alone.total_pcsa, alone.status, np.asarray(local, float)


def _threshold(model: Model, e: float, lam: float, ks: np.ndarray, feasible: np.ndarray) -> float:
    """The least K where (b) is feasible: bisection between the scan's last infeasible and first feasible K."""
    order = np.argsort(ks)
    ks, feasible = ks[order], feasible[order]
    if not feasible.any():
        return np.nan
    i = int(np.argmax(feasible))
    if i == 0:
        return float(ks[0])
    lo, hi = float(ks[i - 1]), float(ks[i])
    while hi - lo > THRESHOLD_TOLERANCE:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if np.isfinite(_global_alone(model, e, lam, mid).total_pcsa) else (mid, hi)
    return hi


REACTION_TIMES = (
    (0.053, "healthy, agonists off (Radebold et al. 2000)"),
    (0.070, "healthy, antagonists on; patients, agonists off"),
)
"""Trunk muscles' reaction times after a sudden load release [s], with labels: Radebold et al. (2000), 17 healthy
subjects (shut-off of the agonists 53 ms, switch-on of the antagonists 70 ms) and 17 patients with chronic low back
pain (shut-off 70 ms), averaged over trials and directions; doi:10.1097/00007632-200004150-00009."""


@dataclass(frozen=True)
class DesignCurve:
    """The design question against the delay (and the lag), both criteria, at one (E, Lambda).

    Leading dimensions (n_lags, n_delays); NaN where no design meets the delay.

    Attributes
    ----------
    eccentricity, lordosis : float
        E and Lambda [m].
    delays : numpy.ndarray, shape (n_delays,)
        tau, ascending [s].
    lags : numpy.ndarray, shape (n_lags,)
        T_a [s].
    activation : numpy.ndarray
        Joint by joint: the least activation for every segment at once [1].
    segment_activation : numpy.ndarray, shape (n_lags, n_delays, n_cor)
        Each segment's own least activation [1].
    pcsa : numpy.ndarray
        The total PCSA at ``activation`` [m^2].
    chain_activation : float
        The chain's global activation (``reflex.activation``) [1].
    local_fraction : numpy.ndarray
        The chain: the least local stiffness as a multiple f of k* [1].
    local_stiffness : numpy.ndarray, shape (n_lags, n_delays, n_cor)
        f k* per joint [N m/rad].
    chain_margin : numpy.ndarray
        The exact multivariable delay margin at the chain's design [s] (>= the delay: the certificate).
    max_root_real : numpy.ndarray
        Re of the rightmost characteristic root found at the delay from the poles' seeds [1/s]
        (:func:`rightmost_root` with ``nodes`` = 0).
    names : tuple of str
    model : dict
    """

    eccentricity: float
    lordosis: float
    delays: np.ndarray
    lags: np.ndarray
    activation: np.ndarray
    segment_activation: np.ndarray
    pcsa: np.ndarray
    chain_activation: float
    local_fraction: np.ndarray
    local_stiffness: np.ndarray
    chain_margin: np.ndarray
    max_root_real: np.ndarray
    names: tuple[str, ...]
    model: dict

    def to_dict(self) -> dict:
        """The document of ``spinectl design --delays ... --json``.

        Returns
        -------
        dict
            Provenance, ``E_m``, ``Lambda_m``, ``delays_s``, ``reaction_times_s``, and ``curves``: one per lag
            with ``activation_time_constant_s``, ``joint`` (``criterion``, ``activation``, ``pcsa_cm2``,
            ``segments``: name and activation per delay) and ``chain`` (``criterion``, ``activation``,
            ``local_stiffness_fraction``, ``local_stiffness_Nm_per_rad``, ``local_stiffness_total_Nm_per_rad``,
            ``delay_margin_s``, ``max_root_real_per_s``).
        """
        model = {k: v for k, v in self.model.items() if k != "header"}
        n = len(self.names)
        curves = []
        for i, lag in enumerate(self.lags):
            joint = {
                "criterion": criterion("joint", n),
                "activation": self.activation[i].tolist(),
                "pcsa_cm2": m2_to_cm2(self.pcsa[i]).tolist(),
                "segments": [
                    {"name": name, "activation": self.segment_activation[i, :, k].tolist()}
                    for k, name in enumerate(self.names)
                ],
            }
            chain_part = {
                "criterion": criterion("chain", n),
                "activation": self.chain_activation,
                "local_stiffness_fraction": self.local_fraction[i].tolist(),
                "local_stiffness_Nm_per_rad": self.local_stiffness[i].tolist(),
                "local_stiffness_total_Nm_per_rad": self.local_stiffness[i].sum(axis=1).tolist(),
                "delay_margin_s": self.chain_margin[i].tolist(),
                "max_root_real_per_s": self.max_root_real[i].tolist(),
            }
            curves.append({"activation_time_constant_s": float(lag), "joint": joint, "chain": chain_part})
        return model | {
            "E_m": self.eccentricity,
            "Lambda_m": self.lordosis,
            "delays_s": self.delays.tolist(),
            "reaction_times_s": [{"delay_s": t, "label": label} for t, label in REACTION_TIMES],
            "curves": curves,
        }

    def table(self) -> str:
        """The curves as rows per lag: both criteria's required design per delay.

        Returns
        -------
        str
            No final newline.
        """
        n = len(self.names)
        lines = [
            self.model.get("header", "preset unknown"),
            f"E = {self.eccentricity * 100:.2f} cm, Lambda = {self.lordosis * 100:.2f} cm; joint by joint: "
            f"{criterion('joint', n)}; chain: {criterion('chain', n)} at activation {self.chain_activation:.4g}",
        ]
        for i, lag in enumerate(self.lags):
            lines += [
                "",
                f"activation lag T_a = {lag * 1000:.4g} ms",
                f"{'delay[ms]':>9} {'joint: activation':>17} {'PCSA[cm2]':>10} {'chain: sum k[N m/rad]':>21} "
                f"{'x k*':>7} {'tau_m[ms]':>10}",
            ]
            lines += [
                f"{d * 1000:9.4g} {_word(self.activation[i, j], 17, '.4f')} "
                f"{_word(m2_to_cm2(self.pcsa[i, j]), 10, '.2f')} "
                f"{_word(float(np.sum(self.local_stiffness[i, j])), 21, '.1f')} "
                f"{_word(self.local_fraction[i, j], 7, '.4f')} {_word(self.chain_margin[i, j] * 1000, 10, '.4g')}"
                for j, d in enumerate(self.delays)
            ]
        return "\n".join(lines)


@with_one_blas_thread
def delay_curve(model: Model, eccentricity: float, lordosis: float, delays, lags=None, kp=None, kd=None) -> DesignCurve:
    """Both criteria's required design against the delay, for each lag: the design curve.

    Joint by joint, each delay's least activations are bisected together (one vectorised margin call per
    halving for all delays) in the brackets of the activation scan, whose margins do not depend on the
    delay. The chain's least local stiffness is nondecreasing in the delay (a design that meets a delay
    meets every shorter one), so each delay starts from the previous delay's answer: if that meets the
    delay it is the answer; otherwise the bracket from it to the top of the search is narrowed by a
    safeguarded inverse interpolation of the exact margins (:func:`_bracket_root`), to the bisection's
    precision and with its certificate. The exact delay margin at each fraction is computed once (it does
    not depend on the delay), and the rightmost root once per fraction that the margin admits.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    delays : array_like, shape (n_delays,)
        tau in [0, 10] s; sorted ascending in the result.
    lags : array_like, optional
        T_a values [s], >= 0; default: ``reflex.activation_time_constant``.
    kp, kd : float, optional
        Explicit gains [N m/rad], [N m s/rad].

    Returns
    -------
    DesignCurve

    Raises
    ------
    ParameterError
        A delay or lag out of range; E or Lambda out of range.
    """
    from ..errors import ParameterError
    from ..model import config
    from ..model.source import header, provenance

    ds = np.sort(np.asarray(delays, float).ravel())
    if ds.size == 0 or not np.all(np.isfinite(ds) & (ds >= 0) & (ds <= 10)):
        raise ParameterError("--delays", f"must be delays in [0, 10] s (got {np.asarray(delays).tolist()})")
    lag_values = np.asarray([model.reflex.activation_time_constant] if lags is None else lags, float).ravel()
    if lag_values.size == 0 or not np.all(np.isfinite(lag_values) & (lag_values >= 0) & (lag_values <= 10)):
        raise ParameterError("--lags", f"must be lags in [0, 10] s (got {np.asarray(lags).tolist()})")
    e, lam = float(eccentricity), float(lordosis)
    coefficients = checked_coefficients(model, e, lam)
    optimum = np.asarray(solve_point(model, e, lam).pcsa, float)
    names = model.geometry.cor_names
    rows = []
    for lag in lag_values:
        at = config.set_parameters(model, {"reflex.activation_time_constant": float(lag)})
        rows.append(_curve_at_lag(at, e, lam, coefficients, optimum, ds, kp, kd))
    stack = [np.array([r[i] for r in rows]) for i in range(6)]
    activation, segment_activation, local_fraction, least, chain_margin, roots = stack
    return DesignCurve(
        eccentricity=e,
        lordosis=lam,
        delays=ds,
        lags=lag_values,
        activation=activation,
        segment_activation=segment_activation,
        pcsa=activation * np.sum(optimum),
        chain_activation=model.reflex.activation,
        local_fraction=local_fraction,
        local_stiffness=local_fraction[..., None] * least,
        chain_margin=chain_margin,
        max_root_real=roots,
        names=tuple(names),
        model=provenance(model) | {"header": header(model)},
    )


def _curve_at_lag(model, e, lam, coefficients, optimum, delays, kp, kd):
    """(activation, segment activations, chain fraction, k* per delay, chain margin, root) at the model's lag."""
    n = len(model.geometry.cor_names)
    if not np.all(np.isfinite(optimum)):
        nan = np.full(delays.size, np.nan)
        return nan, np.full((delays.size, n), np.nan), nan, np.full((delays.size, n), np.nan), nan, nan
    with arithmetic_guard(e, lam):
        common, each = _joint_curve(model, coefficients, optimum, delays, kp, kd)
    fraction, least, margin, roots = _chain_curve(model, e, lam, model.reflex.activation * optimum, delays, kp, kd)
    return common, each, fraction, np.broadcast_to(least, (delays.size, n)), margin, roots


def _joint_curve(model, coefficients, optimum, delays, kp, kd):
    """Joint by joint at every delay: the common least activation (n_delays,) and each segment's (n_delays, n)."""
    scan = np.linspace(0.0, 1.0, SCAN)
    margins = segment_margins_at(model, coefficients, optimum, scan, kp, kd)  # (SCAN, n)
    n = margins.shape[1]
    pick = [lambda m, k=k: m[:, k] for k in range(n)] + [lambda m: np.min(m, axis=1)]
    answers = []
    for value in pick:
        ok = value(margins)[None, :] >= delays[:, None]  # (n_delays, SCAN)
        first = np.argmax(ok, axis=1)
        found = ok.any(axis=1)
        hi = scan[first]
        lo = np.where(first > 0, scan[np.maximum(first - 1, 0)], hi)
        active = found & (first > 0)
        for _ in range(BISECTIONS if active.any() else 0):
            mid = 0.5 * (lo + hi)
            meets = value(segment_margins_at(model, coefficients, optimum, mid, kp, kd)) >= delays
            hi = np.where(active & meets, mid, hi)
            lo = np.where(active & ~meets, mid, lo)
        answers.append(np.where(found, hi, np.nan))
    return answers[-1], np.stack(answers[:-1], axis=1)


def _chain_curve(model, e, lam, pcsa, delays, kp, kd):
    """The chain at every delay, warm-started: (fraction, k*, exact margin at it, rightmost root's Re) per delay."""
    mass, stiffness, damping = chain_matrices(model, e, lam, pcsa)
    _, least = least_local_stiffness_stacked(stiffness[None], model.optimisation.stability_margin)
    least, lag = least[0], model.reflex.activation_time_constant
    margins: dict[float, object] = {}
    fails_from: dict[float, float] = {}  # f -> a delay at which f is unstable, so f fails every longer delay
    rooted: set[float] = set()  # the fractions whose rightmost root has been checked (at the first delay met)
    roots: dict[float, tuple[float, complex]] = {}  # f -> (a delay, the rightmost root there)

    def loop(f):
        return chain_loop_at(model, mass, stiffness, damping, least, f, kp, kd)

    def root(f, d):
        """The rightmost characteristic root at f and d, once per (f, d)."""
        if f not in roots or roots[f][0] != d:
            k, dl, p, dd = loop(f)
            with arithmetic_guard(e, lam):
                roots[f] = (d, rightmost_root(mass, k, dl, p, dd, d, lag))
        return roots[f][1]

    def exact(f):
        """The exact margin at f, once per f (it does not depend on the delay)."""
        if f not in margins:
            k, dl, p, dd = loop(f)
            if not (np.any(p) or np.any(dd)):
                margins[f] = from_crossings(np.empty(0), np.empty(0), np.empty(0), chain.coupled_margin(k) > 0)
            else:
                with arithmetic_guard(e, lam):
                    margins[f] = chain_delay_margin(mass, k, dl, p, dd, lag)
        return margins[f]

    def met(f, d):
        m = margins[f]
        return bool(stable_at(m, d) and m.margin >= d)

    def meets(f, d):
        """The exact margin at f meets d, and (once per f) no root at d in the right half-plane."""
        if f in fails_from and fails_from[f] <= d:
            return False
        exact(f)
        if not met(f, d):
            return False  # the margin alone rejects f: no root needed
        if f not in rooted and d > 0 and root(f, d).real >= 0:  # a true root: unstable
            fails_from[f] = d
            return False
        rooted.add(f)
        return True

    top = 1.0 if model.reflex.gains == "rule" and kp is None and kd is None else LOCAL_MAX
    width = top / 2**BISECTIONS  # the single design's precision
    f, out = 0.0, []
    for d in delays:
        if np.isfinite(f) and not meets(f, d):
            if not meets(top, d):
                f = np.nan  # no design meets this delay, nor (by monotonicity) any longer one
            else:  # the bracket first narrowed by every fraction already judged
                lo = max([f] + [g for g, at in fails_from.items() if at <= d] + [g for g in margins if not met(g, d)])
                hi = min([top] + [g for g in rooted if g > lo and met(g, d)])
                f = _bracket_root(lambda x, d=d: meets(x, d), _inverse_interpolant(margins, d, met), lo, hi, width)
        if np.isnan(f):
            out.append((np.nan, np.nan, np.nan))
            continue
        out.append((f, float(exact(f).margin), float(root(f, d).real)))
    fraction, margin, rights = (np.array(x) for x in zip(*out, strict=True))
    return fraction, least, margin, rights


def _inverse_interpolant(margins, d, met):
    """An estimate of the fraction whose exact margin is d, from the margins already found, or None.

    Inverse interpolation: the fraction as a polynomial in the margin through the (up to) three fractions
    whose margins are nearest to d, among those whose margin is finite and agrees with the verdict at d (a
    margin that a crossing count overrules says nothing about where the verdict changes). Inverse quadratic
    interpolation is the step of Brent's method [1]_; the margin does not depend on the delay, so the
    fractions judged at shorter delays serve too.

    Returns
    -------
    callable
        () -> the estimate [1] or None (fewer than two such margins).

    References
    ----------
    .. [1] Brent RP (1973). Algorithms for Minimization without Derivatives, ch. 4. Prentice-Hall.
    """

    def estimate():
        known = [
            (abs(m.margin - d), g, m.margin)
            for g, m in margins.items()
            if m.stable_without_delay and np.isfinite(m.margin) and met(g, d) == (m.margin >= d)
        ]
        near: dict[float, float] = {}  # margin -> fraction, the nearest first, one fraction per margin
        for _, g, t in sorted(known):
            if len(near) < 3:
                near.setdefault(t, g)
        if len(near) < 2:
            return None
        # Lagrange's polynomial in the margin through the nearest (margin, fraction) pairs, at d
        return sum(g * np.prod([(d - u) / (t - u) for u in near if u != t]) for t, g in near.items())

    return estimate


def _bracket_root(meets, estimate, lo, hi, width):
    """The least f in (lo, hi] that meets, to ``width``: a safeguarded interpolation search on a bracket.

    ``lo`` fails and ``hi`` meets; each step judges one fraction strictly inside the bracket and keeps the
    part that still brackets the change, so the answer is certified exactly as by bisection: it meets, and
    a fraction within ``width`` below it fails (``hi - lo <= width`` on return). The step is the estimate
    (:func:`_inverse_interpolant`), kept at least 0.45 ``width`` inside each end so that, once the estimate
    is accurate, the next step lands on the other side of the change and closes the bracket; where the
    estimate is missing or outside the bracket, or the last three steps did not halve the bracket (a margin
    that jumps or bends, when the crossing that limits it changes), the step is the midpoint, as in
    bisection. Brent's method keeps its steps inside the bracket the same way [1]_. Correctness does not
    depend on the estimate, only the number of steps: at most four per halving.

    Parameters
    ----------
    meets : callable
        f -> bool, the verdict at the delay.
    estimate : callable
        () -> the estimated change [1] or None, from the fractions judged so far.
    lo, hi : float
        A failing and a meeting fraction [1], lo < hi.
    width : float
        The precision [1].

    Returns
    -------
    float
        ``hi`` at the end [1].

    References
    ----------
    .. [1] Brent RP (1973). Algorithms for Minimization without Derivatives, ch. 4. Prentice-Hall.
    """
    spans = [hi - lo]
    while hi - lo > width:
        x = estimate()
        if x is None or not lo < x < hi or (len(spans) > 3 and spans[-1] > 0.5 * spans[-4]):
            x = 0.5 * (lo + hi)
        else:
            x = min(max(x, lo + 0.45 * width), hi - 0.45 * width)
        lo, hi = (lo, x) if meets(x) else (x, hi)
        spans.append(hi - lo)
    return hi
