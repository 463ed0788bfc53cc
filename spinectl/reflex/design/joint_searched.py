"""Joint by joint over every PD reflex: each segment's least co-contraction when its (k_p, k_d) are free.

The joint-by-joint design (:mod:`~spinectl.reflex.design.joint`) answers for the reflex rule at each
activation. Here each segment's gains are searched instead: at an activation a, the segment's exact delay
margin with the lag (:func:`spinectl.reflex.delay.delay_margin`, vectorised) over a log grid of
:data:`GRID` x :data:`GRID` gains, :data:`DECADES` decades each side of the rule's (or of the segment's own
scale where the rule gives none), with the rule's gains and none at all; the best is accepted only with the
certificate of the chain's design, its margin at least the delay and the rightmost root of the segment's
characteristic equation at the delay (:func:`~spinectl.reflex.design.roots.rightmost_root` on the 1 x 1
chain, Chebyshev seeds) on the left. Each segment's activation is bisected in [0, a_rule] (its rule's
answer, a candidate with the rule's gains, so never above it; in [0, 1] where the rule has none, so that the
search starts from no reflex and the grid rather than from the rule) in :data:`HALVINGS` halvings; the common
activation is the largest of them, certified again at every segment. As for the chain, whether the least
activation is monotone for some gains is not known, so the answer is the least certified, not a proof.
A grid of the segment's two gains costs milliseconds, so the whole answer does too.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...model.checks import arithmetic_guard, checked_coefficients
from ...model.params import Model
from ...optimise.reference import solve_point
from .. import gains
from ..delay import delay_margin
from .result import gains_text
from .roots import SPECTRAL_NODES, rightmost_root

GRID = 61
"""Gains per axis of each segment's grid (k_p and k_d): 3,721 exact margins in one vectorised call."""

DECADES = 1.5
"""Half-width of the grid in decades of each gain around its centre."""

HALVINGS = 20
"""Halvings of [0, a_rule] per segment: the answer to 1e-6 of a_rule above the least certified."""

SEARCHED_JOINT_REFLEX = "any PD gains per segment, searched on a grid"
"""The reflex the joint-by-joint searched answer assumes."""


