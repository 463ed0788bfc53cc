"""Self-stability of each lumbar segment for a given PCSA vector.

For CoR k, with all other CoRs fixed (paper, Methods), the linearised equation
of motion about the upright equilibrium is alpha' = omega,
omega' = (S_k alpha + D_k omega) / theta_k, with S_k = dM/dalpha (muscles,
gravity and passive stiffness) and D_k = dM/domega. The segment is self-stable
iff both eigenvalues of its Jacobian have negative real part (paper [1]_, eq. 1;
docs/model.md, "One segment: the Jacobian and eq. 1").

References
----------
.. [1] Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal
   lordosis optimizes the requirements for a stable erect posture. Theor Biol Med
   Model 9:13. doi:10.1186/1742-4682-9-13
"""

from __future__ import annotations

import contextlib
import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..units import m2_to_cm2
from . import chain
from .checks import arithmetic_guard, checked_coefficients, expand_pcsa
from .linear_chain import LinearChain
from .mechanics import SegmentCoefficients
from .operating_point import OperatingPoint, chain_at
from .params import Model
from .source import header, provenance

MARGINAL_TIME_CONSTANT = 10.0
"""Slowest time constant [s] above which a self-stable segment is reported *marginal*.

A self-stable segment whose muscles only just beat gravity returns in about abs(D / S)
(:func:`slowest_time_constant`); above 10 s it is stable in name only: in quiet standing
the closed-loop corrections act over intervals of about a second (the critical time
interval of the stabilogram diffusion; Collins and De Luca 1993, Exp Brain Res
95:308-318), so such a segment has hardly moved back before the next correction, and its
net stiffness abs(S) is below a tenth of abs(D) per second (docs/reflex.md,
"Which question each command answers").
"""


def criterion(kind: str, n_cor: int = 5) -> str:
    """The words that name a verdict's criterion, as every table and JSON document prints them.

    Parameters
    ----------
    kind : {'joint', 'chain'}
        'joint': the paper's criterion, each CoR alone with the others fixed (eq. 1);
        'chain': every CoR free at once (docs/chain.md).
    n_cor : int
        The number of CoRs of the chain.

    Returns
    -------
    str
        E.g. "joint by joint (each CoR alone, the others fixed; the paper's criterion)".
    """
    if kind == "joint":
        return "joint by joint (each CoR alone, the others fixed; the paper's criterion)"
    return f"chain (all {n_cor} CoRs free)"


def jacobian(stiffness, damping, inertia):
    """Jacobian of (alpha', omega') at the equilibrium, shape (..., 2, 2) [1/s^2, 1/s].

    J = [[0, 1], [S/theta, D/theta]] (paper, Stability analysis).

    Parameters
    ----------
    stiffness : array_like
        S = dM/dalpha [N m/rad].
    damping : array_like
        D = dM/domega [N m s/rad].
    inertia : array_like
        theta [kg m^2].

    Returns
    -------
    numpy.ndarray, shape (..., 2, 2)
        J; its second row is [S/theta [1/s^2], D/theta [1/s]]. ``...`` is the
        broadcast shape of the three inputs.
    """
    s, d, theta = np.broadcast_arrays(*(np.asarray(x, float) for x in (stiffness, damping, inertia)))
    jac = np.zeros(s.shape + (2, 2))
    jac[..., 0, 1] = 1.0
    jac[..., 1, 0] = s / theta
    jac[..., 1, 1] = d / theta
    return jac


