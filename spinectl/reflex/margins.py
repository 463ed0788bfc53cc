"""Reflex margins of every segment at one configuration: what ``spinectl margins`` reports.

Combines the operating point (an activation level of the minimum stabilising PCSA,
:func:`spinectl.optimise.reference.solve_point`), the reflex gains (:mod:`spinectl.reflex`),
the exact margins from the quasi-polynomial (:mod:`spinectl.reflex`) and
python-control's margins of the Padé loop (:mod:`spinectl.reflex.loops`).

A :class:`MarginsReport` presents itself: :meth:`MarginsReport.to_dict` (the JSON of
``spinectl margins --json``, units in the key names) and :meth:`MarginsReport.table`.
:func:`report_responses` computes what its plots show (:func:`spinectl.reflex.plots.write_plots`).
"""

from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass, field

import numpy as np

from .. import _validate as v
from ..model import stability
from ..model.checks import arithmetic_guard, checked_coefficients
from ..model.params import Model
from ..model.source import header, provenance
from ..optimise.reference import solve_point
from ..units import m2_to_cm2
from . import gains, loops, pade, simulate
from .delay import critical_gains, delay_margin, phase_margin, stable_at_delay
from .inputs import validated

SKIPPED = "skipped"
"""Optimum status when activation = 0: the optimiser is not consulted (no co-contraction)."""


@dataclass(frozen=True)
class ActivationPoint:
    """PCSA and linearised segments at one (E, Lambda) and activation level.

    The activation resolved into a PCSA by the optimiser, and each segment alone at it; the chain at the
    same PCSA is :func:`~spinectl.model.operating_point.chain_at` its
    :class:`~spinectl.model.operating_point.OperatingPoint` (:func:`spinectl.reflex.chain_verdict.chain_verdict`).

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
    muscle_names : tuple of str
        The muscle of each entry of ``pcsa`` (:attr:`spinectl.model.params.model.Model.muscle_names`).
    """

    eccentricity: float
    lordosis: float
    activation: float
    status: str
    pcsa: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    inertia: np.ndarray
    muscle_names: tuple[str, ...]

    @property
    def ok(self) -> bool:
        """True if the PCSA is known (optimum found, or activation 0)."""
        return bool(np.all(np.isfinite(self.pcsa)))


