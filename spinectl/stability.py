"""Self-stability of each lumbar segment for a given PCSA vector.

For CoR k, with all other CoRs fixed (paper, Methods), the linearised equation
of motion about the upright equilibrium is alpha' = omega,
omega' = (S_k alpha + D_k omega) / theta_k, with S_k = dM/dalpha (muscles,
gravity and passive stiffness) and D_k = dM/domega. The segment is self-stable
iff both eigenvalues of its Jacobian have negative real part (paper, eq. 1).
"""

from __future__ import annotations

import contextlib
import dataclasses
from dataclasses import dataclass

import numpy as np

from . import geometry
from .errors import ModelError, ParameterError
from .mechanics import SegmentCoefficients, segment_coefficients
from .params import Model


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
    """
    s, d, theta = np.broadcast_arrays(*(np.asarray(x, float) for x in (stiffness, damping, inertia)))
    jac = np.zeros(s.shape + (2, 2))
    jac[..., 0, 1] = 1.0
    jac[..., 1, 0] = s / theta
    jac[..., 1, 1] = d / theta
    return jac


def eigenvalues(stiffness, damping, inertia):
    """Eigenvalues of :func:`jacobian` in closed form, shape (..., 2) complex [1/s].

    lambda_{1,2} = D/(2 theta) +- sqrt(D^2/(4 theta^2) + S/theta) (paper, eq. 1,
    with d(omega')/d(omega) = D/theta and d(omega')/d(alpha) = S/theta).
    The root with the larger real part comes first.

    Parameters
    ----------
    stiffness : array_like
        S = dM/dalpha [N m/rad].
    damping : array_like
        D = dM/domega [N m s/rad].
    inertia : array_like
        theta [kg m^2].
    """
    s, d, theta = (np.asarray(x, float) for x in (stiffness, damping, inertia))
    half = d / (2.0 * theta)
    root = np.sqrt((half**2 + s / theta).astype(complex))
    return np.stack([half + root, half - root], axis=-1)


def self_stable(eigs, margin: float = 0.0):
    """True where every eigenvalue has real part < -margin [1/s].

    Parameters
    ----------
    eigs : array_like, shape (..., 2)
        Eigenvalues [1/s], e.g. from :func:`eigenvalues`.
    margin : float
        Required distance of the real parts from zero [1/s].
    """
    return np.all(np.real(eigs) < -margin, axis=-1)


def validate_position(model: Model, eccentricity, lordosis) -> None:
    """Raise unless the model can be evaluated at (E, Lambda); see :func:`checked_coefficients`.

    Parameters
    ----------
    model : Model
        Supplies the modelled ranges, the geometry and every parameter.
    eccentricity, lordosis : array_like
        E and Lambda [m]; broadcast together (a whole grid may be checked at once).

    Raises
    ------
    ParameterError
        E or Lambda is not finite or outside ``geometry.eccentricity_range`` or
        ``geometry.lordosis_range`` [m].
    ModelError
        A fibre attachment lies on a centre of rotation there, or the
        parameters overflow the arithmetic (a value orders of magnitude off).
    """
    checked_coefficients(model, eccentricity, lordosis)


def checked_coefficients(model: Model, eccentricity, lordosis) -> SegmentCoefficients:
    """:func:`~spinectl.mechanics.segment_coefficients` after every check of :func:`validate_position`.

    Floating-point overflow, division by zero and invalid operations become a
    :class:`ModelError`, never a numpy warning or a NaN passed on to a solver.

    Parameters
    ----------
    model : Model
        The parameters.
    eccentricity, lordosis : array_like
        E and Lambda [m]; broadcast together.
    """
    _check_range(model, eccentricity, lordosis)
    with arithmetic_guard(eccentricity, lordosis):
        _check_attachments(model, eccentricity, lordosis)
        coeffs = segment_coefficients(model, eccentricity, lordosis)
        values = [getattr(coeffs, f.name) for f in dataclasses.fields(coeffs)]
        if not all(np.all(np.isfinite(x)) for x in values) or np.any(coeffs.inertia <= 0):
            raise FloatingPointError("non-finite segment coefficients or zero inertia")
    return coeffs


def _where(eccentricity, lordosis) -> str:
    e, lam = np.broadcast_arrays(np.asarray(eccentricity, float), np.asarray(lordosis, float))
    if e.size == 1:
        return f"at E = {e.flat[0]:g} m, Lambda = {lam.flat[0]:g} m"
    return f"on the grid E in [{e.min():g}, {e.max():g}] m, Lambda in [{lam.min():g}, {lam.max():g}] m"


@contextlib.contextmanager
def arithmetic_guard(eccentricity, lordosis):
    """Raise :class:`ModelError` for floating-point trouble inside the ``with`` block.

    Validated parameters are finite, so overflow, division by zero or an
    invalid operation mean that some values are orders of magnitude off (a
    unit typo); the user gets that, not a numpy warning and NaN results.

    Parameters
    ----------
    eccentricity, lordosis : array_like
        E and Lambda [m] being evaluated, named in the message.
    """
    try:
        with np.errstate(over="raise", divide="raise", invalid="raise"):
            yield
    except (FloatingPointError, OverflowError, ZeroDivisionError) as exc:
        reason = str(exc) if isinstance(exc, FloatingPointError) else type(exc).__name__  # numpy's say where
        raise ModelError(
            f"the model's arithmetic fails {_where(eccentricity, lordosis)} ({reason}); "
            "is a parameter or an input orders of magnitude off? (units are SI: m, kg, N, s)"
        ) from None


def _check_attachments(model: Model, eccentricity, lordosis) -> None:
    """Raise :class:`ModelError` if a fibre attachment lies on a centre of rotation.

    A fibre's line of action may pass through a CoR (a zero lever arm is a
    valid answer), but an attachment on the CoR leaves no arm between the
    joint and the muscle: the fibre has zero length on one side of the joint.
    "On" means equal up to round-off of the coordinates.
    """
    cor = geometry.cor_positions(eccentricity, lordosis, model.geometry)  # (..., K, 2)
    upper, lower, share = geometry.all_fibres(model)  # (F, 2), (F, 2), (F, M)
    tolerance = 4 * np.finfo(float).eps
    for end, points in (("upper", upper), ("lower", lower)):
        offset = cor[..., :, None, :] - points  # (..., K, F, 2)
        scale = np.abs(cor[..., :, None, :]).sum(-1) + np.abs(points).sum(-1)
        on_cor = np.abs(offset).sum(-1) <= tolerance * scale
        if on_cor.any():
            *at, k, f = np.argwhere(on_cor)[0]
            muscle = int(np.argmax(share[f]))
            pair = muscle // 2
            e, lam = (
                np.broadcast_to(np.asarray(x, float), on_cor.shape[:-2])[tuple(at)] for x in (eccentricity, lordosis)
            )
            raise ModelError(
                f"muscles.{pair}.{end}: the {end} attachment of a fibre of {model.muscle_names[muscle]} lies on the "
                f"centre of rotation {model.geometry.cor_names[k]} {_where(e, lam)}; a fibre needs a non-zero "
                "arm between the joint and each attachment"
            )


def _check_range(model: Model, eccentricity, lordosis) -> None:
    for name, value, (lo, hi) in (
        ("E", eccentricity, model.geometry.eccentricity_range),
        ("Lambda", lordosis, model.geometry.lordosis_range),
    ):
        arr = np.asarray(value, float)
        if not np.all(np.isfinite(arr)):
            raise ParameterError(name, "must be finite")
        if np.any(arr < lo) or np.any(arr > hi):
            bad = arr[(arr < lo) | (arr > hi)].flat[0]
            raise ParameterError(name, f"must be in [{lo:g}, {hi:g}] m, the modelled range (got {bad:g})")


def expand_pcsa(model: Model, pcsa) -> np.ndarray:
    """Per-muscle PCSA [m^2] from per-muscle (2 n values) or per-pair (n values, each side) input.

    With n values, both muscles of pair j get ``pcsa[j]`` (paired activation).

    Parameters
    ----------
    model : Model
        Supplies the muscle pairs.
    pcsa : array_like, shape (..., n) or (..., 2 n)
        PCSA [m^2], finite and >= 0.
    """
    pcsa = np.asarray(pcsa, float)
    n_pairs = len(model.muscles)
    if pcsa.shape[-1:] == (n_pairs,):
        pcsa = pcsa @ geometry.pairing_matrix(n_pairs).T
    elif pcsa.shape[-1:] != (2 * n_pairs,):
        raise ParameterError(
            "pcsa",
            f"must have {n_pairs} values (one per pair) or {2 * n_pairs} (one per muscle); got {pcsa.shape[-1:]}",
        )
    if not np.all(np.isfinite(pcsa)) or np.any(pcsa < 0):
        raise ParameterError("pcsa", "must be finite and >= 0")
    return pcsa


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

    @property
    def counter_torque_norm(self) -> float:
        """Euclidean norm ||CT|| [N m] (paper, Stability analysis)."""
        return float(np.linalg.norm(self.counter_torque))

    @property
    def all_self_stable(self) -> bool:
        """True if every segment is self-stable."""
        return bool(np.all(self.self_stable))


def segment_stability(model: Model, eccentricity: float, lordosis: float, pcsa) -> StabilityResult:
    """Jacobian eigenvalues, self-stability and counter torque of every segment.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m], inside the modelled range.
    pcsa : array_like
        PCSA [m^2], per pair (n values) or per muscle (2 n values); see :func:`expand_pcsa`.

    Returns
    -------
    StabilityResult
    """
    coeffs = checked_coefficients(model, float(eccentricity), float(lordosis))
    pcsa = expand_pcsa(model, pcsa)
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
        self_stable=self_stable(eigs),
        counter_torque=counter_torque,
        coefficients=coeffs,
    )