def eigenvalues(stiffness, damping, inertia):
    """Eigenvalues of :func:`jacobian`, the roots of theta s^2 - D s - S, shape (..., 2) complex [1/s].

    lambda_{1,2} = D/(2 theta) +- sqrt(D^2/(4 theta^2) + S/theta) (paper [1]_, eq. 1,
    with d(omega')/d(omega) = D/theta and d(omega')/d(alpha) = S/theta), computed
    without cancellation: for real roots q = (D + sign(D) sqrt(D^2 + 4 theta S)) / 2
    gives lambda = q/theta and -S/q (Press et al. [2]_, section 5.6), so the small
    root keeps its precision when theta -> 0 or S -> 0 (the textbook form returns 0
    there). The root with the larger real part comes first.

    Parameters
    ----------
    stiffness : array_like
        S = dM/dalpha [N m/rad].
    damping : array_like
        D = dM/domega [N m s/rad].
    inertia : array_like
        theta [kg m^2], > 0.

    Returns
    -------
    numpy.ndarray, shape (..., 2), complex
        lambda_1, lambda_2 [1/s]; ``...`` is the broadcast shape of the inputs.

    References
    ----------
    .. [1] Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal
       lordosis optimizes the requirements for a stable erect posture. Theor Biol Med
       Model 9:13. doi:10.1186/1742-4682-9-13
    .. [2] Press WH, Teukolsky SA, Vetterling WT, Flannery BP (2007). Numerical Recipes,
       3rd ed., section 5.6, "Quadratic and Cubic Equations". Cambridge University Press.
    """
    s, d, theta = np.broadcast_arrays(*(np.asarray(x, float) for x in (stiffness, damping, inertia)))
    with np.errstate(over="ignore"):  # a stiffness beyond 1e307 overflows here only: scaled below
        disc = d * d + 4.0 * theta * s  # theta^2 times (D/(2 theta))^2 + S/theta, times 4
    real = disc >= 0
    root = np.sqrt(np.abs(disc))
    if not np.all(np.isfinite(disc[np.isfinite(s) & np.isfinite(d) & np.isfinite(theta)])):
        real, root = _scaled_discriminant(s, d, theta, np.isfinite(disc), real, root)
    q = 0.5 * (d + np.where(d < 0, -root, root))  # |q| = (|D| + root) / 2: no cancellation
    nonzero = q != 0  # q = 0 only for D = S = 0: a double root at 0
    big = np.where(nonzero, q / theta, 0.0)
    small = np.where(nonzero, -s / np.where(nonzero, q, 1.0), 0.0)
    first = np.where(real, np.maximum(big, small), d / (2.0 * theta) + 1j * root / (2.0 * theta))
    second = np.where(real, np.minimum(big, small), d / (2.0 * theta) - 1j * root / (2.0 * theta))
    return np.stack([first, second], axis=-1).astype(complex)


def _scaled_discriminant(s, d, theta, finite, real, root):
    """Sign and square root of D^2 + 4 theta S where it overflows: divided by c^2, c = max(abs(D), 2 sqrt(abs(theta S)))
    (each factor's square root taken apart, so nothing overflows); elsewhere ``real`` and ``root`` as given."""
    cross = 2.0 * np.sqrt(np.abs(theta)) * np.sqrt(np.abs(s))  # sqrt(4 abs(theta S))
    c = np.maximum(np.abs(d), cross)
    c = np.where(c > 0, c, 1.0)
    scaled = (d / c) ** 2 + np.sign(theta * np.sign(s)) * (cross / c) ** 2
    return np.where(finite, real, scaled >= 0), np.where(finite, root, c * np.sqrt(np.abs(scaled)))


def slowest_time_constant(stiffness, damping, inertia):
    """The slowest time constant of a set of segments, -1 / max Re(lambda) over their eigenvalues [s].

    How long a self-stable posture takes to recover from a small push: a segment whose stiffness
    S only just beats gravity has a root near S / abs(D), a time constant of abs(D / S) (eq. 1).

    Parameters
    ----------
    stiffness, damping, inertia : array_like, shape (..., n_segments)
        S [N m/rad], D [N m s/rad] and theta [kg m^2] of each segment (:func:`eigenvalues`).

    Returns
    -------
    numpy.ndarray, shape (...)
        The time constant [s]: inf where some eigenvalue has a real part >= 0 (not asymptotically
        stable), NaN where an input is NaN.

    References
    ----------
    .. [1] Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal
       lordosis optimizes the requirements for a stable erect posture. Theor Biol Med
       Model 9:13. doi:10.1186/1742-4682-9-13 (eq. 1)
    """
    slowest = np.asarray(eigenvalues(stiffness, damping, inertia).real.max(axis=(-2, -1)))
    out = np.where(np.isnan(slowest), np.nan, np.inf)
    return np.divide(-1.0, slowest, out=out, where=slowest < 0)