def operating_point(model: Model, eccentricity: float, lordosis: float, activation: float) -> ActivationPoint:
    """PCSA = activation x ``solve_point(model, E, Lambda).pcsa`` and the segments it gives.

    An infeasible optimum is reported in ``status`` with NaN values, never raised.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    activation : float
        Fraction of the minimum stabilising PCSA [1]; 0 skips the optimiser.

    Returns
    -------
    ActivationPoint
        The PCSA [m^2] and each segment's S [N m/rad], D [N m s/rad] and theta [kg m^2] there.
    """
    coeffs = checked_coefficients(model, float(eccentricity), float(lordosis))
    if activation == 0:
        status, pcsa = SKIPPED, np.zeros(len(model.muscle_names))
    else:
        optimum = solve_point(model, eccentricity, lordosis)
        status, pcsa = optimum.status, activation * optimum.pcsa
    return ActivationPoint(
        eccentricity=float(eccentricity),
        lordosis=float(lordosis),
        activation=float(activation),
        status=status,
        pcsa=pcsa,
        stiffness=coeffs.stiffness(pcsa),
        damping=coeffs.damping(pcsa),
        inertia=coeffs.inertia,
        muscle_names=model.muscle_names,
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
    slowest_time_constant : float
        -1 / max Re lambda over the eigenvalues of paper eq. (1) [s]: how slowly the segment without
        reflex settles; inf if not self-stable (it never returns), as
        :func:`spinectl.model.stability.slowest_time_constant`; NaN without an optimum.
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
    slowest_time_constant: float
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

    def to_dict(self) -> dict:
        """This segment as a JSON-ready dict, the unit in each key's name.

        Returns
        -------
        dict
            ``name``, ``stiffness_Nm_per_rad``, ``damping_Nms_per_rad``, ``inertia_kgm2``,
            ``self_stable``, ``slowest_time_constant_s``, ``kp_Nm_per_rad``, ``kd_Nms_per_rad``, ``gain_margin``,
            ``gain_margin_lower``, ``phase_margin_deg``, ``crossover_rad_s``, ``delay_margin_s``,
            ``delay_margin_status``, ``delay_margin_pade_s``, ``kp_min_Nm_per_rad``,
            ``kp_max_Nm_per_rad``, ``stable_at_delay`` and ``python_control`` (None, or its
            ``gain_margin``, ``phase_margin_deg``, ``crossover_rad_s``, ``phase_crossover_rad_s``).
            Infinite and NaN values stay floats; ``--json`` writes them ``null`` with a reason
            (:func:`spinectl.jsondoc.dumps`).
        """
        pc = self.python_control
        return {
            "name": self.name,
            "stiffness_Nm_per_rad": self.stiffness,
            "damping_Nms_per_rad": self.damping,
            "inertia_kgm2": self.inertia,
            "self_stable": self.self_stable,
            "slowest_time_constant_s": self.slowest_time_constant,
            "kp_Nm_per_rad": self.kp,
            "kd_Nms_per_rad": self.kd,
            "gain_margin": self.gain_margin,
            "gain_margin_lower": self.gain_margin_lower,
            "phase_margin_deg": self.phase_margin_deg,
            "crossover_rad_s": self.crossover_rad_s,
            "delay_margin_s": self.delay_margin,
            "delay_margin_status": self.delay_margin_status,
            "delay_margin_pade_s": self.delay_margin_pade,
            "kp_min_Nm_per_rad": self.kp_min,
            "kp_max_Nm_per_rad": self.kp_max,
            "stable_at_delay": self.stable_at_delay,
            "python_control": None
            if pc is None
            else {
                "gain_margin": pc.gain_margin,
                "phase_margin_deg": pc.phase_margin_deg,
                "crossover_rad_s": pc.crossover_rad_s,
                "phase_crossover_rad_s": pc.phase_crossover_rad_s,
            },
        }


@validated
def segment_margins(
    name, stiffness, damping, inertia, kp, kd, delay: float, order: int, lag: float = 0.0
) -> SegmentMargins:
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
    lag : float, optional
        Activation time constant T_a [s].

    Returns
    -------
    SegmentMargins
        Exact and Padé delay margins [s], phase margin [deg], stabilising gain range and verdict.
    """
    s, d, theta, kp, kd = (float(x) for x in (stiffness, damping, inertia, kp, kd))
    exact = delay_margin(s, d, theta, kp, kd, lag)
    pm, w_c = phase_margin(s, d, theta, kp, kd, delay, lag)
    stable = bool(stable_at_delay(s, d, theta, kp, kd, delay, lag))
    kp_min, kp_max = critical_gains(s, d, theta, kd, delay, lag=lag)
    defined = all(np.isfinite(x) for x in (s, d, theta, kp, kd))
    pc = _python_control_margins(s, d, theta, kp, kd, delay, order, stable, lag) if defined else None
    poles = stability.eigenvalues(s, d, theta)
    self_stable = bool(stability.self_stable(poles))
    return SegmentMargins(
        name=name,
        stiffness=s,
        damping=d,
        inertia=theta,
        kp=kp,
        kd=kd,
        self_stable=self_stable,
        slowest_time_constant=float(stability.slowest_time_constant([s], [d], [theta])),
        delay_margin=float(exact.margin),
        delay_margin_status=str(exact.status_names),
        delay_margin_pade=float(pade.pade_delay_margin(s, d, theta, kp, kd, order, lag).margin),
        phase_margin_deg=float(np.degrees(pm)),
        crossover_rad_s=float(w_c),
        gain_margin=pc.gain_margin_upper if pc else np.nan,
        gain_margin_lower=pc.gain_margin_lower if pc else np.nan,
        python_control=pc,
        kp_min=float(kp_min),
        kp_max=float(kp_max),
        stable_at_delay=stable,
    )


def _python_control_margins(s, d, theta, kp, kd, delay, order, stable, lag):
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
            return loops.loop_margins(loops.loop_transfer(s, d, theta, kp, kd, delay, order, lag), stable)
    except (FloatingPointError, RuntimeWarning, np.linalg.LinAlgError):  # LinAlgError: poles of NaN coefficients
        return None


@dataclass(frozen=True)
class MarginsReport:
    """Reflex margins of every segment at one configuration.

    Attributes
    ----------
    point : ActivationPoint
    delay : float
        Reflex delay tau [s].
    activation_time_constant : float
        T_a [s] of the force generation after the delay
        (:attr:`spinectl.model.params.reflex.Reflex.activation_time_constant`).
    pade_order : int
    segments : tuple of SegmentMargins
    gains : str
        How the gains were chosen: 'rule' or 'explicit' (:attr:`spinectl.model.params.reflex.Reflex.gains`),
        'explicit' when both were given to :func:`margins_report`, e.g. 'explicit kp, rule kd' when one was.
    model : dict
        The model's :func:`~spinectl.model.source.provenance` and its :func:`~spinectl.model.source.header`
        line (key ``header``).
    chain : spinectl.reflex.chain_verdict.ChainReflexVerdict or None
        The chain's verdict at the same point (every CoR free), where it was computed
        (:func:`spinectl.reflex.chain_verdict.margins_with_chain`); None: the segments' alone.
    """

    point: ActivationPoint
    delay: float
    activation_time_constant: float
    pade_order: int
    segments: tuple[SegmentMargins, ...]
    gains: str
    model: dict = field(default_factory=dict)
    chain: object | None = None

    @property
    def all_stable_at_delay(self) -> bool:
        """True if the closed loop of every segment is stable at the delay (exact): joint by joint."""
        return all(s.stable_at_delay for s in self.segments)

    def verdict(self) -> str:
        """The joint-by-joint verdict in words, its criterion first.

        Returns
        -------
        str
            One line: the criterion, then "stable at the delay: all segments" or the unstable ones.
        """
        unstable = [s.name for s in self.segments if not s.stable_at_delay]
        words = "all segments" if not unstable else "NOT " + ", ".join(unstable)
        return f"{stability.criterion('joint', len(self.segments))}: stable at the delay: {words}"

    def to_dict(self) -> dict:
        """The report as a JSON-ready dict: the document of ``spinectl margins --json``.

        Returns
        -------
        dict
            The model's :func:`~spinectl.model.source.provenance` (``preset``, ``config``,
            ``config_sha256``, ``overridden``, ``K_Nm_per_rad`` or ``K_per_s2``, ``K_convention``),
            ``E_m``, ``Lambda_m``, ``delay_s``, ``activation_time_constant_s``, ``pade_order``,
            ``activation``, ``optimum_status``, ``gains``, ``pcsa_cm2`` (muscle name -> PCSA [cm^2]), ``segments`` (one
            :meth:`SegmentMargins.to_dict` each), ``criterion`` (of the segments' verdicts: joint by
            joint), ``all_stable_at_delay`` and, where computed, ``chain`` (the chain's verdict,
            :meth:`spinectl.reflex.chain_verdict.ChainReflexVerdict.to_dict`, with its own ``criterion``);
            the unit is in each key's name.
        """
        point = self.point
        model = {k: v for k, v in self.model.items() if k != "header"}
        return (
            model
            | {
                "E_m": point.eccentricity,
                "Lambda_m": point.lordosis,
                "delay_s": self.delay,
                "activation_time_constant_s": self.activation_time_constant,
                "pade_order": self.pade_order,
                "activation": point.activation,
                "optimum_status": point.status,
                "gains": self.gains,
                "pcsa_cm2": dict(zip(point.muscle_names, m2_to_cm2(point.pcsa).tolist(), strict=True)),
                "segments": [s.to_dict() for s in self.segments],
                "criterion": stability.criterion("joint", len(self.segments)),
                "all_stable_at_delay": self.all_stable_at_delay,
            }
            | ({} if self.chain is None else {"chain": self.chain.to_dict()})
        )

    def table(self) -> str:
        """The report as a readable table, one row a segment, with a header and a key to the columns.

        Where an infinite or missing value has a meaning it is written as a word: "unbounded"
        (a delay margin, gain factor or kp range without limit), "none" (no crossover, no
        stabilising range, not self-stable); "n/a" for a segment without an optimum.

        Returns
        -------
        str
            The text ``spinectl margins`` prints (no final newline).
        """
        point = self.point
        solved = "" if point.status == "optimal" else f" (minimum PCSA: {point.status})"  # was "(optimum: optimal)"
        lines = [
            self.model.get("header", "preset unknown"),
            f"E = {point.eccentricity * 100:.2f} cm, Lambda = {point.lordosis * 100:.2f} cm, "
            f"activation {point.activation:g} x minimum PCSA{solved}, "
            f"delay {self.delay:g} s, activation lag {self.activation_time_constant:g} s, "
            f"Pade order {self.pade_order}, gains: {self.gains}",
            "",
            f"{'segment':8} {'S':>8} {'D':>8} {'theta':>6} {'self-stable':>11} {'T_slow[s]':>9} {'kp':>8} "
            f"{'kd':>7} {'GM low':>7} {'GM up':>9} {'PM[deg]':>8} {'w_c':>7} {'tau_m[s]':>9} {'Pade[s]':>9} "
            f"{'kp range at tau':>21} {'stable':>6}",
        ]
        lines += [_row(s) for s in self.segments]
        lines += [
            "",
            "S, kp in N m/rad; D, kd in N m s/rad; theta in kg m^2; w_c in rad/s. T_slow: slowest time constant",
            "of the segment without reflex. GM: stable range of a common factor on kp and kd. tau_m: exact delay",
            "margin (unbounded: any delay; 0: unstable without delay).",
            *self._kd_note(),
            stability.SIGN_NOTE,
            "",
            self.verdict(),
        ]
        if self.chain is not None:
            lines += self.chain.lines()
        return "\n".join(lines)

    def _kd_note(self) -> list[str]:
        """Where the rule's kd is 0, its formula once: the muscles' own damping is enough there (not a missing kd)."""
        if "explicit" in self.gains and "rule kd" not in self.gains:
            return []
        zero = [s.name for s in self.segments if s.kd == 0.0]
        if not zero:
            return []
        return [
            f"kd: the rule's {gains.KD_RULE} = 0 here at {', '.join(zero)} (the muscles' own damping -D covers "
            "the damping ratio; the chain's rule, margins --coupled and design, has its own kd from the chain)."
        ]


def _row(s: SegmentMargins) -> str:
    """One segment's line of :meth:`MarginsReport.table`."""
    na = "n/a" if np.isnan(s.stiffness) else "none"  # no optimum: nothing is known

    def num(value, width, digits, inf="unbounded"):
        return _num(value, width, digits, inf=inf, nan=na)

    self_stable = "n/a" if na == "n/a" else ("yes" if s.self_stable else "no")
    return (
        f"{s.name:8} {num(s.stiffness, 8, 2)} {num(s.damping, 8, 2)} {num(s.inertia, 6, 3)} {self_stable:>11} "
        f"{num(s.slowest_time_constant, 9, 3, inf='none')} {num(s.kp, 8, 2)} {num(s.kd, 7, 2)} "
        f"{num(s.gain_margin_lower, 7, 3)} {num(s.gain_margin, 9, 3)} {num(s.phase_margin_deg, 8, 2, inf='none')} "
        f"{num(s.crossover_rad_s, 7, 3)} {num(s.delay_margin, 9, 4)} {num(s.delay_margin_pade, 9, 4)} "
        f"[{num(s.kp_min, 9, 1)},{num(s.kp_max, 9, 1)}] {'yes' if s.stable_at_delay else 'NO':>6}"
    )