@dataclass(frozen=True)
class JointSearchedDesign:
    """Joint by joint, the least co-contraction the gain grid certified, every segment's gains free.

    Attributes
    ----------
    activation : float
        The least common activation certified [1] (at most the rule's); NaN if the rule has none.
    pcsa : float
        The total PCSA there [m^2].
    names : tuple of str
    segment_activation : numpy.ndarray, shape (n_cor,)
        Each segment's own least activation certified [1].
    kp, kd : numpy.ndarray, shape (n_cor,)
        Each segment's certified gains at the common activation [N m/rad], [N m s/rad].
    delay_margin : numpy.ndarray, shape (n_cor,)
        Their exact margins there [s].
    max_root_real : numpy.ndarray, shape (n_cor,)
        Re of each segment's rightmost root at the delay [1/s].
    rule_kd : numpy.ndarray or None, shape (n_cor,)
        Where the rule has no design: the rule's k_d of each segment at the searched activation
        [N m s/rad], the reflex the rule's infeasibility rests on; None otherwise.
    no_reflex_margin : numpy.ndarray or None, shape (n_cor,)
        Where the rule has no design: each segment's exact margin there with no reflex (k_p = k_d = 0) [s].
    """

    activation: float
    pcsa: float
    names: tuple
    segment_activation: np.ndarray
    kp: np.ndarray
    kd: np.ndarray
    delay_margin: np.ndarray
    max_root_real: np.ndarray
    rule_kd: np.ndarray | None = None
    no_reflex_margin: np.ndarray | None = None

    def to_dict(self) -> dict:
        """``reflex``, ``activation``, ``pcsa_cm2``, ``segments`` (name, activation, gains, margin, root), ``grid``.

        Returns
        -------
        dict
        """
        segments = [
            {
                "name": n,
                "activation": float(self.segment_activation[k]),
                "kp_Nm_per_rad": float(self.kp[k]),
                "kd_Nms_per_rad": float(self.kd[k]),
                "delay_margin_s": float(self.delay_margin[k]),
                "max_root_real_per_s": float(self.max_root_real[k]),
            }
            for k, n in enumerate(self.names)
        ]
        return {
            "reflex": SEARCHED_JOINT_REFLEX,
            "activation": self.activation,
            "pcsa_cm2": 1e4 * self.pcsa,
            "segments": segments,
            "grid": {"gains_per_axis": GRID, "decades_each_side": DECADES, "halvings": HALVINGS},
        } | self._failure_dict()

    def _failure_dict(self) -> dict:
        """Where the rule has no design: its k_d and the margins with no reflex at the searched activation."""
        if self.rule_kd is None or self.no_reflex_margin is None:
            return {}
        margins = [None if np.isinf(m) else float(m) for m in self.no_reflex_margin]
        return {"rule_kd_Nms_per_rad": self.rule_kd.tolist(), "no_reflex_delay_margin_s": margins}

    def lines(self, rule_activation: float, whose: str = "the rule's") -> list[str]:
        """The table's lines, beside the rule's (or the given gains') common activation.

        Parameters
        ----------
        rule_activation : float
            The answer under the design's own reflex, one activation for every segment [x minimum PCSA].
        whose : str
            Whose answer that is, as the line names it: ``"the rule's"`` or ``"the given gains'"``.

        Returns
        -------
        list of str
        """
        if not np.isfinite(self.activation):
            return [
                f"over {SEARCHED_JOINT_REFLEX}: none in [0, 1] either (searched from no reflex and the grid, "
                "the rule having no design)"
            ]
        if np.isfinite(rule_activation):
            less = 100 * (1 - self.activation / rule_activation) if rule_activation > 0 else 0.0
            beside = f"{whose} {rule_activation:.4f}, {less:.0f} % less"
        else:
            beside = f"{whose.removesuffix(chr(39) + 's').removesuffix(chr(39))} have none: searched in [0, 1]"
        return [
            *self._rule_failure_lines(),
            f"over {SEARCHED_JOINT_REFLEX}: activation {self.activation:.4f} x minimum PCSA "
            f"({1e4 * self.pcsa:.2f} cm^2; {beside})",
            "  each segment's own: "
            + ", ".join(f"{n} {a:.4f}" for n, a in zip(self.names, self.segment_activation, strict=True)),
            "  gains there: " + gains_text(self.names, self.kp, self.kd),
            "  certificate: exact margins "
            + ", ".join(f"{1000 * m:.1f}" for m in self.delay_margin)
            + f" ms; rightmost roots Re s <= {np.max(self.max_root_real):.4g} 1/s "
            f"(grid {GRID} x {GRID} gains, {DECADES:g} decades each side, {HALVINGS} halvings)",
        ]

    def _rule_failure_lines(self) -> list[str]:
        """Where the rule has no design: the reflex its infeasibility rests on, and the remedy."""
        if self.rule_kd is None or self.no_reflex_margin is None:
            return []
        free = bool(np.all(self.no_reflex_margin >= 0) and np.all(np.isinf(self.no_reflex_margin)))
        without = (
            "without a reflex every segment is stable at every delay (margins unbounded: margins --kp 0 --kd 0)"
            if free
            else "without a reflex the exact margins are "
            + ", ".join(f"{1000 * m:.1f}" for m in self.no_reflex_margin)
            + " ms"
        )
        return [
            f"  the infeasibility rests on the reflex rule: at activation {self.activation:.4f} its own gains "
            f"(k_d {np.min(self.rule_kd):.3g}-{np.max(self.rule_kd):.3g} N m s/rad) destabilise the segments; "
            f"{without}; remedy: no reflex, or other gains (below; the chain's: --gains search)"
        ]