def hurwitz_stable(stiffness, damping):
    """Self-stability of eq. 1 from the signs of S and D alone (Routh-Hurwitz), shape (...) bool.

    theta s^2 - D s - S with theta > 0 has both roots in Re s < 0 iff -D > 0 and
    -S > 0 (the Routh-Hurwitz criterion of a quadratic, Ogata [1]_, section 5-6): an
    exact verdict, however small theta or S, where the eigenvalues' real parts may
    round to 0.

    Parameters
    ----------
    stiffness : array_like
        S = dM/dalpha [N m/rad].
    damping : array_like
        D = dM/domega [N m s/rad].

    Returns
    -------
    numpy.ndarray of bool
        True where S < 0 and D < 0; broadcast shape of the inputs.

    References
    ----------
    .. [1] Ogata K (2010). Modern Control Engineering, 5th ed., section 5-6,
       "Routh's Stability Criterion". Prentice Hall.
    """
    return (np.asarray(stiffness, float) < 0) & (np.asarray(damping, float) < 0)


def self_stable(eigs, margin: float = 0.0):
    """True where every eigenvalue has real part < -margin [1/s].

    Parameters
    ----------
    eigs : array_like, shape (..., 2)
        Eigenvalues [1/s], e.g. from :func:`eigenvalues`.
    margin : float
        Required distance of the real parts from zero [1/s].

    Returns
    -------
    numpy.ndarray of bool, shape (...)
        True where both eigenvalues have real part < -margin.
    """
    return np.all(np.real(eigs) < -margin, axis=-1)