def _num(value: float, width: int, digits: int, inf: str = "unbounded", nan: str = "none") -> str:
    """``value`` in a column of ``width`` with ``digits`` decimals; infinite and NaN values as the words given."""
    if np.isnan(value):
        return f"{nan:>{width}}"
    if np.isinf(value):
        return f"{('-' if value < 0 else '') + inf:>{width}}"
    return f"{value:{width}.{digits}f}"


def margins_report(model: Model, eccentricity: float, lordosis: float, kp=None, kd=None) -> MarginsReport:
    """Margins of every segment, with the reflex settings of ``model.reflex``.

    Parameters
    ----------
    model : Model
        ``model.reflex`` gives delay, Padé order, activation and gains.
    eccentricity, lordosis : float
        E and Lambda [m].
    kp, kd : float, optional
        Explicit gains for every segment [N m/rad], [N m s/rad], each replacing the configured
        one: finite numbers >= 0, as ``reflex.kp`` and ``reflex.kd`` of a model.

    Returns
    -------
    MarginsReport
        The operating point and one :class:`SegmentMargins` per segment.

    Raises
    ------
    ParameterError
        ``kp`` or ``kd`` not a finite number >= 0 (fields ``reflex.kp``, ``reflex.kd``), or too large
        (:data:`spinectl.reflex.inputs.MAX_MAGNITUDE`); a position outside the modelled range.
    ModelError
        The arithmetic overflows at this position.
    """
    kp = None if kp is None else v.non_negative("reflex.kp", kp)  # the gains of the model's Reflex, checked alike
    kd = None if kd is None else v.non_negative("reflex.kd", kd)
    settings = model.reflex
    point = operating_point(model, eccentricity, lordosis, settings.activation)
    with arithmetic_guard(eccentricity, lordosis):  # absurd gains or delays: a ModelError, not NaN and warnings
        segments = _segments(model, point, settings, kp, kd)
    return MarginsReport(
        point=point,
        delay=settings.delay,
        activation_time_constant=settings.activation_time_constant,
        pade_order=settings.pade_order,
        segments=segments,
        gains=_gains_label(settings.gains, kp, kd),
        model=provenance(model) | {"header": header(model, [s.inertia for s in segments])},
    )


