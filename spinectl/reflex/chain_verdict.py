"""The chain's verdict beside the segments': what ``spinectl margins`` prints by default (docs/chain.md).

``spinectl margins`` judges each segment alone, the others fixed (the paper's criterion). The
same operating point and the same reflex rule on the whole chain, every CoR free, can give the
opposite answer; so the report carries both. The chain at the operating point costs milliseconds
(:func:`spinectl.model.operating_point.chain_at`; its modes, :func:`spinectl.model.stability.modes_of`),
its least local stiffness one small Clarabel problem
(:func:`spinectl.optimise.coupled.least_local_stiffness_stacked`, the deficit the rule
:func:`spinectl.reflex.gains.chain_gains` compensates) and its exact delay margin one delay-free eigenvalue
problem (:func:`spinectl.reflex.mimo.chain_delay_margin`); ``--coupled`` keeps the full report (disk margins,
Padé loop: :mod:`spinectl.reflex.chain_margins`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..model.checks import arithmetic_guard
from ..model.operating_point import OperatingPoint, chain_at
from ..model.params import Model
from ..model.stability import CHAIN_DEPENDS_ON, ChainModes, criterion, modes_of
from ..optimise.coupled import least_local_stiffness_stacked
from .chain_margins import stable_at
from .delay import delay_text
from .gains import resolve_chain_gains
from .margins import ActivationPoint, MarginsReport, margins_report
from .mimo import chain_delay_margin
from .siso import LoopDelayMargin


@dataclass(frozen=True)
class ChainReflexVerdict:
    """The chain under the delayed reflex at the operating point of :class:`~spinectl.reflex.margins.MarginsReport`.

    Attributes
    ----------
    delay : float
        tau [s].
    kp, kd : numpy.ndarray, shape (n_cor,)
        The gains at each joint [N m/rad], [N m s/rad]: the rule on the chain
        (:func:`~spinectl.reflex.gains.chain_gains`) or the explicit ones.
    local_stiffness : numpy.ndarray, shape (n_cor,)
        The least local stiffness for static stability [N m/rad] (problem (a) of docs/chain.md):
        the chain's deficit that the rule compensates.
    exact : LoopDelayMargin
        The chain's exact delay margin (:func:`~spinectl.reflex.mimo.chain_delay_margin`).
    stable_at_delay : bool
    modes : ChainModes
        The chain without reflex at the operating point: the modes the reflex has to hold.
    """

    delay: float
    kp: np.ndarray
    kd: np.ndarray
    local_stiffness: np.ndarray
    exact: LoopDelayMargin
    stable_at_delay: bool
    modes: ChainModes

    @property
    def criterion(self) -> str:
        """The criterion's words: the chain, every CoR free."""
        return criterion("chain", len(self.kp))

    def to_dict(self) -> dict:
        """The chain's verdict as a JSON-ready dict (the ``chain`` of ``spinectl margins --json``).

        Returns
        -------
        dict
            ``criterion``, ``stable_at_delay``, ``delay_margin_s``, ``delay_margin_status``,
            ``delay_margin_frequency_rad_s``, ``kp_Nm_per_rad``, ``kd_Nms_per_rad``,
            ``least_local_stiffness_Nm_per_rad`` (per joint), ``without_reflex``
            (:meth:`~spinectl.model.stability.ChainModes.to_dict`) and ``depends_on``.
        """
        return {
            "criterion": self.criterion,
            "stable_at_delay": self.stable_at_delay,
            "delay_margin_s": float(self.exact.margin),
            "delay_margin_status": self.exact.status,
            "delay_margin_frequency_rad_s": float(self.exact.frequency),
            "kp_Nm_per_rad": self.kp.tolist(),
            "kd_Nms_per_rad": self.kd.tolist(),
            "least_local_stiffness_Nm_per_rad": self.local_stiffness.tolist(),
            "without_reflex": self.modes.to_dict(),
            "depends_on": CHAIN_DEPENDS_ON,
        }

    def lines(self) -> list[str]:
        """The chain's verdict as lines of text: the verdict, the margin and what limits it.

        Returns
        -------
        list of str
            The verdict with its criterion and the exact delay margin, the modes without reflex,
            and where unstable what limits the margin and what would help.
        """
        exact = self.exact
        if not self.modes.defined:
            return [self.modes.summary()]
        margin = delay_text(exact.margin)
        where = f" at {exact.frequency:.4g} rad/s" if np.isfinite(exact.frequency) else ""
        word = "stable" if self.stable_at_delay else "NOT stable"
        lines = [
            f"{self.criterion}, the same reflex rule at every joint (gains from each joint's own stiffness): "
            f"{word} at the delay {delay_text(self.delay)} "
            f"(exact delay margin {margin}{where})",
            "  without reflex: " + self.modes.summary().split(": ", 1)[1],
        ]
        if not self.stable_at_delay:
            lines.append(
                "  the margin is set by the modes that bend the joints against each other; it grows with the levels' "
                "inertia (levels.mass, levels.radius_of_gyration); intrinsic local stiffness holds them: "
                "spinectl design; the full chain report: --coupled"
            )
        return lines