@dataclass(frozen=True)
class StabilityResult:
    """Stability of every segment at one (E, Lambda) for one PCSA vector.

    Attributes
    ----------
    eccentricity, lordosis : float
        E and Lambda [m].
    pcsa : numpy.ndarray, shape (n_muscles,)
        PCSA of each muscle [m^2].
    segment_names : tuple of str
    stiffness, damping, inertia : numpy.ndarray, shape (n_cor,)
        S [N m/rad], D [N m s/rad], theta [kg m^2].
    eigenvalues : numpy.ndarray, shape (n_cor, 2), complex
        [1/s].
    self_stable : numpy.ndarray of bool, shape (n_cor,)
    counter_torque : numpy.ndarray, shape (n_cor,)
        CT_k [N m].
    coefficients : SegmentCoefficients
        The per-unit-PCSA problem data the result was computed from.
    min_pcsa : float
        The minimum total PCSA [m^2] of the LP (paper, Figure 3) when the PCSA is the optimiser's
        chosen activation (:func:`spinectl.optimise.stabilising.stability_at`); NaN when the PCSA was given.
        The chosen activation's total lies within ``optimisation.ct_tolerance`` above it.

    Use :attr:`all_self_stable` for one verdict: the truth value of a result is ambiguous
    (every segment, or any?) and raises a :class:`TypeError` that says so.
    """

    eccentricity: float
    lordosis: float
    pcsa: np.ndarray
    segment_names: tuple[str, ...]
    stiffness: np.ndarray
    damping: np.ndarray
    inertia: np.ndarray
    eigenvalues: np.ndarray
    self_stable: np.ndarray
    counter_torque: np.ndarray
    coefficients: SegmentCoefficients
    min_pcsa: float = math.nan

    def __bool__(self):
        raise TypeError(
            "the truth value of a StabilityResult is ambiguous: use result.all_self_stable (every segment) "
            "or result.self_stable (one bool per segment)"
        )

    @property
    def counter_torque_norm(self) -> float:
        """Euclidean norm ||CT|| [N m] (paper, Stability analysis)."""
        return float(np.linalg.norm(self.counter_torque))

    @property
    def slowest_time_constant(self) -> float:
        """The slowest time constant over the segments [s] (:func:`slowest_time_constant`); inf if not stable."""
        return float(slowest_time_constant(self.stiffness, self.damping, self.inertia))

    @property
    def all_self_stable(self) -> bool:
        """True if every segment is self-stable."""
        return bool(np.all(self.self_stable))

    @property
    def time_constants(self) -> np.ndarray:
        """Each segment's slowest time constant [s], shape (n_cor,) (:func:`slowest_time_constant`)."""
        return slowest_time_constant(self.stiffness[:, None], self.damping[:, None], self.inertia[:, None])

    @property
    def marginal(self) -> np.ndarray:
        """Self-stable segments slower than :data:`MARGINAL_TIME_CONSTANT`, shape (n_cor,) bool."""
        return self.self_stable & (self.time_constants > MARGINAL_TIME_CONSTANT)

    def chain(self, model: Model) -> ChainModes:
        """The chain's modes at this PCSA, every CoR free (:func:`chain_modes`): the chain's verdict.

        Parameters
        ----------
        model : Model
            The model the result was computed with.

        Returns
        -------
        ChainModes
        """
        return chain_modes(model, self.eccentricity, self.lordosis, self.pcsa)

    def verdict(self) -> str:
        """The joint-by-joint verdict in words, with its criterion and the marginal segments.

        Returns
        -------
        str
            One line, e.g. "joint by joint (...): self-stable: all segments (L1L2 marginal: ...)".
        """
        words = "all segments" if self.all_self_stable else "NOT all segments"
        marginal = [
            f"{name} marginal: slowest time constant {tau:.4g} s > {MARGINAL_TIME_CONSTANT:g} s"
            for name, tau, flag in zip(self.segment_names, self.time_constants, self.marginal, strict=True)
            if flag
        ]
        return f"{criterion('joint', len(self.segment_names))}: self-stable: {words}" + (
            f" ({'; '.join(marginal)})" if marginal else ""
        )

    def to_dict(self, model: Model, pcsa_source: str = "given") -> dict:
        """The result as a JSON-ready dict: the document of ``spinectl stability --json``.

        Parameters
        ----------
        model : Model
            The model the result was computed with (muscle names, K and its convention).
        pcsa_source : {'given', 'min_pcsa'}
            Where the PCSA came from: given by the caller, or the minimum stabilising
            PCSA (the optimiser's chosen activation,
            :func:`spinectl.optimise.stabilising.minimum_stabilising_pcsa`).

        Returns
        -------
        dict
            The model's :func:`~spinectl.model.source.provenance` (``preset``, ``config``,
            ``config_sha256``, ``overridden``, ``K_Nm_per_rad`` or ``K_per_s2``, ``K_convention``), ``E_m``,
            ``Lambda_m``, ``pcsa_source``, ``pcsa_cm2`` (muscle name -> PCSA [cm^2]),
            ``chosen_pcsa_total_cm2`` (the total of that PCSA), ``min_pcsa_cm2`` (the LP minimum,
            NaN for a given PCSA), ``total_pcsa_cm2`` (deprecated name of ``chosen_pcsa_total_cm2``,
            kept for one release), ``segments`` (each
            with ``name``, ``stiffness_Nm_per_rad``, ``damping_Nms_per_rad``, ``inertia_kgm2``,
            ``eigenvalues`` as [real, imaginary] pairs [1/s], ``self_stable``, ``slowest_time_constant_s``,
            ``marginal`` (slower than :data:`MARGINAL_TIME_CONSTANT`), ``counter_torque_Nm``),
            ``criterion`` (of these verdicts: joint by joint, :func:`criterion`), ``all_self_stable``,
            ``marginal_segments``, ``marginal_time_constant_s``, ``slowest_time_constant_s`` (inf if not
            stable), ``counter_torque_norm_Nm`` and ``chain`` (the chain's verdict beside it,
            :meth:`ChainModes.to_dict`); the unit is in each key's name.
        """
        pcsa = m2_to_cm2(self.pcsa)
        return provenance(model) | {
            "E_m": self.eccentricity,
            "Lambda_m": self.lordosis,
            "pcsa_source": pcsa_source,
            "pcsa_cm2": dict(zip(model.muscle_names, pcsa.tolist(), strict=False)),
            "chosen_pcsa_total_cm2": float(pcsa.sum()),
            "min_pcsa_cm2": float(m2_to_cm2(self.min_pcsa)),
            "total_pcsa_cm2": float(pcsa.sum()),
            "segments": [
                {
                    "name": name,
                    "stiffness_Nm_per_rad": float(self.stiffness[k]),
                    "damping_Nms_per_rad": float(self.damping[k]),
                    "inertia_kgm2": float(self.inertia[k]),
                    "eigenvalues": [[float(z.real), float(z.imag)] for z in self.eigenvalues[k]],
                    "self_stable": bool(self.self_stable[k]),
                    "slowest_time_constant_s": float(self.time_constants[k]),
                    "marginal": bool(self.marginal[k]),
                    "counter_torque_Nm": float(self.counter_torque[k]),
                }
                for k, name in enumerate(self.segment_names)
            ],
            "criterion": criterion("joint", len(self.segment_names)),
            "all_self_stable": self.all_self_stable,
            "marginal_segments": [n for n, f in zip(self.segment_names, self.marginal, strict=True) if f],
            "marginal_time_constant_s": MARGINAL_TIME_CONSTANT,
            "slowest_time_constant_s": self.slowest_time_constant,
            "counter_torque_norm_Nm": self.counter_torque_norm,
            "chain": self.chain(model).to_dict(),
        }

    def table(self, model: Model, pcsa_source: str = "given") -> str:
        """The result as a readable table, one row a segment, with the PCSA and ||CT|| around it.

        Parameters
        ----------
        model : Model
            The model the result was computed with (muscle names, K and its convention).
        pcsa_source : {'given', 'min_pcsa'}
            Where the PCSA came from (see :meth:`to_dict`); 'min_pcsa' says so in the PCSA line.

        Returns
        -------
        str
            The text ``spinectl stability`` prints (no final newline).
        """

        def complex_column(z: complex) -> str:  # a real root as a real number (its imaginary part is exactly 0)
            real = _fixed(z.real, "9", 3)
            return f"{real}{_fixed(z.imag, '+9', 3)}j" if z.imag else f"{real}{'':10}"

        pcsa = m2_to_cm2(self.pcsa)
        given = pcsa_source == "given"
        minimum = "" if math.isnan(self.min_pcsa) else f"; LP minimum {m2_to_cm2(self.min_pcsa):.2f}"
        lines = [
            header(model, self.inertia),
            f"E = {self.eccentricity * 100:.2f} cm, Lambda = {self.lordosis * 100:.2f} cm",
            ("PCSA [cm^2]: " if given else "PCSA [cm^2] (minimum stabilising, chosen activation): ")
            + ", ".join(f"{n} {p:.2f}" for n, p in zip(model.muscle_names, pcsa, strict=False))
            + f"  (total {pcsa.sum():.2f}{minimum})",
            "",
            f"{'segment':8} {'S [N m/rad]':>12} {'D [N m s/rad]':>14} {'theta [kg m2]':>14} "
            f"{'lambda_1 [1/s]':>20} {'lambda_2 [1/s]':>20} {'stable':>8} {'CT [N m]':>10}",
        ]
        for k, name in enumerate(self.segment_names):
            eig = self.eigenvalues[k]
            lines.append(
                f"{name:8} {_fixed(self.stiffness[k], '12', 3)} {_fixed(self.damping[k], '14', 4)} "
                f"{_fixed(self.inertia[k], '14', 4)} {complex_column(eig[0]):>20} {complex_column(eig[1]):>20} "
                f"{_stable_word(self.self_stable[k], self.marginal[k]):>8} {_fixed(self.counter_torque[k], '10', 3)}"
            )
        lines += [
            SIGN_NOTE,
            "",
            f"||CT|| = {self.counter_torque_norm:.3f} N m; slowest time constant "
            f"{_time_constant_text(self.slowest_time_constant)}",
            self.verdict(),
            self.chain(model).summary(),
        ]
        return "\n".join(lines)


