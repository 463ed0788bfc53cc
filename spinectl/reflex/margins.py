"""Reflex margins of every segment at one configuration: what ``spinectl margins`` reports.

Combines the operating point (an activation level of the minimum stabilising PCSA,
:func:`spinectl.optimise.reference.solve_point`), the reflex gains (:mod:`spinectl.reflex`),
the exact margins from the quasi-polynomial (:mod:`spinectl.reflex`) and
python-control's margins of the Padé loop (:mod:`spinectl.reflex.loops`).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from ..model import stability
from ..model.checks import arithmetic_guard, checked_coefficients
from ..model.params import Model
from ..optimise.reference import solve_point
from . import gains, loops, pade
from .delay import critical_gains, delay_margin, phase_margin, stable_at_delay

SKIPPED = "skipped"
"""Optimum status when activation = 0: the optimiser is not consulted (no co-contraction)."""


@dataclass(frozen=True)
class OperatingPoint:
    """PCSA and linearised segments at one (E, Lambda) and activation level.

    Attributes
    ----------
    eccentricity, lordosis : float
        E and Lambda [m].
    activation : float
        Fraction of the minimum stabilising PCSA [1].
    status : str
        Status of :func:`~spinectl.optimise.reference.solve_point` ('optimal', 'infeasible', ...)
        or 'skipped' at activation 0. Unless optimal or skipped, every value is NaN.
    pcsa : numpy.ndarray, shape (n_muscles,)
        activation x the optimum's PCSA [m^2].
    stiffness, damping, inertia : numpy.ndarray, shape (n_cor,)
        S [N m/rad], D [N m s/rad], theta [kg m^2] per segment.
    """

    eccentricity: float
    lordosis: float
    activation: float
    status: str
    pcsa: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    inertia: np.ndarray

    @property
    def ok(self) -> bool:
        """True if the PCSA is known (optimum found, or activation 0)."""
        return bool(np.all(np.isfinite(self.pcsa)))


def operating_point(model: Model, eccentricity: float, lordosis: float, activation: float) -> OperatingPoint:
    """PCSA = activation x ``solve_point(model, E, Lambda).pcsa`` and the segments it gives.

    An infeasible optimum is reported in ``status`` with NaN values, never raised.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    activation : float
        Fraction of the minimum stabilising PCSA [1]; 0 skips the optimiser.
    """
    coeffs = checked_coefficients(model, float(eccentricity), float(lordosis))
    if activation == 0:
        status, pcsa = SKIPPED, np.zeros(len(model.muscle_names))
    else:
        optimum = solve_point(model, eccentricity, lordosis)
        status, pcsa = optimum.status, activation * optimum.pcsa
    return OperatingPoint(
        eccentricity=float(eccentricity),
        lordosis=float(lordosis),
        activation=float(activation),
        status=status,
        pcsa=pcsa,
        stiffness=coeffs.stiffness(pcsa),
        damping=coeffs.damping(pcsa),
        inertia=coeffs.inertia,
    )


@dataclass(frozen=True)
class SegmentMargins:
    """The reflex loop of one segment and its margins.

    Attributes
    ----------
    name : str
    stiffness, damping, inertia : float
        S [N m/rad], D [N m s/rad], theta [kg m^2].
    kp, kd : float
        Reflex gains [N m/rad], [N m s/rad].
    self_stable : bool
        Stable without reflex (:func:`spinectl.model.stability.self_stable`): no open-loop pole in Re s >= 0.
    delay_margin : float
        Exact delay margin [s] (inf: any delay; 0: unstable without delay; NaN: undefined).
    delay_margin_status : str
        One of :data:`spinectl.reflex.STATUS`.
    delay_margin_pade : float
        The same from the Padé loop of the configured order [s].
    phase_margin_deg : float
        Exact phase margin at the configured delay [deg] (inf without crossover).
    crossover_rad_s : float
        Gain crossover that limits the delay margin [rad/s].
    gain_margin, gain_margin_lower : float
        Stable range (lower, upper) of a common factor on kp and kd [1], from
        python-control on the Padé loop (:class:`spinectl.reflex.loops.LoopMargins`).
    python_control : loops.LoopMargins or None
        python-control's own reading of the Padé loop; None where undefined, or where its
        polynomial arithmetic overflows (very short delays at high Padé orders).
    kp_min, kp_max : float
        Range of kp that stabilises the segment at the delay, given kd [N m/rad].
    stable_at_delay : bool
        Closed loop stable at the configured delay (exact).
    """

    name: str
    stiffness: float
    damping: float
    inertia: float
    kp: float
    kd: float
    self_stable: bool
    delay_margin: float
    delay_margin_status: str
    delay_margin_pade: float
    phase_margin_deg: float
    crossover_rad_s: float
    gain_margin: float
    gain_margin_lower: float
    python_control: loops.LoopMargins | None
    kp_min: float
    kp_max: float
    stable_at_delay: bool


def segment_margins(name, stiffness, damping, inertia, kp, kd, delay: float, order: int) -> SegmentMargins:
    """All margins of one segment's reflex loop (see :class:`SegmentMargins`).

    Parameters
    ----------
    name : str
        Name of the CoR.
    stiffness, damping, inertia : float
        S [N m/rad], D [N m s/rad], theta [kg m^2]; NaN gives NaN margins.
    kp, kd : float
        Reflex gains [N m/rad], [N m s/rad].
    delay : float
        tau [s].
    order : int
        Order of the Padé approximant.
    """
    s, d, theta, kp, kd = (float(x) for x in (stiffness, damping, inertia, kp, kd))
    exact = delay_margin(s, d, theta, kp, kd)
    pm, w_c = phase_margin(s, d, theta, kp, kd, delay)
    stable = bool(stable_at_delay(s, d, theta, kp, kd, delay))
    kp_min, kp_max = critical_gains(s, d, theta, kd, delay)
    defined = all(np.isfinite(x) for x in (s, d, theta, kp, kd))
    pc = _python_control_margins(s, d, theta, kp, kd, delay, order, stable) if defined else None
    return SegmentMargins(
        name=name,
        stiffness=s,
        damping=d,
        inertia=theta,
        kp=kp,
        kd=kd,
        self_stable=bool(stability.self_stable(stability.eigenvalues(s, d, theta))),
        delay_margin=float(exact.margin),
        delay_margin_status=str(exact.status_names),
        delay_margin_pade=float(pade.pade_delay_margin(s, d, theta, kp, kd, order).margin),
        phase_margin_deg=float(np.degrees(pm)),
        crossover_rad_s=float(w_c),
        gain_margin=pc.gain_margin_upper if pc else np.nan,
        gain_margin_lower=pc.gain_margin_lower if pc else np.nan,
        python_control=pc,
        kp_min=float(kp_min),
        kp_max=float(kp_max),
        stable_at_delay=stable,
    )


def _python_control_margins(s, d, theta, kp, kd, delay, order, stable):
    """python-control's margins of the Padé loop, or None where its polynomial arithmetic overflows.

    Its Padé coefficients grow like (1/tau)^n, so very short delays at high orders
    overflow in ``stability_margins``; the exact margins do not depend on it.
    python-control evaluates L(jw) under its own ``np.errstate(all="warn")``, so its
    trouble arrives as RuntimeWarnings (underflow aside, see
    :func:`spinectl.reflex.loops.ignoring_underflow`) and makes its reading undefined too.
    """
    try:
        with np.errstate(over="raise", divide="raise", invalid="raise"), warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)
            return loops.loop_margins(loops.loop_transfer(s, d, theta, kp, kd, delay, order), stable)
    except (FloatingPointError, RuntimeWarning, np.linalg.LinAlgError):  # LinAlgError: poles of NaN coefficients
        return None


@dataclass(frozen=True)
class MarginsReport:
    """Reflex margins of every segment at one configuration.

    Attributes
    ----------
    point : OperatingPoint
    delay : float
        Reflex delay tau [s].
    pade_order : int
    segments : tuple of SegmentMargins
    """

    point: OperatingPoint
    delay: float
    pade_order: int
    segments: tuple[SegmentMargins, ...]


def analyse(model: Model, eccentricity: float, lordosis: float, kp=None, kd=None) -> MarginsReport:
    """Margins of every segment, with the reflex settings of ``model.reflex``.

    Parameters
    ----------
    model : Model
        ``model.reflex`` gives delay, Padé order, activation and gains.
    eccentricity, lordosis : float
        E and Lambda [m].
    kp, kd : float, optional
        Explicit gains for every segment [N m/rad], [N m s/rad], each replacing the configured one.
    """
    settings = model.reflex
    point = operating_point(model, eccentricity, lordosis, settings.activation)
    with arithmetic_guard(eccentricity, lordosis):  # absurd gains or delays: a ModelError, not NaN and warnings
        segments = _segments(model, point, settings, kp, kd)
    return MarginsReport(point=point, delay=settings.delay, pade_order=settings.pade_order, segments=segments)


def _segments(model, point, settings, kp, kd) -> tuple[SegmentMargins, ...]:
    kps, kds = gains.resolve_gains(point.stiffness, point.damping, point.inertia, settings, kp, kd)
    return tuple(
        segment_margins(
            name,
            point.stiffness[k],
            point.damping[k],
            point.inertia[k],
            kps[k],
            kds[k],
            settings.delay,
            settings.pade_order,
        )
        for k, name in enumerate(model.geometry.cor_names)
    )
