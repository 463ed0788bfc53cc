"""What the explorer's views show, as pure functions of its state (no Panel, no browser).

:func:`point_numbers` is the point: the margins report of :func:`spinectl.reflex.margins.margins_report`
(the chosen activation = ``activation`` x the optimum's PCSA, docs/reflex.md) and, at that
PCSA, each segment's eigenvalues and counter torque (paper eq. 1 and Methods, "Stability
analysis and calculation of counter torques"; :func:`spinectl.model.stability.segment_stability`).
:attr:`PointNumbers.chain` is the chain's verdict under the same reflex, every CoR free
(:func:`spinectl.reflex.chain_verdict.margins_with_chain`, docs/chain.md), beside the segments', each
judged alone (the paper's criterion); :func:`design_numbers` answers the design question at the
state's delay as ``spinectl design`` does (:func:`spinectl.reflex.design.gain_searched.answer`, docs/reflex.md,
"The design question"), which takes seconds, so the explorer runs it only on request; :func:`design_rows` gives
its words, those of the command's table.
:func:`landscapes` is the minimum PCSA and ||CT|| over the paper's range on a coarse grid,
solved on the stacked fast path (:func:`spinectl.landscape.sweep.sweep`, docs/optimisation.md).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import xarray as xr

from ..landscape.sweep import sweep
from ..model.params import Model
from ..model.stability import criterion, segment_stability
from ..paper import grid
from ..reflex.chain_margins import stable_at
from ..reflex.chain_verdict import ChainReflexVerdict, margins_with_chain
from ..reflex.delay import delay_text
from ..reflex.design import Design, answer
from ..reflex.margins import MarginsReport, margins_report
from .state import ExploreState, model_at

LANDSCAPE_POINTS = 41
"""Points per axis of the explorer's landscapes (41 x 41: 2 mm steps over the paper's 0 to 8 cm)."""
LANDSCAPE_VARIABLES = ("min_pcsa_cm2", "counter_torque_norm_Nm", "status")
"""The variables of the sweep that the landscape views show."""
DIGITS = 4
"""Significant digits of the numbers in the explorer's table."""