SIGN_NOTE = "S < 0 restores and D < 0 damps (eq. 1: theta phi'' = S phi + D phi'; spinectl anatomy prints -K, > 0)"
"""The sign of S and D, under every table that prints them: the paper's eq. 1 makes a restoring stiffness and
a damping negative, where ``spinectl anatomy`` prints -K (docs/model.md, "One segment: the Jacobian and eq. 1")."""


CHAIN_DEPENDS_ON = (
    "levels.mass and levels.radius_of_gyration (the inertia of the lumbar levels), passive.stiffness "
    "and the global PCSA (the joints' stiffness), local muscles (spinectl stability --coupled: the least "
    "local stiffness)"
)
"""What the chain's modes depend on, as the tables and JSON documents say it (docs/chain.md, "Dynamic stability")."""


@dataclass(frozen=True)
class ChainModes:
    """The chain's modes at one global PCSA, every CoR free (docs/chain.md, "Dynamic stability").

    Attributes
    ----------
    segment_names : tuple of str
    eigenvalues : numpy.ndarray, shape (2 n_cor,), complex
        Of :func:`spinectl.model.chain.state_matrix` [1/s], the largest real part first; NaN
        where the mass matrix is singular (``levels.mass`` = 0).
    """

    segment_names: tuple[str, ...]
    eigenvalues: np.ndarray

    @property
    def defined(self) -> bool:
        """False where the mass matrix is singular (the eigenvalues are NaN)."""
        return bool(np.all(np.isfinite(self.eigenvalues)))

    @property
    def stable(self) -> bool:
        """True if every mode decays (Re lambda < 0); False if one does not or the modes are undefined."""
        return self.defined and bool(self_stable(self.eigenvalues))

    @property
    def growth_times(self) -> np.ndarray:
        """1 / Re lambda of the modes that do not decay [s], fastest first (a mode grows by e in that time)."""
        rates = np.sort(self.eigenvalues.real[self.eigenvalues.real >= 0])[::-1]
        with np.errstate(divide="ignore"):
            return 1.0 / rates

    @property
    def slowest_time_constant(self) -> float:
        """-1 / max Re lambda [s] of a stable chain; inf if a mode does not decay, NaN if undefined."""
        if not self.defined:
            return np.nan
        top = float(np.max(self.eigenvalues.real))
        return -1.0 / top if top < 0 else np.inf

    def to_dict(self) -> dict:
        """The chain's verdict as a JSON-ready dict.

        Returns
        -------
        dict
            ``criterion``, ``stable``, ``defined``, ``eigenvalues`` ([real, imaginary] pairs [1/s]),
            ``growing_modes`` (how many do not decay), ``growth_time_constants_s`` (of those, fastest
            first), ``slowest_time_constant_s`` and ``depends_on``.
        """
        return {
            "criterion": criterion("chain", len(self.segment_names)),
            "stable": self.stable,
            "defined": self.defined,
            "eigenvalues": [[float(z.real), float(z.imag)] for z in self.eigenvalues],
            "growing_modes": int(self.growth_times.size),
            "growth_time_constants_s": self.growth_times.tolist(),
            "slowest_time_constant_s": self.slowest_time_constant,
            "depends_on": CHAIN_DEPENDS_ON,
        }

    def summary(self) -> str:
        """The chain's verdict, its limiting modes and their time constants, and what they depend on.

        Returns
        -------
        str
            One line, its criterion first.
        """
        name = criterion("chain", len(self.segment_names))
        if not self.defined:
            return f"{name}: undefined (no optimum, or a singular mass matrix: levels.mass = 0)"
        if self.stable:
            return f"{name}: stable; slowest time constant {_time_constant_text(self.slowest_time_constant)}"
        times = self.growth_times
        finite = times[np.isfinite(times)]
        span = (
            f"{finite[0] * 1000:.3g} to {finite[-1] * 1000:.3g} ms" if finite.size > 1
            else (f"{finite[0] * 1000:.3g} ms" if finite.size else "no finite time")
        )  # fmt: skip
        return (
            f"{name}: NOT stable, {times.size} of {self.eigenvalues.size} modes grow (by e in {span}); "
            f"they depend on {CHAIN_DEPENDS_ON}"
        )


