"""The chain's least local stiffness over every diagonal PD reflex, beside the rule's; the cost of a margin.

:func:`~spinectl.reflex.design.chain.chain_design` answers the design question for one reflex: the rule's
gains handed over to the local muscles, (1 - f)+ times :func:`spinectl.reflex.gains.chain_gains`. Other
diagonal gains can need less local stiffness (docs/reflex.md, "The design question, over every diagonal
reflex"). :func:`gain_searched_design` answers over all of them: a bisection on f in [0, f_rule] (f_rule the
rule's answer, whose gains are a candidate, so the answer is never above it), each fraction judged with the
gains in hand first, then with the best of the rule's shape at other strengths (:data:`SHAPE_FACTORS`) and,
if that fails, with the seeded gain search of :func:`spinectl.reflex.gain_search.search_chain_gains` (it
maximises the exact margin) started from it. A fraction is accepted only with a certificate: the
exact margin of its gains (:func:`spinectl.reflex.mimo.chain_delay_margin`) meets the delay with no
critical delay crossed below it, and the rightmost root at the delay
(:func:`~spinectl.reflex.design.roots.rightmost_root`, with the Chebyshev seeds) has Re s < 0.

Whether the least stiffness is monotone in f is not known for every gain (more local stiffness with the same
gains can move a delayed loop's crossings either way), so the bisection's answer is the least fraction the
search certified, not a proof that no smaller one exists: a fraction is rejected only because the budgeted
search found no gains for it. The cost is bounded: :data:`SEARCH_STEPS` bisections, each at most one search
with :data:`SEARCH_BUDGET`, seeded (:data:`SEARCH_SEED`), so the answer is reproducible.

:func:`answer` is ``spinectl design``: the rule's design (:func:`~spinectl.reflex.design.curve.design`) at
the delay times a margin ratio R (a design at R tau holds for every delay up to R tau: its exact margin is
the first critical delay), with the global PCSA and the gains it used, the cost of the modest ratio
:data:`COST_RATIO` beside it, joint by joint the answer over every segment's gains
(:mod:`~spinectl.reflex.design.joint_searched`, milliseconds) and the chain's searched answer on request.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ...model.linear_chain import LinearChain
from ...model.operating_point import OperatingPoint, chain_at
from ...model.params import Model
from .. import gains
from ..chain_margins import stable_at
from ..delay import delay_text
from ..gain_search import population_members, search_chain_gains
from ..mimo import chain_delay_margin
from .chain import chain_design
from .joint_searched import joint_searched_design
from .result import GIVEN_REFLEX, RULE_REFLEX, gains_text
from .roots import SPECTRAL_NODES, rightmost_root

SEARCH_STEPS = 5
"""Bisections of [0, f_rule] in the gain-searched design: the answer to f_rule / 32 above the least found."""

SEARCH_BUDGET = {"population": 1, "generations": 3, "restarts": 2, "restart_evaluations": 100}
"""The budget of each gain search (:func:`spinectl.reflex.gain_search.search_chain_gains`): a population of 1
per gain (10 members for the 5 joints' 10 gains, :func:`~spinectl.reflex.gain_search.population_members`) over
3 generations, then at most two Nelder-Mead runs of 100 exact margins: about 250 exact margins, 5-20 s."""

SHAPE_FACTORS = (0.2, 0.3, 0.4, 0.6, 1.0)
"""Multiples of the rule's full gains (before the hand-over), k_p and k_d apart, tried as the search's start:
the rule's shape at other strengths (the issue's examples, 0.40 k_p with 0.30 k_d, lie on it)."""

SEARCH_SEED = 0
"""The seed of every gain search: the same model gives the same answer."""

COST_RATIO = 1.1
"""The modest delay-margin ratio whose cost the table shows by default: the design at 1.1 times the delay."""

SEARCHED_HEADING = "over diagonal PD gains"
"""How the searched answer's line starts in the table (the docs cut the table's lines from it)."""

SEARCHED_REFLEX = "any diagonal PD gains, searched"
"""The reflex the searched answer assumes, as the table and JSON label it (the rule's and the given gains' labels,
RULE_REFLEX and GIVEN_REFLEX, are in :mod:`~spinectl.reflex.design.result`, which the curve shares)."""


@dataclass(frozen=True)
class GainSearchedDesign:
    """The least local stiffness the seeded gain search certified, over every diagonal PD reflex.

    Attributes
    ----------
    fraction : float
        f [1] (k* multiples); at most the rule's.
    local_stiffness : numpy.ndarray, shape (n_cor,)
        f k* [N m/rad].
    kp, kd : numpy.ndarray, shape (n_cor,)
        The certified gains [N m/rad], [N m s/rad].
    delay_margin : float
        Their exact delay margin [s] (>= the delay).
    max_root_real : float
        Re of the rightmost root at the delay [1/s] (< 0).
    searches : int
        Gain searches run (a fraction held by the gains in hand or a shape needs none).
    evaluations : int
        Exact margins (or delay-free root checks) computed.
    method : str
    found_by : str
        The stage whose gains hold the answer: ``"rule"`` (the rule's own design: no smaller fraction
        certified), ``"shape"`` (the rule's shape at one of the strengths :data:`SHAPE_FACTORS`, the first
        stage) or ``"search"`` (the seeded gain search, the second); ``""`` if not known.
    shape : tuple of float
        (a, b) where ``found_by`` is ``"shape"``: the gains are a k_p and b k_d of the rule's full gains; else ().
    """

    fraction: float
    local_stiffness: np.ndarray
    kp: np.ndarray
    kd: np.ndarray
    delay_margin: float
    max_root_real: float
    searches: int
    evaluations: int
    method: str
    found_by: str = ""
    shape: tuple = ()

    def to_dict(self) -> dict:
        """``reflex``, ``local_stiffness_fraction``, ``local_stiffness_Nm_per_rad``, ``kp_Nm_per_rad``, ....

        Returns
        -------
        dict
            Also ``kd_Nms_per_rad``, ``delay_margin_s``, ``max_root_real_per_s``, ``searches``,
            ``evaluations``, ``budget`` (steps, seed and each search's budget), ``method``, ``found_by`` and
            ``shape_factors`` ([a, b] of the rule's k_p and k_d where the rule's shape found the gains, else null).
        """
        return {
            "reflex": SEARCHED_REFLEX,
            "local_stiffness_fraction": self.fraction,
            "local_stiffness_Nm_per_rad": self.local_stiffness.tolist(),
            "kp_Nm_per_rad": self.kp.tolist(),
            "kd_Nms_per_rad": self.kd.tolist(),
            "delay_margin_s": self.delay_margin,
            "max_root_real_per_s": self.max_root_real,
            "searches": self.searches,
            "evaluations": self.evaluations,
            "budget": {"bisections": SEARCH_STEPS, "seed": SEARCH_SEED} | SEARCH_BUDGET,
            "method": self.method,
            "found_by": self.found_by,
            "shape_factors": list(self.shape) or None,
        }

    def lines(self, names, rule_fraction: float, least_static, at: str = "the delay") -> list[str]:
        """The table's lines for this answer, beside the rule's f.

        Parameters
        ----------
        names : sequence of str
            The joints.
        rule_fraction : float
            The rule's answer f, of k*.
        least_static : array_like, shape (n,)
            k*, the least local stiffness for static stability [N m/rad].
        at : str
            The delay the certificate's root is at, in words: ``"the delay"``, or with ``--margin R`` the
            designed delay R tau (the rule's certificate names it the same way).

        Returns
        -------
        list of str
        """
        total = float(np.sum(self.local_stiffness))
        rule_total = rule_fraction * float(np.sum(least_static))
        # "at most": a budgeted search certifies what it found, it does not prove that nothing less holds
        return [
            f"{SEARCHED_HEADING} ({stages_text(len(self.kp))}): at most {total:.1f} N m/rad, certified "
            f"({self.fraction:.4f} x k*; the rule's {rule_total:.1f}, "
            f"{100 * (1 - total / rule_total) if rule_total > 0 else 0.0:.0f} % less)",
            f"  {self.found_text()}",
            "  gains: " + gains_text(names, self.kp, self.kd),
            f"  certificate: exact delay margin {delay_text(self.delay_margin)}; rightmost root at {at} "
            f"Re s = {self.max_root_real:.4g} 1/s",
            f"  search: {self.method}; {self.searches} seeded gain searches run, {self.evaluations} margin "
            f"evaluations (budget: {SEARCH_STEPS} bisections, each search {_budget_text(len(self.kp))}, "
            f"seed {SEARCH_SEED})",
        ]

    def found_text(self) -> str:
        """Which stage found the gains, in words (the rule's shape and its strengths, or the search).

        Returns
        -------
        str
        """
        if self.found_by == "shape":
            a, b = self.shape
            return (
                f"found by the first stage, the rule's shape: k_p x {a:g}, k_d x {b:g} of the rule's gains (before "
                "the hand-over)"
            )
        if self.found_by == "search":
            return "found by the budgeted search (no strength of the rule's shape held this fraction)"
        if self.found_by == "rule":
            return "found: the rule's own gains (no smaller fraction certified)"
        return "found by the search's stages"


@dataclass(frozen=True)
class MarginCost:
    """The rule's design at a delay-margin ratio R: the local stiffness that holds every delay up to R tau.

    Attributes
    ----------
    ratio : float
        R [1].
    fraction : float
        f at R tau [1]; NaN if none.
    local_stiffness : numpy.ndarray, shape (n_cor,)
        [N m/rad].
    """

    ratio: float
    fraction: float
    local_stiffness: np.ndarray

    def to_dict(self) -> dict:
        """``margin_ratio``, ``local_stiffness_fraction``, ``local_stiffness_Nm_per_rad``.

        Returns
        -------
        dict
        """
        return {
            "margin_ratio": self.ratio,
            "local_stiffness_fraction": self.fraction,
            "local_stiffness_Nm_per_rad": self.local_stiffness.tolist(),
        }


def stages_text(n_joints: int) -> str:
    """The two stages of the search over the gains, in words: the rule's shape's strengths, the search's members.

    Parameters
    ----------
    n_joints : int
        Joints n (the search's members grow with its 2 n gains).

    Returns
    -------
    str
    """
    members = population_members(SEARCH_BUDGET["population"], n_joints)
    return f"the rule's shape at {len(SHAPE_FACTORS) ** 2} strengths, then a budgeted search of {members} members"


def _budget_text(n_joints: int) -> str:
    b = SEARCH_BUDGET
    members = population_members(b["population"], n_joints)
    return (
        f"differential evolution of {members} members (population {b['population']} per gain) over "
        f"{b['generations']} generations, then at most {b['restarts']} Nelder-Mead runs of "
        f"{b['restart_evaluations']} evaluations"
    )


class _Chain:
    """The chain at its operating point: the loop at each fraction, and the certificate of gains there."""

    def __init__(self, model: Model, e: float, lam: float, pcsa, least_static):
        self.model, self.least = model, np.asarray(least_static, float)
        self.linear = chain_at(OperatingPoint(model, e, lam, pcsa, slip_check=False))  # local stiffness: .at((), k)
        self.mass = self.linear.mass_matrix
        self.delay, self.lag = model.reflex.delay, model.reflex.activation_time_constant
        self.evaluations = self.searches = 0

    def at(self, f) -> LinearChain:
        """The chain with local stiffness f k* and its damping."""
        return self.linear.at((), f * self.least)

    def gains(self, f, kp=None, kd=None):
        """The rule's gains handed over at f, (1 - f)+ times its full gains (or the given gains)."""
        k, d = self.linear.stiffness_offset, self.linear.damping_offset
        scale = max(1.0 - f, 0.0)  # as the rule's design hands over to the local muscles
        return gains.resolve_chain_gains(self.model.reflex, self.mass, k, d, self.least, kp, kd, scale)

    def loop(self, f):
        chain = self.at(f)
        return chain.stiffness_offset, chain.damping_offset

    def margin(self, f, kp, kd) -> float:
        """The exact margin of gains at f [s]; 0 if unstable without delay or a critical delay crossed below."""
        k, d = self.loop(f)
        exact = chain_delay_margin(self.mass, k, d, kp, kd, self.lag)
        self.evaluations += 1
        return float(exact.margin) if stable_at(exact, self.delay) and exact.stable_without_delay else 0.0

    def certify(self, f, kp, kd):
        """(margin [s], rightmost root's Re [1/s]) if the gains hold f at the delay, else None."""
        margin = self.margin(f, kp, kd)
        if not margin >= self.delay:
            return None
        k, d = self.loop(f)
        root = rightmost_root(self.mass, k, d, kp, kd, self.delay, self.lag, SPECTRAL_NODES)
        return (margin, float(root.real)) if root.real < 0 else None

    def search(self, f, starts):
        """Gains for f: the best of ``starts`` if it holds f, else the seeded search's best from it.

        ``starts`` are (kp, kd, found_by, shape); so is the answer, ``found_by`` ``"search"`` for the search's.
        """
        kp, kd, found_by, shape = max(starts, key=lambda g: self.margin(f, g[0], g[1]))
        if self.certify(f, kp, kd) is not None:
            return kp, kd, found_by, shape
        self.searches += 1
        found = search_chain_gains(
            self.at(f), kp, kd, self.lag, seed=SEARCH_SEED, **SEARCH_BUDGET
        )  # fmt: skip
        self.evaluations += found.evaluations
        return found.kp, found.kd, "search", ()


def gain_searched_design(model: Model, eccentricity: float, lordosis: float, pcsa, rule) -> GainSearchedDesign:
    """The least local stiffness f k* in [0, f_rule] that some diagonal PD reflex holds at the delay (see the module).

    Parameters
    ----------
    model : Model
        ``model.reflex``: the delay and lag.
    eccentricity, lordosis : float
        E and Lambda [m].
    pcsa : numpy.ndarray, shape (n_muscles,)
        The global PCSA of the rule's design [m^2].
    rule : ChainDesign
        The rule's answer (:func:`~spinectl.reflex.design.chain.chain_design`) at the same delay, with its
        gains (``kp``, ``kd``): the first candidate.

    Returns
    -------
    GainSearchedDesign
        NaN fraction where the rule has no answer (no design up to its top to start from).
    """
    n = len(rule.least_static)
    if not np.isfinite(rule.fraction):
        nan = np.full(n, np.nan)
        return GainSearchedDesign(np.nan, nan, nan, nan, np.nan, np.nan, 0, 0, "none: the rule has no design")
    chain = _Chain(model, float(eccentricity), float(lordosis), pcsa, rule.least_static)
    kp0, kd0 = chain.gains(0.0)  # the rule's gains before the hand-over: its shape, at other strengths
    shapes = [(a * kp0, b * kd0, "shape", (a, b)) for a in SHAPE_FACTORS for b in SHAPE_FACTORS]
    # best: f, kp, kd, found_by, shape, margin, root; the gains keep the name of the stage that found them
    best = (rule.fraction, rule.kp, rule.kd, "rule", (), rule.delay_margin, rule.max_root_real)
    lo, hi = 0.0, rule.fraction
    for _ in range(SEARCH_STEPS):
        f = 0.5 * (lo + hi)
        held = chain.certify(f, best[1], best[2])  # the gains in hand first: no search if they hold f
        gains = best[1:5]
        if held is None:
            gains = chain.search(f, [gains, *shapes])
            held = chain.certify(f, gains[0], gains[1])
        if held is None:
            lo = f
        else:
            hi, best = f, (f, *gains, *held)
    f, kp, kd, found_by, shape, margin, root = best
    method = (
        f"bisection of [0, f_rule] over the gains: the least fraction certified ({SEARCH_STEPS} halvings, "
        f"to {rule.fraction / 2**SEARCH_STEPS:.4f} x k*); a lower one may need gains the search missed"
    )
    return GainSearchedDesign(
        float(f), f * rule.least_static, np.asarray(kp, float), np.asarray(kd, float), float(margin),
        float(root), chain.searches, chain.evaluations, method, found_by, tuple(float(x) for x in shape),
    )  # fmt: skip


def answer(model: Model, eccentricity: float, lordosis: float, kp=None, kd=None, search=False, ratio=1.0, decay=0.0):
    """``spinectl design`` at one delay: the rule's design at R tau, labelled, with its cost and the searched answer.

    Parameters
    ----------
    model : Model
        ``model.reflex.delay`` is tau.
    eccentricity, lordosis : float
        E and Lambda [m].
    kp, kd : float, optional
        Explicit gains for every segment and joint.
    search : bool
        Also :func:`gain_searched_design` (tens of seconds).
    ratio : float
        R >= 1: the design holds every delay up to R tau (the design at R tau).
    decay : float
        A least decay rate sigma [1/s] instead: both criteria's designs have every root at the delay at
        Re s < -sigma (:mod:`~spinectl.reflex.design.decay`); 0, none. Not with ``search`` or R > 1; no
        ``joint_searched`` beside it.

    Returns
    -------
    Design
        With ``margin_ratio``, ``nominal_delay``, ``margin_cost`` (at :data:`COST_RATIO` where R = 1),
        ``nominal_design`` (the chain's at tau where R > 1),
        ``searched``, ``joint_searched`` and the chain's ``pcsa``, ``kp``, ``kd`` and ``reflex``.

    Raises
    ------
    ParameterError
        R tau beyond the delay's bound; E or Lambda out of range.
    """
    from ...model import config
    from ...optimise.reference import solve_point
    from .curve import design

    nominal, e, lam = model.reflex.delay, float(eccentricity), float(lordosis)
    at = config.set_parameters(model, {"reflex.delay": ratio * nominal}) if ratio != 1.0 else model
    result = design(at, e, lam, kp=kp, kd=kd, decay=decay)
    optimum = np.asarray(solve_point(at, e, lam).pcsa, float)
    pcsa = at.reflex.activation * optimum
    rule = result.chain
    n = len(rule.least_static)
    kp_used, kd_used = (
        _Chain(at, e, lam, pcsa, rule.least_static).gains(rule.fraction, kp, kd)
        if np.isfinite(rule.fraction)
        else (np.full(n, np.nan), np.full(n, np.nan))
    )
    label = RULE_REFLEX if at.reflex.gains == "rule" and kp is None and kd is None else GIVEN_REFLEX
    rule = replace(rule, pcsa=float(np.sum(pcsa)), kp=np.asarray(kp_used), kd=np.asarray(kd_used), reflex=label)
    cost = None
    if ratio == 1.0 and not decay > 0 and np.all(np.isfinite(pcsa)) and COST_RATIO * nominal <= _max_delay():
        longer = config.set_parameters(model, {"reflex.delay": COST_RATIO * nominal})
        c = chain_design(longer, e, lam, pcsa, at.reflex.activation, kp, kd)
        cost = MarginCost(COST_RATIO, c.fraction, c.local_stiffness)
    nominal_design = None
    if ratio != 1.0 and np.all(np.isfinite(pcsa)):  # the design at the delay asked for: what the margin costs
        c = chain_design(model, e, lam, pcsa, at.reflex.activation, kp, kd)
        nominal_design = MarginCost(1.0, c.fraction, c.local_stiffness)
    searched = gain_searched_design(at, e, lam, pcsa, rule) if search and np.all(np.isfinite(pcsa)) else None
    # milliseconds: always beside the rule's, but for a decay rate, which that grid does not certify
    joint = joint_searched_design(at, e, lam, result, kp, kd) if not decay > 0 else None
    return replace(
        result, chain=rule, margin_ratio=float(ratio), nominal_delay=nominal, margin_cost=cost, searched=searched,
        joint_searched=joint, nominal_design=nominal_design,
    )  # fmt: skip


def _max_delay() -> float:
    from ...model.params import MAX_DELAY

    return MAX_DELAY
