"""What the explorer's views show, as pure functions of its state (no Panel, no browser).

:func:`point_numbers` is the point: the margins report of :func:`spinectl.reflex.margins.analyse`
(the chosen activation = ``activation`` x the optimum's PCSA, docs/reflex.md) and, at that
PCSA, each segment's eigenvalues and counter torque (paper eq. 1 and Methods, "Stability
analysis and calculation of counter torques"; :func:`spinectl.model.stability.segment_stability`).
:func:`landscapes` is the minimum PCSA and ||CT|| over the paper's range on a coarse grid,
solved on the stacked fast path (:func:`spinectl.landscape.sweep.sweep`, docs/optimisation.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

from ..landscape.sweep import sweep
from ..model.params import Model
from ..model.stability import segment_stability
from ..paper import grid
from ..reflex.margins import MarginsReport, analyse
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
        Margins of every segment at the chosen activation; ``report.point.pcsa`` is that PCSA [m^2].
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
        """Whether each segment's closed loop is stable at the delay, shape (n_cor,)."""
        return np.array([s.stable_at_delay for s in self.report.segments])

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
        E.g. ``'-3.142'``, ``'-1.5+2.25j'``, ``'inf'``, ``'nan'``.
    """
    value = complex(value)
    if value.imag == 0:
        return f"{value.real:.{DIGITS}g}"
    return f"{value.real:.{DIGITS}g}{value.imag:+.{DIGITS}g}j"


def point_numbers(base: Model, state: ExploreState) -> PointNumbers:
    """Every number the explorer shows at ``state``: margins, eigenvalues, counter torques.

    Parameters
    ----------
    base : Model
        The preset or configuration the explorer started from.
    state : ExploreState

    Returns
    -------
    PointNumbers
        An infeasible optimum is an answer: the report's status says so and the eigenvalues and
        counter torques are NaN.

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
    report = analyse(model, state.eccentricity, state.lordosis)
    n_cor = len(model.geometry.cor_names)
    eigenvalues = np.full((n_cor, 2), np.nan, complex)
    counter_torque = np.full(n_cor, np.nan)
    if report.point.ok:
        at = segment_stability(model, state.eccentricity, state.lordosis, report.point.pcsa)
        eigenvalues, counter_torque = at.eigenvalues, at.counter_torque
    return PointNumbers(state, model, report, eigenvalues, counter_torque)


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