def _gains_label(configured: str, kp, kd) -> str:
    """How the gains were chosen: the configured way, 'explicit' when both were given, or a mix."""
    if kp is None and kd is None:
        return configured
    if kp is not None and kd is not None:
        return "explicit"
    return f"explicit kp, {configured} kd" if kp is not None else f"{configured} kp, explicit kd"


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
            settings.activation_time_constant,
        )
        for k, name in enumerate(model.geometry.cor_names)
    )


@dataclass(frozen=True)
class ReportResponses:
    """What the plots of a :class:`MarginsReport` show, computed (:func:`report_responses`).

    Attributes
    ----------
    loops : dict of str to control.TransferFunction
        Segment name -> its Padé loop L(s) (:func:`spinectl.reflex.loops.loop_transfer`), for each
        segment with a reflex (kp > 0 or kd > 0) whose loop python-control can evaluate.
    simulations : dict of str to Simulation
        Segment name -> two simulated runs, with the reflex (run 0) and without it (run 1)
        (:func:`spinectl.reflex.simulate.simulate`), for each segment with a finite stiffness.
    chain : tuple of Simulation or None
        The chain, every CoR free (:func:`spinectl.reflex.simulate.simulate_chain` of its nonlinear plant), with
        the chain's reflex and without it, every joint perturbed alike; one run per joint each. None where the
        report has no chain verdict or no segment was simulated.
    divergence : float
        ``reflex.sim_divergence`` [rad] of the simulations: a run stops where abs(alpha) exceeds it (its angles
        frozen after); NaN if not recorded.
    """

    loops: dict
    simulations: dict
    chain: tuple | None = None
    divergence: float = float("nan")


