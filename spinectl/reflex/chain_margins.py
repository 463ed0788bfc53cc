"""Reflex margins of the whole chain at one configuration: ``spinectl margins --coupled`` (docs/chain.md).

The margins of any linearised chain under the diagonal delayed reflex are :func:`chain_reflex_margins`
(on a :class:`~spinectl.model.linear_chain.LinearChain`); the paper's chain at the operating point of
``spinectl margins`` (``reflex.activation`` times the per-segment optimum) is :func:`coupled_margins`:
the rule's diagonal gains (:func:`spinectl.reflex.gains.chain_gains`, or the configured or given ones),
the exact delay margin (:func:`spinectl.reflex.mimo.chain_delay_margin`), its Padé estimate and the
disk margins of the Padé loop.
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass

import numpy as np

from ..model.checks import arithmetic_guard
from ..model.linear_chain import LinearChain
from ..model.params import Model
from ..model.stability import criterion
from ..optimise.coupled import CoupledStability, coupled_stability_at
from .chain_system import DiskMargins, chain_disk_margins, linear_chain_loop
from .delay import delay_text
from .gains import resolve_chain_gains
from .margins import _num, operating_point
from .mimo import highest_crossing, linear_chain_delay_margin, pade_margin
from .siso import LoopDelayMargin

DISK_POINTS = 600
"""Frequencies of the disk-margin sweep, log-spaced from 0.01 rad/s to ten times the highest crossing."""


def stable_at(exact: LoopDelayMargin, delay: float) -> bool:
    """Is the loop stable at ``delay``? Count the root pairs that crossed on [0, delay).

    Each critical delay below ``delay`` moves a pair of roots across the imaginary axis in its
    direction (:meth:`~spinectl.reflex.siso.LoopDelayMargin.critical_delays`); stable iff stable
    without delay and none is left on the right.

    Parameters
    ----------
    exact : LoopDelayMargin
    delay : float
        tau [s].

    Returns
    -------
    bool
    """
    if not exact.stable_without_delay:
        return False
    if exact.margin == np.inf:
        return True
    return sum(d for t, _, d in exact.critical_delays(delay) if t < delay) == 0 and exact.margin != delay


@dataclass(frozen=True)
class ChainReflexMargins:
    """Any linearised chain under the diagonal delayed reflex: its margins.

    Attributes
    ----------
    exact : LoopDelayMargin
        The exact delay margin and the crossings (:func:`spinectl.reflex.mimo.chain_delay_margin`).
    delay_margin_pade : float
        The Padé loop's delay margin [s].
    stable_at_delay : bool
        The true-delay loop is stable at the delay.
    disk : DiskMargins or None
        Of the Padé loop at the delay; None where that loop is unstable (no margin to speak of).
    """

    exact: LoopDelayMargin
    delay_margin_pade: float
    stable_at_delay: bool
    disk: DiskMargins | None


def chain_reflex_margins(
    chain: LinearChain, kp, kd, delay: float, order: int, lag: float, u=(), guard=contextlib.nullcontext
) -> ChainReflexMargins:
    """The exact and Padé delay margins and the disk margins of a chain at its controls ``u``.

    Parameters
    ----------
    chain : LinearChain
        M, K(u), D(u); fixed at an activation (:meth:`LinearChain.at`), ``u`` is empty.
    kp, kd : array_like, shape (n,)
        Diagonal gains [N m/rad], [N m s/rad].
    delay : float
        tau [s].
    order : int
        Padé order.
    lag : float
        T_a [s]; 0 none.
    u : array_like, shape (m,)
        The controls [control unit].
    guard : callable
        A context manager factory around the exact margin (the paper's: numpy's floating-point
        errors as a :class:`~spinectl.errors.ModelError` naming the configuration); none by default.

    Returns
    -------
    ChainReflexMargins

    Raises
    ------
    ModelError
        M is singular (for the disk margins of a loop stable at the delay).

    References
    ----------
    Seiler P, Packard A, Gahinet P (2020). An introduction to disk margins. IEEE Control
    Systems Magazine 40(5):78-95. doi:10.1109/MCS.2020.3005277.
    """
    with guard():  # gains or delays orders of magnitude off: the caller's error
        exact = linear_chain_delay_margin(chain, kp, kd, lag, u)
    stable = stable_at(exact, delay)
    disk = None
    if stable:
        loop = linear_chain_loop(chain, kp, kd, delay, order, lag, u)
        top = highest_crossing(chain.mass_matrix, chain.stiffness(u), chain.damping(u), kp, kd)
        disk = chain_disk_margins(loop, np.logspace(-2, np.log10(10.0 * top), DISK_POINTS))
    return ChainReflexMargins(exact, pade_margin(exact, order), stable, disk)


@dataclass(frozen=True)
class CoupledMargins:
    """The chain under the diagonal delayed reflex at one configuration.

    Attributes
    ----------
    chain : CoupledStability
        The matrices, the least local stiffness and the eigenvalues at the operating point.
    activation : float
        Fraction of the per-segment minimum PCSA [1].
    delay : float
        tau [s].
    activation_time_constant : float
        T_a [s].
    pade_order : int
    gains : str
        'rule' (:func:`spinectl.reflex.gains.chain_gains`) or 'explicit'.
    kp, kd : numpy.ndarray, shape (n_cor,)
        [N m/rad], [N m s/rad].
    exact : LoopDelayMargin
        The exact delay margin and the crossings (:func:`spinectl.reflex.mimo.chain_delay_margin`).
    delay_margin_pade : float
        The Padé loop's delay margin [s].
    stable_at_delay : bool
        The true-delay loop is stable at ``delay``.
    disk : DiskMargins or None
        Of the Padé loop at ``delay``; None where that loop is unstable (no margin to speak of).
    """

    chain: CoupledStability
    activation: float
    delay: float
    activation_time_constant: float
    pade_order: int
    gains: str
    kp: np.ndarray
    kd: np.ndarray
    exact: LoopDelayMargin
    delay_margin_pade: float
    stable_at_delay: bool
    disk: DiskMargins | None

    def to_dict(self, model: Model) -> dict:
        """The document of ``spinectl margins --coupled --json``.

        Parameters
        ----------
        model : Model
            The model of the result.

        Returns
        -------
        dict
            :meth:`CoupledStability.to_dict <spinectl.optimise.coupled.at_activation.CoupledStability.to_dict>`
            with ``delay_s``, ``activation_time_constant_s``, ``pade_order``, ``activation`` and
            ``gains``, and under ``coupled`` also ``kp_Nm_per_rad``, ``kd_Nms_per_rad`` (per joint),
            ``delay_margin_s``, ``delay_margin_status``, ``delay_margin_frequency_rad_s``,
            ``delay_margin_pade_s``, ``disk_margin``, ``disk_gain_margin`` (a factor),
            ``disk_phase_margin_deg``, ``disk_loop_at_a_time`` (per joint: ``disk_margin``,
            ``disk_gain_margin``, ``disk_phase_margin_deg``) and ``stable_at_delay``; the disk
            margins NaN where the loop is unstable at the delay; ``criterion``, the chain's (all CoRs
            free), names these verdicts too; ``pcsa_source`` is 'activation'
            (``activation`` x the minimum stabilising PCSA per segment).
        """
        out = self.chain.to_dict(model, pcsa_source="activation")
        out.update(
            delay_s=self.delay,
            activation_time_constant_s=self.activation_time_constant,
            pade_order=self.pade_order,
            activation=self.activation,
            gains=self.gains,
        )
        disk = self.disk
        single = np.full((len(self.kp), 3), np.nan) if disk is None else disk.loop_at_a_time
        out["coupled"].update(
            kp_Nm_per_rad=self.kp.tolist(),
            kd_Nms_per_rad=self.kd.tolist(),
            delay_margin_s=float(self.exact.margin),
            delay_margin_status=self.exact.status,
            delay_margin_frequency_rad_s=float(self.exact.frequency),
            delay_margin_pade_s=float(self.delay_margin_pade),
            disk_margin=np.nan if disk is None else disk.disk_margin,
            disk_gain_margin=np.nan if disk is None else disk.gain_margin,
            disk_phase_margin_deg=np.nan if disk is None else disk.phase_margin_deg,
            disk_loop_at_a_time=[
                {"disk_margin": a, "disk_gain_margin": g, "disk_phase_margin_deg": p} for a, g, p in single.tolist()
            ],
            stable_at_delay=self.stable_at_delay,
        )
        return out

    def table(self, model: Model) -> str:
        """The chain's table (:meth:`CoupledStability.table`) and the reflex's margins.

        Parameters
        ----------
        model : Model

        Returns
        -------
        str
            Text, no final newline; the verdict at the delay starts with its criterion, the chain's.
        """
        exact, disk = self.exact, self.disk
        margin = delay_text(exact.margin)
        where = f" at {exact.frequency:.4g} rad/s" if np.isfinite(exact.frequency) else ""
        lines = [
            self.chain.table(model, pcsa_source="activation", activation=self.activation),
            "",
            f"delayed reflex on the chain: activation {self.activation:g} x minimum PCSA, delay {self.delay:g} s, "
            f"activation lag {self.activation_time_constant:g} s, gains: {self.gains}",
            f"{'joint':8} {'kp [N m/rad]':>13} {'kd [N m s/rad]':>15} {'disk alpha':>11} {'GM':>9} {'PM[deg]':>8}",
        ]
        single = np.full((len(self.kp), 3), np.nan) if disk is None else disk.loop_at_a_time
        for name, kp, kd, (a, g, p) in zip(self.chain.segment_names, self.kp, self.kd, single, strict=True):
            lines.append(f"{name:8} {kp:13.3f} {kd:15.4f} {_num(a, 11, 3)} {_num(g, 9, 3)} {_num(p, 8, 2)}")
        lines += [
            f"exact delay margin {margin}{where} ({exact.status}); Pade order {self.pade_order}: "
            f"{delay_text(self.delay_margin_pade)}",
            f"{criterion('chain', len(self.kp))}: stable at the delay: {'yes' if self.stable_at_delay else 'NO'}",
            "multiloop disk margin: "
            + (
                "none (the loop is unstable at the delay)"
                if disk is None
                else f"alpha {disk.disk_margin:.3f}, gain factor {disk.gain_margin:.3f}, "
                f"phase {disk.phase_margin_deg:.2f} deg (per joint, the others closed: the table)"
            ),
        ]
        return "\n".join(lines)


def coupled_margins(model: Model, eccentricity: float, lordosis: float, kp=None, kd=None) -> CoupledMargins:
    """The chain's reflex margins with the settings of ``model.reflex`` (see the module).

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    kp, kd : float, optional
        One gain for every joint [N m/rad], [N m s/rad], replacing the configured or rule's.

    Returns
    -------
    CoupledMargins

    Raises
    ------
    ModelError
        No per-segment optimum at (E, Lambda), or the mass matrix is singular.
    ParameterError
        E or Lambda out of range.

    References
    ----------
    Seiler P, Packard A, Gahinet P (2020). An introduction to disk margins. IEEE Control
    Systems Magazine 40(5):78-95. doi:10.1109/MCS.2020.3005277.
    """
    settings = model.reflex
    point = operating_point(model, eccentricity, lordosis, settings.activation)
    pcsa = point.pcsa if point.ok else None  # None: coupled_stability_at says why there is no optimum
    chain = coupled_stability_at(model, eccentricity, lordosis, pcsa)
    lag = settings.activation_time_constant
    kp, kd = resolve_chain_gains(
        settings, chain.mass, chain.stiffness, chain.damping, chain.local.local_stiffness, kp, kd
    )
    margins = chain_reflex_margins(
        chain.linear_chain, kp, kd, settings.delay, settings.pade_order, lag,
        guard=lambda: arithmetic_guard(eccentricity, lordosis),
    )  # fmt: skip
    return CoupledMargins(
        chain=chain,
        activation=settings.activation,
        delay=settings.delay,
        activation_time_constant=lag,
        pade_order=settings.pade_order,
        gains=settings.gains,
        kp=kp,
        kd=kd,
        exact=margins.exact,
        delay_margin_pade=margins.delay_margin_pade,
        stable_at_delay=margins.stable_at_delay,
        disk=margins.disk,
    )
