"""The answers of the design question as data: one delay (:class:`Design`) and the curve (:class:`DesignCurve`).

Each answer has its JSON document (``to_dict``) and its table (``table``); the computations are in
:mod:`~spinectl.reflex.design.joint` (joint by joint), :mod:`~spinectl.reflex.design.chain` (the chain) and
:mod:`~spinectl.reflex.design.curve` (both, at one delay or against the delay).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...model.stability import criterion
from ...units import m2_to_cm2
from ..delay import delay_text

LOCAL_MAX = 2.0
"""Largest local stiffness searched with explicit gains, as a multiple of the least for static stability k*
(the rule's reflex vanishes at 1 k*, where the search ends)."""


RULE_REFLEX = "the reflex rule, (1 - f)+ x the rule's gains"
GIVEN_REFLEX = "the given gains kp, kd at every joint"
"""The reflex the chain's answer assumes, as the table and JSON label it: the rule's, or the gains given."""


BOUNDARY_RTOL = 1e-3
"""A chain design's margin more than this above the delay (relative) did not stop on the delay: the least
stiffness is where the margin jumps past it (at K = 40 N m/rad, 376 ms against 120 ms), not a boundary at it."""


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
        Re of the rightmost characteristic root at the delay [1/s]
        (:func:`~spinectl.reflex.design.roots.rightmost_root`).
    largest_delay : float
        The largest delay met by any local stiffness the search tried [s]: the largest exact margin
        there (with the design's own); inf (JSON null, "unbounded") when one is stable at every delay, e.g. the
        rule's f = 1, which has no reflex. The same meaning as :attr:`Design.largest_delay` joint by joint.
    method : str
    pcsa : float
        The global PCSA the chain used [m^2]: ``activation`` times the minimum stabilising PCSA at this
        (E, Lambda, K); NaN if not recorded.
    kp, kd : numpy.ndarray or None, shape (n_cor,)
        The reflex gains at the design [N m/rad], [N m s/rad]; None if not recorded.
    reflex : str
        The reflex the answer assumes (:data:`~spinectl.reflex.design.gain_searched.RULE_REFLEX`); '' if not recorded.
    """

    activation: float
    fraction: float
    local_stiffness: np.ndarray
    least_static: np.ndarray
    delay_margin: float
    max_root_real: float
    largest_delay: float
    method: str
    pcsa: float = float("nan")
    kp: np.ndarray | None = None
    kd: np.ndarray | None = None
    reflex: str = ""

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
        } | self._used()

    def _used(self) -> dict:
        """The reflex assumed, the global PCSA and the gains, where recorded."""
        if not self.reflex:
            return {}
        return {
            "reflex": self.reflex,
            "global_pcsa_cm2": float(m2_to_cm2(self.pcsa)),
            "kp_Nm_per_rad": None if self.kp is None else self.kp.tolist(),
            "kd_Nms_per_rad": None if self.kd is None else self.kd.tolist(),
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
    margin_ratio : float
        R of ``--margin R``: the design holds every delay up to R x :attr:`nominal_delay` (1: at the delay).
    nominal_delay : float
        The delay asked for [s]; :attr:`delay` is R times it.
    margin_cost : object or None
        The chain's design at 1.1 x the delay, what a modest margin costs (None where not computed).
    searched : object or None
        The chain's design over every diagonal PD reflex (``--gains search``,
        :class:`~spinectl.reflex.design.gain_searched.GainSearchedDesign`), or None.
    joint_searched : object or None
        Joint by joint over every segment's PD gains
        (:class:`~spinectl.reflex.design.joint_searched.JointSearchedDesign`), or None.
    decay_rate : float
        sigma of ``--decay-rate``: the chain's design has every root at the delay at Re s < -sigma [1/s]; 0, none.
    nominal_design : object or None
        Where ``--margin R`` > 1: the chain's design at the delay asked for (:attr:`nominal_delay`), a
        :class:`~spinectl.reflex.design.gain_searched.MarginCost` with ratio 1, what the margin is paid against.
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
    margin_ratio: float = 1.0
    nominal_delay: float = float("nan")
    margin_cost: object = None
    searched: object = None
    joint_searched: object = None
    decay_rate: float = 0.0
    nominal_design: object = None

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
        return (
            model
            | {
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
            | self._robustness()
        )

    def _robustness(self) -> dict:
        """The margin ratio, the cost of the default one and the searched answer, where computed."""
        out = {}
        if np.isfinite(self.nominal_delay):
            out |= {"margin_ratio": self.margin_ratio, "nominal_delay_s": self.nominal_delay}
        if self.decay_rate > 0:
            out["decay_rate_per_s"] = self.decay_rate
        if self.margin_cost is not None:
            out["margin_cost"] = self.margin_cost.to_dict()
        if self.nominal_design is not None:
            out["nominal_design"] = self.nominal_design.to_dict()
        if self.searched is not None:
            out["chain_gain_searched"] = self.searched.to_dict()
        if self.joint_searched is not None:
            out["joint_gain_searched"] = self.joint_searched.to_dict()
        return out

    def table(self) -> str:
        """The design as readable text: both criteria, each with its answer and certificate.

        Returns
        -------
        str
            No final newline: the lines of :meth:`readings`, each criterion after an empty line.
        """
        r = self.readings()
        return "\n".join(
            [*r["header"], *r["headline"], "", *r["joint_title"], *r["joint_table"], *r["joint"], "",
             *r["chain_title"], *r["chain"]]
        )  # fmt: skip

    def readings(self) -> dict[str, list[str]]:
        """The design's words, part by part: what :meth:`table` prints and the explorer shows.

        Returns
        -------
        dict of str to list of str
            ``header`` (the model), ``headline`` (the point, the delay, the status); joint by joint
            ``joint_title`` (its criterion), ``joint_table`` (the segments' columns, fixed width) and
            ``joint`` (the answer, the reflex it assumes, its boundary, the answer over every segment's
            gains); the chain ``chain_title`` (its criterion and the reflex) and ``chain`` (the answer, its
            certificate, the reflex assumed, the global PCSA, the gains, the boundary and what a margin costs,
            the searched answer or where to get it). A line that starts with two spaces is a note on the line
            above it.
        """
        c = self.chain
        return {
            "header": [self.model.get("header", "preset unknown")],
            "headline": [
                f"E = {self.eccentricity * 100:.2f} cm, Lambda = {self.lordosis * 100:.2f} cm, delay "
                f"{self._delay_words()}, activation lag {self.activation_time_constant * 1000:.4g} ms; "
                f"{self.status_text()}"
            ],
            "joint_title": [f"{criterion('joint', len(self.segments))}: least co-contraction ({self.method})"],
            "joint_table": self._segment_lines(),
            "joint": [self._joint_answer(), *self._joint_lines()],
            "chain_title": [
                f"{criterion('chain', len(c.local_stiffness))}: least local stiffness{_under(c.reflex)} at "
                f"activation {_word(c.activation, 0, '.4f')} ({c.method})"
            ],
            "chain": [*self._chain_answer(), *self._chain_lines()],
        }

    def _segment_lines(self) -> list[str]:
        """Joint by joint, each segment's least activation, PCSA and margin: a fixed-width table with its head."""
        lines = [f"{'segment':8} {'activation':>10} {'PCSA[cm2]':>10} {'tau_m[s]':>10}"]
        return lines + [
            f"{s.name:8} {_word(s.activation, 10, '.4f')} {_word(m2_to_cm2(s.pcsa), 10, '.2f')} "
            f"{_word(s.delay_margin, 10, '.4f')}"
            for s in self.segments
        ]

    def _joint_answer(self) -> str:
        """Joint by joint, the one activation for every segment, or why there is none."""
        if np.isfinite(self.activation):
            return (
                f"one activation for every segment (the largest above): {self.activation:.4f} x minimum PCSA "
                f"({m2_to_cm2(self.pcsa):.2f} cm^2); tau_m: each segment's exact delay margin at its activation"
            )
        if self.decay_rate > 0:
            return (
                f"no activation in [0, 1] meets the delay at every segment with every root at Re s < "
                f"-{self.decay_rate:g} 1/s (--decay-rate)"
            )
        return (
            f"no activation in [0, 1] meets the delay at every segment; the largest delay met: "
            f"{delay_text(self.largest_delay)}"
        )

    def _chain_answer(self) -> list[str]:
        """The chain's local stiffness per joint and its certificate, or why there is none."""
        c = self.chain
        if np.isfinite(c.fraction):
            return [
                "local stiffness [N m/rad]: "
                + ", ".join(f"{s.name} {k:.2f}" for s, k in zip(self.segments, c.local_stiffness, strict=True))
                + f"  ({c.fraction:.4f} x the least for static stability, total {np.sum(c.local_stiffness):.1f})",
                self._certificate_line(),
            ]
        if self.decay_rate > 0:
            return [
                f"no local stiffness meets the delay with every root at Re s < -{self.decay_rate:g} 1/s (--decay-rate)"
            ]
        return [f"no local stiffness meets the delay; the largest delay met: {delay_text(c.largest_delay)}"]

    def status_text(self) -> str:
        """The status as the table's heading says it, scoped to the answer it is about.

        'infeasible' is joint by joint's answer under its reflex, 'chain_infeasible' the chain's: the other answers
        (the chain's, those over other gains) may exist below it, so the words name which one failed.

        Returns
        -------
        str
            ``"status ok"``, ``"status (the rule, joint by joint): infeasible"``, ``"status (the rule, the chain):
            infeasible"`` (``"the given gains"`` for explicit gains), or the optimum's status where it failed.
        """
        if self.status == "ok":
            return "status ok"
        reflex = "the given gains" if self.chain.reflex == GIVEN_REFLEX else "the rule"
        if self.status == "infeasible":
            return f"status ({reflex}, joint by joint): infeasible"
        if self.status == "chain_infeasible":
            return f"status ({reflex}, the chain): infeasible"
        return f"status (the per-segment optimum): {self.status}"

    def _joint_lines(self) -> list[str]:
        """Joint by joint: the reflex the answer assumes, and the answer over every segment's gains."""
        if self.decay_rate > 0:
            return [
                f"  reflex assumed: the reflex rule at each activation; every root of each segment's loop at the "
                f"delay at Re s < -{self.decay_rate:g} 1/s (--decay-rate; tau_m: its own exact delay margin)"
            ]
        if self.joint_searched is None:
            return []
        given = self.chain.reflex == GIVEN_REFLEX  # the same gains go to every segment's loop
        reflex = "the given gains kp, kd at each segment" if given else "the reflex rule at each activation"
        return [
            f"  reflex assumed: {reflex}",
            *self._joint_boundary_lines(),
            *self.joint_searched.lines(self.activation, "the given gains'" if given else "the rule's"),
        ]

    def _joint_boundary_lines(self) -> list[str]:
        """Joint by joint, the least co-contraction is a stability boundary, as the chain's is."""
        if not (np.isfinite(self.activation) and self.activation > 0):
            return []
        if self.margin_ratio != 1.0:
            return [
                f"  robust: designed at {self.margin_ratio:g} x the delay {delay_text(self.nominal_delay)}, so "
                f"it holds every delay up to {delay_text(self.delay)} (--margin {self.margin_ratio:g})"
            ]
        setting = max(self.segments, key=lambda seg: seg.activation)  # the segment that sets the common activation
        ratio = setting.delay_margin / self.delay if self.delay > 0 else np.inf
        if ratio > 1.0 + BOUNDARY_RTOL:  # its margin jumped past the delay at the least value (as the chain's can)
            return [
                f"  boundary: the least value is where the margin of the segment that sets it ({setting.name}) jumps "
                f"past the delay, to {delay_text(setting.delay_margin)} ({ratio:.3g} x the delay), not where it "
                f"equals the delay: less co-contraction is unstable at this delay, and any margin up to "
                f"{ratio:.3g} x costs nothing more"
            ]
        return [
            "  boundary: the least value sits on its stability boundary (the margin of the segment that sets it "
            "= the delay; less co-contraction is unstable at this delay); a margin costs more: --margin R"
        ]

    def _chain_lines(self) -> list[str]:
        """The reflex the chain's answer assumes, its PCSA and gains, the margin it has and the searched answer."""
        c, names = self.chain, [s.name for s in self.segments]
        if not c.reflex:
            return []
        lines = [
            f"  reflex assumed: {c.reflex}; global PCSA {m2_to_cm2(c.pcsa):.2f} cm^2 "
            f"(activation {c.activation:.4g} x the minimum stabilising PCSA at this K, which shrinks as K grows)"
        ]
        if c.kp is not None and np.all(np.isfinite(c.kp)):
            lines.append("  gains (kp [N m/rad], kd [N m s/rad]): " + gains_text(names, c.kp, c.kd))
        if np.isfinite(c.fraction):
            lines.append(self._boundary_line())
        if self.searched is not None:
            lines += self.searched.lines(names, c.fraction, c.least_static, self._designed_delay())
        elif np.isfinite(c.fraction) and _under(c.reflex):
            lines.append("  the least under the reflex rule; other diagonal PD gains may need less: --gains search")
        return lines

    def _delay_words(self) -> str:
        """The delay designed for, and the one asked for where ``--margin R`` made them differ."""
        if self.margin_ratio == 1.0:
            return delay_text(self.delay)
        return (
            f"{delay_text(self.nominal_delay)} (designed at {delay_text(self.delay)}: --margin {self.margin_ratio:g})"
        )

    def _designed_delay(self) -> str:
        """The delay the certificates' roots are at, in words: with --margin R, R tau."""
        return "the delay" if self.margin_ratio == 1.0 else f"the designed delay {delay_text(self.delay)}"

    def _certificate_line(self) -> str:
        """The chain's certificate: the exact margin and the rightmost root (with a decay rate, beyond -sigma)."""
        c = self.chain
        root = f"rightmost root at {self._designed_delay()} Re s = {_word(c.max_root_real, 0, '.4g')} 1/s"
        if not self.decay_rate > 0:
            return f"certificate: exact delay margin {delay_text(c.delay_margin)} >= {delay_text(self.delay)}; {root}"
        return (
            f"certificate: every root at the delay has Re s < -{self.decay_rate:g} 1/s (the exact margin of the loop "
            f"shifted by the decay rate meets the delay); {root} (<= -{self.decay_rate:g}); exact delay margin "
            f"{delay_text(c.delay_margin)}"
        )

    def _boundary_line(self) -> str:
        """The least value is a stability boundary; what a margin costs."""
        c = self.chain
        if self.decay_rate > 0:
            return (
                f"  robust: designed for a least decay rate {self.decay_rate:g} 1/s (--decay-rate): every "
                f"disturbance dies out at least as fast as exp(-{self.decay_rate:g} t), time constant "
                f"{1 / self.decay_rate:.4g} s; the least value sits on that boundary (rightmost root at "
                f"-{self.decay_rate:g} 1/s)"
            )
        if self.margin_ratio != 1.0:
            return (
                f"  robust: designed at {self.margin_ratio:g} x the delay {delay_text(self.nominal_delay)}, so "
                f"it holds every delay up to {delay_text(self.delay)} (--margin {self.margin_ratio:g})"
                + self._nominal_words()
            )
        ratio = c.delay_margin / self.delay if self.delay > 0 else np.inf
        if ratio > 1.0 + BOUNDARY_RTOL:  # the margin jumped past the delay at the least value: no delay sets it
            return (
                f"  boundary: the least value is where the margin jumps past the delay, from below it to "
                f"{delay_text(c.delay_margin)} ({ratio:.3g} x the delay), not where it equals the delay: less "
                f"stiffness is unstable at this delay, and any margin up to {ratio:.3g} x costs nothing more"
            )
        text = "  boundary: the least value sits on its stability boundary (margin = the delay)"
        cost = self.margin_cost
        if cost is not None and np.isfinite(cost.fraction):
            more = np.sum(cost.local_stiffness) - np.sum(c.local_stiffness)
            text += (
                f"; a margin of {cost.ratio:g} x the delay needs {np.sum(cost.local_stiffness):.1f} N m/rad "
                f"({cost.fraction:.4f} x k*, {more:+.1f}; --margin R)"
            )
        elif cost is not None:
            text += f"; no local stiffness holds {cost.ratio:g} x the delay"
        return text

    def _nominal_words(self) -> str:
        """Beside a --margin design: the chain's design at the delay asked for, so that the margin's cost shows."""
        nominal = self.nominal_design
        if nominal is None:
            return ""
        if not np.isfinite(nominal.fraction):
            return f"; at {delay_text(self.nominal_delay)} itself no local stiffness meets the delay"
        total, here = np.sum(nominal.local_stiffness), np.sum(self.chain.local_stiffness)
        return (
            f"; the design at {delay_text(self.nominal_delay)} itself needs {total:.1f} N m/rad "
            f"({nominal.fraction:.4f} x k*): the margin costs {here - total:+.1f}"
        )

    def __bool__(self):
        raise TypeError(
            "the truth value of a Design is ambiguous: use design.status == 'ok' (both criteria met), or "
            "design.activation / design.chain.fraction (NaN where none meets the delay)"
        )


def _under(reflex: str) -> str:
    """' under the reflex rule' where the chain's design assumes the rule's gains; '' otherwise."""
    return " under the reflex rule" if reflex == RULE_REFLEX else ""


def gains_text(names, kp, kd) -> str:
    """Each joint's diagonal gains as text.

    Parameters
    ----------
    names : sequence of str
        The joints.
    kp, kd : array_like, shape (n,)
        Gains [N m/rad], [N m s/rad].

    Returns
    -------
    str
        ``L1L2 kp 30.0 kd 2.16, ...``.
    """
    return ", ".join(f"{n} kp {p:.1f} kd {d:.2f}" for n, p, d in zip(names, kp, kd, strict=True))


def _word(value: float, width: int, fmt: str) -> str:
    """A number, or 'none' (NaN) / 'unbounded' (inf), right-aligned in ``width``."""
    text = "none" if np.isnan(value) else ("unbounded" if np.isinf(value) else format(value, fmt))
    return f"{text:>{width}}"


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
        (:func:`~spinectl.reflex.design.roots.rightmost_root` with ``nodes`` = 0).
    names : tuple of str
    model : dict
    reflex : str
        The reflex every value assumes (:func:`curve_reflex`).
    global_pcsa : float
        The chain's global PCSA, ``chain_activation`` x the minimum stabilising PCSA at this K [m^2].
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
    reflex: str = ""
    global_pcsa: float = float("nan")

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
            "reflex": self.reflex,
            "global_pcsa_cm2": float(m2_to_cm2(self.global_pcsa)),
            "reading": " ".join(self.notes()),
            "curves": curves,
        }

    def notes(self) -> list[str]:
        """What every value rests on: the reflex, that it is a boundary, what tau_m is and a zero row.

        Returns
        -------
        list of str
        """
        notes = [
            f"reflex assumed: {self.reflex}.",
            "Each nonzero value is the least, a stability boundary: less is unstable at that delay (a margin costs "
            "more: design --delay D --margin R); a 0 needs none: the reflex alone holds that delay (no boundary).",
            "tau_m: the chain's exact delay margin at its design (joint by joint every segment's is at least the "
            "delay).",
        ]
        zero = np.isclose(self.delays, 0.0)
        if zero.any():
            notes.append(
                "0 ms: the reflex acting without delay; where it holds by itself (answers 0: no co-contraction, no "
                "local stiffness) tau_m is the delay that reflex alone holds, not a designed margin."
            )
        return notes

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
            f"E = {self.eccentricity * 100:.2f} cm, Lambda = {self.lordosis * 100:.2f} cm; {criterion('joint', n)}; "
            f"{criterion('chain', n)} at activation {self.chain_activation:.4g} (global PCSA "
            f"{m2_to_cm2(self.global_pcsa):.2f} cm^2: the minimum stabilising PCSA at this K times it)",
            *self.notes(),
        ]
        for i, lag in enumerate(self.lags):
            lines += [
                "",
                f"activation lag T_a = {lag * 1000:.4g} ms",
                f"{'delay[ms]':>9} {'joint: activation':>17} {'PCSA[cm2]':>10} {'chain: sum k[N m/rad]':>21} "
                f"{'x k*':>7} {'chain tau_m[ms]':>16}",
            ]
            lines += [
                f"{d * 1000:9.4g} {_word(self.activation[i, j], 17, '.4f')} "
                f"{_word(m2_to_cm2(self.pcsa[i, j]), 10, '.2f')} "
                f"{_word(float(np.sum(self.local_stiffness[i, j])), 21, '.1f')} "
                f"{_word(self.local_fraction[i, j], 7, '.4f')} {_word(self.chain_margin[i, j] * 1000, 16, '.4g')}"
                for j, d in enumerate(self.delays)
            ]
        return "\n".join(lines)