RESPONSE_SPAN = 5.0
"""Slowest time constants a simulated response of ``spinectl margins --plot`` spans."""

RESPONSE_SHORTEST = 1.0
"""Shortest simulated response [s]: a few periods of the fastest loops of the spine."""


def slowest_time_constant(segment: SegmentMargins, delay: float, order: int, lag: float) -> float:
    """1 / abs(Re s) of the rightmost root of the segment with its reflex, or without it if it has none [s].

    The rightmost pole of python-control's Padé closed loop (:func:`spinectl.reflex.loops.closed_loop`)
    and of the segment alone (paper, eq. 1): the slower of the two runs that a response plot shows.
    A decaying response settles, and a growing one grows by e, in one such time constant; inf at a
    root on the axis.

    Parameters
    ----------
    segment : SegmentMargins
        A segment with a finite stiffness.
    delay : float
        tau [s].
    order : int
        Order of the Padé approximant.
    lag : float
        Activation time constant T_a [s].

    Returns
    -------
    float
        The time constant [s].
    """
    s, d, theta = segment.stiffness, segment.damping, segment.inertia
    rates = [np.max(np.real(stability.eigenvalues(s, d, theta)))]
    if (segment.kp > 0 or segment.kd > 0) and segment.python_control is not None:
        poles = loops.closed_loop(s, d, theta, segment.kp, segment.kd, delay, order, lag=lag).poles()
        rates.append(np.max(np.real(poles)))
    with np.errstate(divide="ignore"):
        return float(np.max(1.0 / np.abs(rates)))