def chain_verdict(
    model: Model, point: ActivationPoint, delay: float, lag: float, kp=None, kd=None
) -> ChainReflexVerdict:
    """The chain at ``point`` under the delayed reflex: the rule on the chain, or the explicit gains.

    Parameters
    ----------
    model : Model
        ``model.reflex`` gives the rule's settings and its ``gains`` ('rule' or 'explicit').
    point : ActivationPoint
        The operating point of :func:`spinectl.reflex.margins.operating_point`.
    delay, lag : float
        tau [s] and T_a [s].
    kp, kd : float, optional
        One gain for every joint [N m/rad], [N m s/rad], replacing the configured or rule's.

    Returns
    -------
    ChainReflexVerdict
        NaN margins (status 'undefined') where the point has no optimum or the mass matrix is singular.
    """
    e, lam = point.eccentricity, point.lordosis
    settings, n = model.reflex, len(model.geometry.cor_names)
    pcsa = point.pcsa if point.ok else np.zeros_like(point.pcsa)
    linear = chain_at(OperatingPoint(model, e, lam, pcsa, slip_check=False))
    modes = modes_of(linear, guard=arithmetic_guard(e, lam))
    mass, stiffness, damping = linear.mass_matrix, linear.stiffness_offset, linear.damping_offset
    if not (point.ok and modes.defined):  # no optimum, or levels without mass: nothing to judge
        nan = np.full(n, np.nan)
        modes = dataclasses.replace(modes, eigenvalues=np.full(2 * n, complex(np.nan, np.nan)))  # no optimum: undefined
        exact = chain_delay_margin(np.eye(n), np.full((n, n), np.nan), np.zeros((n, n)), nan, nan, lag)
        return ChainReflexVerdict(delay, nan, nan, nan, exact, False, modes)
    _, local = least_local_stiffness_stacked(stiffness[None], model.optimisation.stability_margin)
    local = local[0]
    kp, kd = resolve_chain_gains(settings, mass, stiffness, damping, local, kp, kd)
    with arithmetic_guard(e, lam):
        exact = chain_delay_margin(mass, stiffness, damping, kp, kd, lag)
    return ChainReflexVerdict(delay, kp, kd, local, exact, stable_at(exact, delay), modes)


def margins_with_chain(model: Model, eccentricity: float, lordosis: float, kp=None, kd=None) -> MarginsReport:
    """Every segment's margins (:func:`spinectl.reflex.margins.margins_report`) and the chain's verdict beside them.

    Parameters
    ----------
    model : Model
        ``model.reflex`` gives delay, Padé order, activation and gains.
    eccentricity, lordosis : float
        E and Lambda [m].
    kp, kd : float, optional
        Explicit gains for every segment and joint [N m/rad], [N m s/rad].

    Returns
    -------
    MarginsReport
        With ``chain`` a :class:`ChainReflexVerdict`.

    Raises
    ------
    ParameterError
        As :func:`~spinectl.reflex.margins.margins_report`.
    ModelError
        As :func:`~spinectl.reflex.margins.margins_report`.
    """
    report = margins_report(model, eccentricity, lordosis, kp=kp, kd=kd)
    verdict = chain_verdict(model, report.point, report.delay, report.activation_time_constant, kp=kp, kd=kd)
    return dataclasses.replace(report, chain=verdict)