@dataclass(frozen=True)
class PointNumbers:
    """The numbers of every view at one state.

    Attributes
    ----------
    state : ExploreState
    model : Model
        The model of the state (:func:`spinectl.explore.state.model_at`).
    report : MarginsReport
        Margins of every segment at the chosen activation; ``report.point.pcsa`` is that PCSA [m^2];
        ``report.chain`` the chain's verdict under the same reflex (:attr:`chain`).
    eigenvalues : numpy.ndarray, shape (n_cor, 2), complex
        Eigenvalues of each segment at that PCSA [1/s] (paper eq. 1); NaN without an optimum.
    counter_torque : numpy.ndarray, shape (n_cor,)
        CT_k at that PCSA [N m]; NaN without an optimum.
    """

    state: ExploreState
    model: Model
    report: MarginsReport
    eigenvalues: np.ndarray
    counter_torque: np.ndarray

    @property
    def segment_names(self) -> tuple[str, ...]:
        """The segments (CoRs), top to bottom."""
        return self.model.geometry.cor_names

    @property
    def pcsa(self) -> np.ndarray | None:
        """PCSA of each muscle at the chosen activation [m^2], or None without an optimum."""
        return self.report.point.pcsa if self.report.point.ok else None

    @property
    def delay_margin(self) -> np.ndarray:
        """Exact delay margin of each segment [s], shape (n_cor,) (inf: any delay; 0: unstable without)."""
        return np.array([s.delay_margin for s in self.report.segments])

    @property
    def stable_at_delay(self) -> np.ndarray:
        """Whether each segment's closed loop is stable at the delay, each CoR alone, shape (n_cor,)."""
        return np.array([s.stable_at_delay for s in self.report.segments])

    @property
    def criterion(self) -> str:
        """The words of the segments' criterion: joint by joint, each CoR alone (the paper's)."""
        return criterion("joint", len(self.segment_names))

    @property
    def chain(self) -> ChainReflexVerdict:
        """The chain under the same reflex, every CoR free (:func:`spinectl.reflex.chain_verdict.chain_verdict`)."""
        return self.report.chain

    def chain_row(self) -> dict[str, str]:
        """The chain's verdict as shown beside the segments' table (:func:`shown`).

        Returns
        -------
        dict
            ``criterion``; ``stable_at_delay`` ('yes', 'no', or 'undefined' without an optimum or
            with massless levels); ``delay_margin_s`` (the exact multivariable delay margin [s]) and
            ``frequency_rad_s`` (its crossing [rad/s]); without reflex: ``modes`` (how many of how many
            grow), ``growth_times_s`` (by e, fastest and slowest growing mode [s]) and
            ``slowest_time_constant_s`` (-1 / max Re lambda [s]; 'none: a mode grows' while one grows).
        """
        verdict, modes = self.chain, self.chain.modes
        growth = modes.growth_times  # fastest first
        word = ("yes" if verdict.stable_at_delay else "no") if modes.defined else "undefined"
        extremes = dict.fromkeys(shown(t) for t in growth[[0, -1]]) if growth.size else {"none": None}
        return {
            "criterion": verdict.criterion,
            "stable_at_delay": word,
            "delay_margin_s": shown(verdict.exact.margin),
            "frequency_rad_s": shown(verdict.exact.frequency),
            "modes": f"{growth.size} of {modes.eigenvalues.size} grow" if modes.defined else "undefined",
            "growth_times_s": " to ".join(extremes),
            "slowest_time_constant_s": (
                "none: a mode grows" if np.isinf(modes.slowest_time_constant) else shown(modes.slowest_time_constant)
            ),
        }

    def verdicts(self) -> list[str]:
        """The two verdicts at the delay, each with its criterion, as the explorer's first lines say them.

        Returns
        -------
        list of str
            Joint by joint (how many segments are stable alone at the delay), then the chain under the same
            reflex, every CoR free (stable or not, with its exact delay margin [s]).
        """
        delay = delay_text(self.state.delay)
        alone = int(np.sum(self.stable_at_delay))
        segments = "every segment" if alone == self.stable_at_delay.size else f"{alone} of {self.stable_at_delay.size}"
        row = self.chain_row()
        chain = {"yes": "stable", "no": "NOT stable", "undefined": "undefined"}[row["stable_at_delay"]]
        return [
            f"{self.criterion}: {segments} stable at τ = {delay}",
            f"{row['criterion']}, the same reflex at every joint: {chain} at τ = {delay} "
            f"(exact delay margin {delay_text(self.chain.exact.margin)})",
        ]

    def rows(self) -> list[dict[str, str]]:
        """One row per segment, every number as shown (:func:`shown`), for the explorer's table.

        Returns
        -------
        list of dict
            ``segment``, ``eigenvalue_1``, ``eigenvalue_2`` [1/s], ``counter_torque_Nm``,
            ``delay_margin_s`` and ``stable_at_delay`` ('yes'/'no') of each segment.
        """
        return [
            {
                "segment": name,
                "eigenvalue_1": shown(eigs[0]),
                "eigenvalue_2": shown(eigs[1]),
                "counter_torque_Nm": shown(ct),
                "delay_margin_s": shown(margin),
                "stable_at_delay": "yes" if stable else "no",
            }
            for name, eigs, ct, margin, stable in zip(
                self.segment_names,
                self.eigenvalues,
                self.counter_torque,
                self.delay_margin,
                self.stable_at_delay,
                strict=True,
            )
        ]


def shown(value) -> str:
    """A number as the explorer shows it: :data:`DIGITS` significant digits, complex as a + bj.

    Parameters
    ----------
    value : float or complex

    Returns
    -------
    str
        E.g. ``'-3.142'``, ``'-1.5+2.25j'``; an infinite value (a delay margin or a largest delay met that no
        delay bounds) ``'unbounded'``, as the command line prints it (:func:`spinectl.reflex.delay.delay_text`),
        and a NaN (nothing to show) ``'none'``: never Python's 'inf' and 'nan'.
    """
    value = complex(value)
    if value.imag == 0:
        if np.isnan(value.real):
            return "none"
        if np.isinf(value.real):
            return "unbounded" if value.real > 0 else "-unbounded"
        return f"{value.real:.{DIGITS}g}"
    return f"{value.real:.{DIGITS}g}{value.imag:+.{DIGITS}g}j"