def chain_modes(model: Model, eccentricity: float, lordosis: float, pcsa, local_stiffness=0.0) -> ChainModes:
    """The chain's modes at a global PCSA: :func:`modes_of` the chain at that operating point (milliseconds).

    The chain is :func:`~spinectl.model.operating_point.chain_at` the
    :class:`~spinectl.model.operating_point.OperatingPoint` of these arguments (``pcsa`` as computed: no
    unit-slip check).

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    pcsa : array_like, shape (n_muscles,)
        Global PCSA of each muscle [m^2].
    local_stiffness : array_like, shape (n_cor,), optional
        Stiffness of the local muscles at each joint [N m/rad], with the damping of their force-velocity slope
        (docs/chain.md, "Local muscles as joint stiffness and damping").

    Returns
    -------
    ChainModes
        The eigenvalues [1/s] of :func:`spinectl.model.chain.dynamic_eigenvalues`.

    Raises
    ------
    ParameterError
        A field of the operating point out of range (:class:`~spinectl.model.operating_point.OperatingPoint`).

    References
    ----------
    Bergmark A (1989). Stability of the lumbar spine. A study in mechanical engineering.
    Acta Orthop Scand Suppl 230:1-54. doi:10.3109/17453678909154177.
    """
    point = OperatingPoint(model, eccentricity, lordosis, pcsa, local_stiffness, slip_check=False)
    return modes_of(chain_at(point), guard=arithmetic_guard(point.eccentricity, point.lordosis))