class _Segments:
    """The segments at the position: each one's loop at an activation, its best gains and their certificate."""

    def __init__(self, model: Model, e: float, lam: float, kp=None, kd=None):
        self.model, self.kp, self.kd = model, kp, kd
        self.coefficients = checked_coefficients(model, e, lam)
        self.optimum = np.asarray(solve_point(model, e, lam).pcsa, float)
        self.delay, self.lag = model.reflex.delay, model.reflex.activation_time_constant
        steps = 10.0 ** np.linspace(-DECADES, DECADES, GRID)
        self.p_steps, self.d_steps = (x.ravel() for x in np.meshgrid(steps, steps))

    def plant(self, k: int, a: float):
        """(S, D, theta) of segment k at activation a."""
        p = a * self.optimum
        return self.coefficients.stiffness(p)[k], self.coefficients.damping(p)[k], self.coefficients.inertia[k]

    def best(self, k: int, a: float):
        """(kp, kd, margin) of the best gains on the grid around the rule's, the rule's and none, at a."""
        s, d, theta = self.plant(k, a)
        rule_p, rule_d = (
            float(x[0]) for x in gains.resolve_gains([s], [d], [theta], self.model.reflex, self.kp, self.kd)
        )
        centre_p = max(rule_p, abs(s), 1.0)  # the rule gives no k_p to a self-stable segment: its own scale
        centre_d = max(rule_d, np.sqrt(theta * centre_p))
        kps = np.concatenate([centre_p * self.p_steps, [rule_p, 0.0]])
        kds = np.concatenate([centre_d * self.d_steps, [rule_d, 0.0]])
        with np.errstate(all="ignore"):
            margins = np.asarray(delay_margin(s, d, theta, kps, kds, self.lag).margin, float)
        i = int(np.nanargmax(np.where(np.isnan(margins), -np.inf, margins)))
        return kps[i], kds[i], float(margins[i])

    def rule_kd(self, k: int, a: float) -> float:
        """The rule's (or the explicit) k_d of segment k at activation a [N m s/rad]."""
        s, d, theta = self.plant(k, a)
        return float(gains.resolve_gains([s], [d], [theta], self.model.reflex, self.kp, self.kd)[1][0])

    def no_reflex_margin(self, k: int, a: float) -> float:
        """Segment k's exact margin at activation a with no reflex [s]."""
        s, d, theta = self.plant(k, a)
        with np.errstate(all="ignore"):
            return float(np.asarray(delay_margin(s, d, theta, 0.0, 0.0, self.lag).margin))

    def certify(self, k: int, a: float):
        """(kp, kd, margin, root's Re) if the best gains hold segment k at a at the delay, else None."""
        kp, kd, margin = self.best(k, a)
        if not margin >= self.delay:
            return None
        s, d, theta = self.plant(k, a)
        root = rightmost_root([[theta]], [[s]], [[d]], [kp], [kd], self.delay, self.lag, SPECTRAL_NODES)
        return (kp, kd, margin, float(root.real)) if root.real < 0 else None

    def least(self, k: int, rule: float) -> float:
        """Segment k's least activation certified in [0, rule] (the rule's answer, itself certified by the rule).

        Where the rule has none (``rule`` NaN) in [0, 1], NaN if the grid holds the segment nowhere there.
        """
        if self.certify(k, 0.0) is not None:
            return 0.0
        if not np.isfinite(rule):
            if self.certify(k, 1.0) is None:
                return np.nan
            rule = 1.0
        lo, hi = 0.0, rule
        for _ in range(HALVINGS):
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if self.certify(k, mid) is not None else (mid, hi)
        return hi


def joint_searched_design(model: Model, eccentricity: float, lordosis: float, design, kp=None, kd=None):
    """Joint by joint over every PD reflex per segment: the least co-contraction certified (see the module).

    Parameters
    ----------
    model : Model
        ``model.reflex``: the delay, lag and the rule (or explicit gains) the grid centres on.
    eccentricity, lordosis : float
        E and Lambda [m].
    design : Design
        The rule's answer at the same delay (:func:`~spinectl.reflex.design.curve.design`): each segment's
        activation bounds its search.
    kp, kd : float, optional
        Explicit gains the grid centres on.

    Returns
    -------
    JointSearchedDesign
    """
    e, lam = float(eccentricity), float(lordosis)
    names = tuple(s.name for s in design.segments)
    rule = np.array([s.activation for s in design.segments], float)
    n = len(names)
    nan = np.full(n, np.nan)
    segments = _Segments(model, e, lam, kp, kd)
    if not np.all(np.isfinite(segments.optimum)):
        return JointSearchedDesign(np.nan, np.nan, names, nan, nan, nan, nan, nan)
    with arithmetic_guard(e, lam):
        own = np.array([segments.least(k, rule[k]) for k in range(n)])
        if not np.all(np.isfinite(own)):  # the grid holds some segment nowhere in [0, 1]
            return JointSearchedDesign(np.nan, np.nan, names, own, nan, nan, nan, nan)
        common = float(np.max(own))
        held = [segments.certify(k, common) for k in range(n)]
        if any(h is None for h in held) and np.isfinite(design.activation):  # held below, not at the common one
            common = design.activation
            held = [segments.certify(k, common) for k in range(n)]
    if any(h is None for h in held):  # the rule's own gains at its answer are the certificate there
        return JointSearchedDesign(design.activation, design.pcsa, names, rule, nan, nan, nan, nan)
    kps, kds, margins, roots = (np.array(x, float) for x in zip(*held, strict=True))
    pcsa = common * float(np.sum(segments.optimum))
    failure = {}
    if not np.isfinite(design.activation):  # name the reflex the rule's infeasibility rests on
        failure = {
            "rule_kd": np.array([segments.rule_kd(k, common) for k in range(n)]),
            "no_reflex_margin": np.array([segments.no_reflex_margin(k, common) for k in range(n)]),
        }
    return JointSearchedDesign(common, pcsa, names, own, kps, kds, margins, roots, **failure)