def point_numbers(base: Model, state: ExploreState, previous: PointNumbers | None = None) -> PointNumbers:
    """Every number the explorer shows at ``state``: margins, eigenvalues, counter torques, the chain's verdict.

    Parameters
    ----------
    base : Model
        The preset or configuration the explorer started from.
    state : ExploreState
    previous : PointNumbers, optional
        The numbers of the same ``base`` at an earlier state. Where that state differs from ``state`` in
        the delay alone, its chain's exact delay margin is reused, compared with the new delay: the
        margin, the rule's gains and the modes do not depend on the delay
        (:func:`spinectl.reflex.chain_verdict.chain_verdict`), so it is not computed again.

    Returns
    -------
    PointNumbers
        An infeasible optimum is an answer: the report's status says so and the eigenvalues and
        counter torques are NaN; the chain's verdict is then 'undefined'.

    Raises
    ------
    ParameterError
        A state outside the model's allowed ranges.

    References
    ----------
    Wagner H, Liebetrau A, Schinowski D, Wulf T, de Lussanet MHE (2012). Spinal lordosis
    optimizes the requirements for a stable erect posture. Theor Biol Med Model 9:13 (eq. 1),
    doi:10.1186/1742-4682-9-13.
    """
    model = model_at(base, state)
    if previous is not None and dataclasses.replace(previous.state, delay=state.delay) == state:
        chain = previous.chain
        chain = dataclasses.replace(chain, delay=state.delay, stable_at_delay=stable_at(chain.exact, state.delay))
        report = dataclasses.replace(margins_report(model, state.eccentricity, state.lordosis), chain=chain)
    else:
        report = margins_with_chain(model, state.eccentricity, state.lordosis)
    n_cor = len(model.geometry.cor_names)
    eigenvalues = np.full((n_cor, 2), np.nan, complex)
    counter_torque = np.full(n_cor, np.nan)
    if report.point.ok:
        at = segment_stability(model, state.eccentricity, state.lordosis, report.point.pcsa)
        eigenvalues, counter_torque = at.eigenvalues, at.counter_torque
    return PointNumbers(state, model, report, eigenvalues, counter_torque)


def design_numbers(base: Model, state: ExploreState, search: bool = False) -> Design:
    """The design answer at the state's delay, as ``spinectl design`` gives it: both criteria, labelled.

    :func:`spinectl.reflex.design.gain_searched.answer` of the state's model at its point, the function
    ``spinectl design`` calls: joint by joint the least co-contraction, for the chain the least local stiffness
    under the reflex rule, each with the reflex it assumes, the chain's global PCSA and gains, that the least
    value is a stability boundary and what a margin of 1.1 x the delay costs; seconds, so the explorer runs it
    on request.

    Parameters
    ----------
    base : Model
    state : ExploreState
    search : bool
        Also the chain's answer over every diagonal PD reflex (``spinectl design --gains search``: a seeded
        gain search, each candidate certified; tens of seconds).

    Returns
    -------
    Design
        Infeasible designs are answers (NaN and the status, with the largest delay met).

    Raises
    ------
    ParameterError
        A state outside the model's allowed ranges.
    """
    return answer(model_at(base, state), state.eccentricity, state.lordosis, search=search)


def design_rows(design: Design) -> dict[str, list[tuple[str, bool]]]:
    """The design answer as the explorer shows it: the words of ``spinectl design``'s table, part by part.

    :meth:`spinectl.reflex.design.result.Design.readings`, whose lines the command prints; a line the command
    indents by two spaces, a note on the line above it, is marked as one (the explorer indents it so).

    Parameters
    ----------
    design : Design
        An answer of :func:`design_numbers`.

    Returns
    -------
    dict of str to list of (str, bool)
        The keys of :meth:`~spinectl.reflex.design.result.Design.readings` (``header``, ``headline``,
        ``joint_title``, ``joint_table``, ``joint``, ``chain_title``, ``chain``), each a list of (the line
        without its indent, whether it is a note); the segments' fixed-width table (``joint_table``) as printed.
    """
    return {
        key: [(line if key == "joint_table" else line.strip(), line.startswith("  ")) for line in lines]
        for key, lines in design.readings().items()
    }


def landscape_axis(points: int = LANDSCAPE_POINTS) -> np.ndarray:
    """The landscapes' E and Lambda axis: the paper's 0 to 8 cm with ``points`` points [m].

    Parameters
    ----------
    points : int

    Returns
    -------
    numpy.ndarray, shape (points,)
    """
    return grid.paper_axis(points)


def landscapes(base: Model, state: ExploreState, points: int = LANDSCAPE_POINTS) -> xr.Dataset:
    """Minimum PCSA and ||CT|| over E x Lambda for the state's mass and K (Figures 3 and 4).

    Neither depends on the point or on the reflex, so the explorer solves them again only
    when the mass, K or the model change.

    Parameters
    ----------
    base : Model
    state : ExploreState
    points : int
        Points per axis (:data:`LANDSCAPE_POINTS`).

    Returns
    -------
    xarray.Dataset
        ``min_pcsa_cm2`` [cm^2], ``counter_torque_norm_Nm`` [N m] and ``status`` on dimensions
        (``E``, ``Lambda``) [m]; NaN where no PCSA stabilises (docs/optimisation.md).
    """
    axis = landscape_axis(points)
    dataset = sweep(model_at(base, state), axis, axis, method="fast", progress=False)
    return dataset[list(LANDSCAPE_VARIABLES)]