def modes_of(linear: LinearChain, guard=None) -> ChainModes:
    """The modes of a chain at its operating point: the eigenvalues of its M, K and D (an analysis of a chain).

    Parameters
    ----------
    linear : LinearChain
        Fixed at its operating point, without controls (:func:`spinectl.model.operating_point.chain_at`).
    guard : context manager, optional
        Around the arithmetic (:func:`~spinectl.model.checks.arithmetic_guard` of the point); default none.

    Returns
    -------
    ChainModes
        The eigenvalues [1/s] of :func:`spinectl.model.chain.dynamic_eigenvalues`; NaN where M is singular.

    Raises
    ------
    ParameterError
        A chain with free controls.
    """
    if linear.n_controls:
        raise ParameterError("chain", f"must be fixed at its operating point (got {linear.n_controls} free controls)")
    with guard if guard is not None else contextlib.nullcontext():
        eigs = chain.dynamic_eigenvalues(linear.mass_matrix, linear.stiffness_offset, linear.damping_offset)
    return ChainModes(segment_names=linear.joints, eigenvalues=eigs)


def segment_stability(
    model: Model, eccentricity: float, lordosis: float, pcsa, *, given: bool = True
) -> StabilityResult:
    """Jacobian eigenvalues, self-stability and counter torque of every segment.

    The analysis of the paper [1]_ (Methods, Stability analysis and calculation of
    counter torques): eq. 1 per CoR, and the counter torques CT_k.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m], inside the modelled range.
    pcsa : array_like
        PCSA [m^2], per pair (n values) or per muscle (2 n values); see :func:`expand_pcsa`.
    given : bool
        False for a PCSA that spinectl computed: not checked against the plausible size of a
        typed one (:func:`expand_pcsa`).

    Returns
    -------
    StabilityResult
        Per segment (shape (n_cor,)): S [N m/rad], D [N m s/rad], theta [kg m^2], the
        eigenvalues [1/s], the self-stability verdict and CT_k [N m]; with the
        per-muscle PCSA [m^2] used and the coefficients it came from.

    Raises
    ------
    ParameterError
        E or Lambda outside the modelled range, or a PCSA vector of the wrong length
        or with negative or non-finite entries.
    ModelError
        The model cannot be evaluated there (see :func:`~spinectl.model.checks.validate_position`).

    References
    ----------
    .. [1] Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal
       lordosis optimizes the requirements for a stable erect posture. Theor Biol Med
       Model 9:13. doi:10.1186/1742-4682-9-13

    Examples
    --------
    The paper's verdict at its optimum (E = 3 cm, Lambda = 4 cm) and the minimum PCSA there:

    >>> from spinectl import load_preset, segment_stability
    >>> from spinectl.optimise.active_set import solve_point
    >>> model = load_preset("wagner2012")
    >>> optimum = solve_point(model, 0.03, 0.04)
    >>> round(optimum.min_pcsa * 1e4, 1)  # [cm^2]
    35.8
    >>> result = segment_stability(model, 0.03, 0.04, optimum.pcsa, given=False)
    >>> result.self_stable.tolist()
    [True, True, True, True, True]
    """
    coeffs = checked_coefficients(model, float(eccentricity), float(lordosis))
    pcsa = expand_pcsa(model, pcsa, given=given)
    with arithmetic_guard(eccentricity, lordosis):  # e.g. a PCSA of 1e300 cm^2
        stiffness = coeffs.stiffness(pcsa)
        damping = coeffs.damping(pcsa)
        eigs = eigenvalues(stiffness, damping, coeffs.inertia)
        counter_torque = coeffs.counter_torque(pcsa)
        if not all(np.all(np.isfinite(x)) for x in (stiffness, damping, eigs, counter_torque)):
            raise FloatingPointError("non-finite stiffness, damping, eigenvalues or counter torque")
    return StabilityResult(
        eccentricity=float(eccentricity),
        lordosis=float(lordosis),
        pcsa=pcsa,
        segment_names=model.geometry.cor_names,
        stiffness=stiffness,
        damping=damping,
        inertia=coeffs.inertia,
        eigenvalues=eigs,
        self_stable=hurwitz_stable(stiffness, damping),
        counter_torque=counter_torque,
        coefficients=coeffs,
    )