def response_duration(segment: SegmentMargins, report: MarginsReport, settings) -> float:
    """How long to simulate a segment for its response plot: :data:`RESPONSE_SPAN` slowest time constants [s].

    Between :data:`RESPONSE_SHORTEST` (or ten time steps) and ``settings.sim_duration`` (the longest simulation).

    Parameters
    ----------
    segment : SegmentMargins
        A segment of ``report`` with a finite stiffness.
    report : MarginsReport
        Its report (delay, activation lag, Padé order).
    settings : spinectl.model.params.Reflex
        ``sim_duration`` bounds the result.

    Returns
    -------
    float
        The duration [s].
    """
    slow = slowest_time_constant(segment, report.delay, report.pade_order, report.activation_time_constant)
    shortest = min(max(RESPONSE_SHORTEST, 10 * settings.sim_time_step), settings.sim_duration)
    return float(np.clip(RESPONSE_SPAN * slow, shortest, settings.sim_duration))


def report_responses(model: Model, report: MarginsReport) -> ReportResponses:
    """The loops and the simulated responses of every segment of ``report``: the compute step of its plots.

    Each simulation spans :data:`RESPONSE_SPAN` of the slowest time constants of its two runs
    (:func:`response_duration`), at most ``sim_duration``. A segment without reflex (kp = kd = 0,
    e.g. self-stable under the default rule) has no loop; one whose Padé loop python-control
    cannot evaluate (``python_control`` None: microsecond delays at high orders) neither. A
    segment of an infeasible optimum (NaN stiffness) has neither a loop nor a simulation.

    Parameters
    ----------
    model : Model
        The model of the report (geometry and the simulation settings of ``model.reflex``).
    report : MarginsReport
        Output of :func:`margins_report` for ``model``.

    Returns
    -------
    ReportResponses

    Raises
    ------
    ParameterError
        The simulation cannot run at the report's delay (too many time steps, see
        :func:`spinectl.reflex.simulate.simulate`).
    """
    point = report.point
    usable = [(k, s) for k, s in enumerate(report.segments) if np.isfinite(s.stiffness)]  # NaN: infeasible
    transfer = {
        s.name: loops.loop_transfer(
            s.stiffness,
            s.damping,
            s.inertia,
            s.kp,
            s.kd,
            report.delay,
            report.pade_order,
            report.activation_time_constant,
        )
        for _, s in usable
        if (s.kp > 0 or s.kd > 0) and s.python_control is not None
    }
    simulations = {
        s.name: simulate.simulate(
            simulate.segment_plant(model, point.eccentricity, point.lordosis, k, point.pcsa),
            [s.kp, 0.0],
            [s.kd, 0.0],
            report.delay,
            dataclasses.replace(model.reflex, sim_duration=response_duration(s, report, model.reflex)),
        )
        for k, s in usable
    }
    return ReportResponses(
        loops=transfer, simulations=simulations, chain=_chain_responses(model, report, simulations),
        divergence=model.reflex.sim_divergence,
    )  # fmt: skip


def _chain_responses(model: Model, report: MarginsReport, simulations: dict) -> tuple | None:
    """The chain's response with its reflex and without, over the longest segment's span (see ReportResponses)."""
    point, verdict = report.point, report.chain
    if verdict is None or not simulations or not point.ok:
        return None
    plant = simulate.nonlinear_chain_plant(model, point.eccentricity, point.lordosis, point.pcsa)
    span = max(float(sim.time[-1]) for sim in simulations.values())
    settings = dataclasses.replace(model.reflex, sim_duration=max(span, 10 * model.reflex.sim_time_step))
    kick, none = np.full(len(verdict.kp), model.reflex.sim_perturbation), np.zeros(len(verdict.kp))
    runs = [
        simulate.simulate_chain(plant, kp, kd, [report.delay], settings, kick)[0]
        for kp, kd in ((verdict.kp, verdict.kd), (none, none))
    ]
    return tuple(runs)