FIXED_LIMIT = 1e9
"""Magnitude from which a table prints a number in exponent notation: a stiffness of 1e308 (``--K 1e308``)
in fixed notation is 309 digits wide."""


def eigenvalue_text(z: complex, decimals: int = 3) -> str:
    """An eigenvalue as text: a real one (imaginary part exactly 0, as LAPACK returns for a real root) as a
    real number, a complex one as ``a+bj``.

    Parameters
    ----------
    z : complex
        The eigenvalue [1/s].
    decimals : int, optional
        Decimals of each part.

    Returns
    -------
    str
        E.g. ``'68.321'`` or ``'-3.653+1.204j'``.
    """
    real = f"{z.real:.{decimals}f}"
    return f"{real}{z.imag:+.{decimals}f}j" if z.imag else real


def _fixed(value: float, width: str, decimals: int) -> str:
    """``value`` in fixed notation of ``width`` (a format width, e.g. ``'12'`` or ``'+9'``), or as ``1.000e+308``."""
    kind = "f" if abs(value) < FIXED_LIMIT or not math.isfinite(value) else "e"
    return f"{value:{width}.{decimals}{kind}}"


def _stable_word(stable: bool, marginal: bool) -> str:
    """A segment's joint-by-joint verdict in a table column: yes, marginal or NO."""
    return ("marginal" if marginal else "yes") if stable else "NO"


def _time_constant_text(tau: float) -> str:
    """A time constant [s] as text; inf (a segment that does not return) as "none", as ``spinectl margins`` says."""
    return f"{tau:.4g} s" if np.isfinite(tau) else "none (not every segment returns)"
