"""The paper's landmarks: what Figures 3, 4 and S1 show, and how spinectl measures each.

A table (:data:`LANDMARKS`) of the values the paper reports, each with its
unit, how spinectl measures it from the K = 0 and K = 15 N m/rad landscapes
(:func:`measure`) and where the paper says it (its Results, Discussion and
Additional file 1; docs/reproduction.md, "The claims one by one", gives the verdict
on each). Shared by the reproduction report and the calibration of the
unstated parameters. The instruments that read a landscape (a value at a position, the
crest of a ridge fitted between grid points) are :mod:`spinectl.paper.readings`.

"About" in the paper is read as +-20 % (values read off contour plots);
"<" and ">" are strict; an exact zero allows 1e-6 N m.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import xarray as xr

from .grid import POSITIONS
from .readings import CrestFit as CrestFit  # the readings' names, here as before they had their own module
from .readings import at as at
from .readings import crest_fit as crest_fit
from .readings import grid_point as grid_point
from .readings import label as label
from .readings import line_slope as line_slope
from .readings import vertex as vertex

OPTIMUM = (0.03, 0.04)
"""(E, Lambda) [m] that the paper's model requires (paper, Discussion: E ~ 3 cm, Lambda ~ 4 cm).

The paper's text also calls this region "position C" (Discussion: "see
Figure 4, position C") and puts C on the ridge Lambda ~ 1.7 E (Results), which
the corner (8 cm, 8 cm) is not on; the C-ratios are therefore reported for both readings.
"""

FIGURE_POSITIONS = {**POSITIONS, "C": OPTIMUM}
"""(E, Lambda) [m] of positions A-D as the figures and the report mark them: A, B and D at the corners,
C at Figure 3's reading, the interior point of the physiological situation (E ~ 3 cm, Lambda ~ 4 cm;
docs/reproduction.md, "The captions"). The landmarks keep every reading of C."""

RIDGE_SLOPE = 1.7
"""Slope of the paper's ridge of minimum PCSA, Lambda = 1.7 E (paper, Results)."""

RIDGE_RISE = 40.0 / 35.0 - 1.0
"""How far the ridge rises above A, relative to A [1]: the paper's ridge 'saturates at approximately
40 cm2' along the line through A, where the PCSA is 'about 35 cm2' (Results): 40/35 - 1 = 0.14."""

RIDGE_C = (POSITIONS["C"][1] / RIDGE_SLOPE, POSITIONS["C"][1])
"""(E, Lambda) [m] of position C read on the ridge line: where Lambda = 1.7 E reaches the top
edge of the grid, Lambda = 8 cm (paper, Results: the line runs "crossing the locations marked
with A and C", which the corner (8 cm, 8 cm) is not on). A third reading of C, beside the corner
and the text's optimum (:data:`OPTIMUM`)."""

CT_LIMIT = 30.0
"""Realistic maximum of the local muscles' counter torque [N m] (paper, Discussion: +-30 N m)."""

LOCAL_LEVER_ARM = 0.07
"""Conservative lever arm of the local muscles [m] (paper, Discussion: 7.0 cm, 30 N m ~ 17 cm^2)."""


ABOUT = 0.2
"""'About' read as +-20 % of the paper's value."""

ZERO_TORQUE = 1e-6
"""An exact zero of ‖CT‖ allows this much [N m] (rounding)."""


@dataclass(frozen=True)
class Landmarks:
    """The landscapes a measurement needs.

    Attributes
    ----------
    k0 : xarray.Dataset
        K = 0 (Figures 3 and 4).
    k15 : xarray.Dataset, optional
        K = 15 N m/rad with the model's convention (Figure S1).
    k15_other : xarray.Dataset, optional
        K = 15 N m/rad with the other convention.
    """

    k0: xr.Dataset
    k15: xr.Dataset | None = None
    k15_other: xr.Dataset | None = None


@dataclass(frozen=True)
class Landmark:
    """One value the paper reports.

    Attributes
    ----------
    name : str
        Identifier, e.g. ``"min_pcsa_A"``.
    paper : float
        The paper's value, in ``unit``.
    relation : str
        '~' (about, +-:data:`ABOUT`), '=' (exactly, +-:data:`ZERO_TORQUE`), '<' or '>'.
    unit : str
    how : str
        How spinectl measures it.
    where : str
        Where the paper says it.
    measure : callable
        ``measure(landmarks) -> float``; NaN when a landscape it needs is missing.
    positions : tuple of (float, float or None)
        The (E, Lambda) [m] it reads at the nearest grid point (Lambda None: the
        whole column at E); :func:`measure` reports the grid points used where they differ.
    uncertainty : callable, optional
        ``uncertainty(landmarks) -> float``, the measurement's standard error in ``unit``
        (a slope fitted to a crest, :func:`~spinectl.paper.readings.crest_fit`); None where the value is read directly.
    """

    name: str
    paper: float
    relation: str
    unit: str
    how: str
    where: str
    measure: Callable[[Landmarks], float]
    positions: tuple = ()
    uncertainty: Callable[[Landmarks], float] | None = None

    def agrees(self, value: float) -> bool:
        """Whether ``value`` matches the paper's value under :attr:`relation`.

        Parameters
        ----------
        value : float
            spinectl's measurement, in :attr:`unit`.

        Returns
        -------
        bool
            False for a value that is not finite.
        """
        if not np.isfinite(value):
            return False
        if self.relation == "<":
            return value < self.paper
        if self.relation == ">":
            return value > self.paper
        if self.relation == "=":
            return abs(value - self.paper) <= ZERO_TORQUE
        return abs(value - self.paper) <= ABOUT * abs(self.paper)


def _ridge(dataset: xr.Dataset | None) -> float:
    return np.nan if dataset is None else float(dataset["min_pcsa_cm2"].max())


def _rise(d: Landmarks) -> float:
    """How far the ridge rises above A, relative to A [1]: 0 for a plateau at A's value."""
    return _ratio(_ridge(d.k0), _pcsa("A")(d)) - 1.0


def _crest(name: str, pick: str, k15: bool = False) -> dict[str, Callable]:
    """The slope and its standard error (readings.crest_fit) of the K = 0 (or K = 15) landscape."""

    def fit(d: Landmarks) -> CrestFit:
        dataset = d.k15 if k15 else d.k0
        return CrestFit(np.nan, np.nan, 0) if dataset is None else crest_fit(dataset, name, pick)

    return {"measure": lambda d: fit(d).slope, "uncertainty": lambda d: fit(d).uncertainty}


def _ratio(a: float, b: float) -> float:
    return a / b if b else np.nan


def _pcsa(name: str) -> Callable[[Landmarks], float]:
    return lambda d: at(d.k0, "min_pcsa_cm2", POSITIONS[name])


def _ct(position) -> Callable[[Landmarks], float]:
    return lambda d: at(d.k0, "counter_torque_norm_Nm", position)


def _ct_ratio(top, bottom) -> Callable[[Landmarks], float]:
    return lambda d: _ratio(_ct(top)(d), _ct(bottom)(d))


def _best_lordosis(d: Landmarks) -> float:
    """Lambda [cm] of least ‖CT‖ at E = 3 cm, between grid points (readings.vertex) where it is inside."""
    column = d.k0["counter_torque_norm_Nm"].sel(E=OPTIMUM[0], method="nearest")
    values, axis = column.values, column["Lambda"].values
    if np.all(np.isnan(values)):
        return np.nan
    i = int(np.nanargmin(values))
    if 0 < i < values.size - 1 and np.isfinite(values[i - 1 : i + 2]).all():
        return float(vertex(axis, values, i)) * 100.0
    return float(axis[i]) * 100.0


def _halving(other: bool) -> Callable[[Landmarks], float]:
    return lambda d: _ratio(_ridge(d.k15_other if other else d.k15), _ridge(d.k0))


LANDMARKS: tuple[Landmark, ...] = (
    Landmark(
        "min_pcsa_A",
        35.0,
        "~",
        "cm2",
        "minimum PCSA at A",
        "Results, Fig. 3: 'about 35 cm2 (position A)'",
        _pcsa("A"),
        positions=(POSITIONS["A"],),
    ),
    Landmark(
        "min_pcsa_D_over_A",
        1.0,
        "<",
        "1",
        "minimum PCSA at D / at A",
        "Results: 'Increasing the spinal curvature slightly reduces the required PCSA (position D)'",
        lambda d: _ratio(_pcsa("D")(d), _pcsa("A")(d)),
        positions=(POSITIONS["D"], POSITIONS["A"]),
    ),
    Landmark(
        "min_pcsa_B",
        15.0,
        "<",
        "cm2",
        "minimum PCSA at B",
        "Results: 'less than 15 cm2 for E = 8 cm, Lambda = 0'",
        _pcsa("B"),
        positions=(POSITIONS["B"],),
    ),
    Landmark(
        "min_pcsa_ridge",
        40.0,
        "~",
        "cm2",
        "largest minimum PCSA on the grid",
        "Results: 'the PCSA saturates at approximately 40 cm2'",
        lambda d: _ridge(d.k0),
    ),
    Landmark(
        "ridge_rise",
        RIDGE_RISE,
        "~",
        "1",
        "largest minimum PCSA / minimum PCSA at A, minus 1 (0: a plateau at A's value)",
        "Results: 'about 35 cm2 (position A)' on the line through A and C, which 'saturates at approximately 40'",
        _rise,
        positions=(POSITIONS["A"],),
    ),
    Landmark(
        "ridge_slope",
        RIDGE_SLOPE,
        "~",
        "1",
        "Lambda/E of the ridge's crest, located between grid points (fit through 0, ± its standard error)",
        "Results: 'Around the line Lambda = 1.7E'",
        **_crest("min_pcsa_cm2", "max"),
    ),
    Landmark(
        "ridge_over_B",
        3.0,
        "~",
        "1",
        "largest minimum PCSA / minimum PCSA at B",
        "Results: 'this threefold reduction in minimum PCSA with an increasing eccentricity'",
        lambda d: _ratio(_ridge(d.k0), _pcsa("B")(d)),
        positions=(POSITIONS["B"],),
    ),
    Landmark(
        "ct_A",
        0.0,
        "=",
        "N m",
        "‖CT‖ at A",
        "Discussion: 'no local counter torques are necessary' (position A)",
        _ct(POSITIONS["A"]),
        positions=(POSITIONS["A"],),
    ),
    Landmark(
        "ct_valley_slope",
        1.0,
        "~",
        "1",
        "Lambda/E of the floor of ‖CT‖'s valley, located between grid points (fit through 0, ± its standard error)",
        "Results: 'the minimum counter torques were found along the angle bisector'",
        **_crest("counter_torque_norm_Nm", "min"),
    ),
    Landmark(
        "ct_B",
        70.0,
        ">",
        "N m",
        "‖CT‖ at B",
        "Discussion: 'local counter torques ... exceed +-70 Nm' (B)",
        _ct(POSITIONS["B"]),
        positions=(POSITIONS["B"],),
    ),
    Landmark(
        "ct_D_over_C",
        2.0,
        "~",
        "1",
        "‖CT‖ at D / at C (C = corner 8, 8 cm)",
        "Results: 'the required local torques in position D are twice those of position C'",
        _ct_ratio(POSITIONS["D"], POSITIONS["C"]),
        positions=(POSITIONS["D"], POSITIONS["C"]),
    ),
    Landmark(
        "ct_B_over_C",
        3.0,
        "~",
        "1",
        "‖CT‖ at B / at C (C = corner 8, 8 cm)",
        "Results: 'in position B ... three times as high'",
        _ct_ratio(POSITIONS["B"], POSITIONS["C"]),
        positions=(POSITIONS["B"], POSITIONS["C"]),
    ),
    Landmark(
        "ct_D_over_C_text",
        2.0,
        "~",
        "1",
        "‖CT‖ at D / at C read as E = 3, Lambda = 4 cm",
        "Results, with C as the Discussion places it",
        _ct_ratio(POSITIONS["D"], OPTIMUM),
        positions=(POSITIONS["D"], OPTIMUM),
    ),
    Landmark(
        "ct_B_over_C_text",
        3.0,
        "~",
        "1",
        "‖CT‖ at B / at C read as E = 3, Lambda = 4 cm",
        "Results, with C as the Discussion places it",
        _ct_ratio(POSITIONS["B"], OPTIMUM),
        positions=(POSITIONS["B"], OPTIMUM),
    ),
    Landmark(
        "ct_D_over_C_ridge",
        2.0,
        "~",
        "1",
        "‖CT‖ at D / at C read on the ridge line (E = 8/1.7, Lambda = 8 cm)",
        "Results, with C where the line Lambda = 1.7 E 'crossing the locations marked with A and C' leaves the grid",
        _ct_ratio(POSITIONS["D"], RIDGE_C),
        positions=(POSITIONS["D"], RIDGE_C),
    ),
    Landmark(
        "ct_B_over_C_ridge",
        3.0,
        "~",
        "1",
        "‖CT‖ at B / at C read on the ridge line (E = 8/1.7, Lambda = 8 cm)",
        "Results, with C on the ridge line as above",
        _ct_ratio(POSITIONS["B"], RIDGE_C),
        positions=(POSITIONS["B"], RIDGE_C),
    ),
    Landmark(
        "optimum_lordosis",
        4.0,
        "~",
        "cm",
        "Lambda of least ‖CT‖ at E = 3 cm (between grid points)",
        "Discussion: 'require an eccentricity of E ~ 3 cm and a lumbar lordosis of Lambda ~ 4 cm'",
        _best_lordosis,
        positions=((OPTIMUM[0], None),),
    ),
    Landmark(
        "ct_optimum",
        CT_LIMIT,
        "<",
        "N m",
        "‖CT‖ at E = 3, Lambda = 4 cm",
        "Discussion: the optimum lies inside the +-30 N m limit (Fig. 4 contour)",
        _ct(OPTIMUM),
        positions=(OPTIMUM,),
    ),
    Landmark(
        "min_pcsa_ridge_K15",
        23.0,
        "~",
        "cm2",
        "largest minimum PCSA, K = 15 N m/rad",
        "Additional file 1, Fig. S1: 'the PCSA saturates at approximately 23 cm2'",
        lambda d: _ridge(d.k15),
    ),
    Landmark(
        "halving_K15",
        0.5,
        "~",
        "1",
        "largest minimum PCSA, K = 15 / K = 0 (model's K convention)",
        "Discussion: 'the required PCSA is halved'; Fig. S1",
        _halving(other=False),
    ),
    Landmark(
        "halving_K15_other",
        0.5,
        "~",
        "1",
        "the same with the other K convention",
        "Discussion; docs/errata.md, 'The units of eq. 2': which convention halves it?",
        _halving(other=True),
    ),
    Landmark(
        "ridge_slope_K15",
        RIDGE_SLOPE,
        "~",
        "1",
        "ridge slope as above, K = 15 N m/rad",
        "Results: elasticity 'does not affect the relationship ... qualitatively'",
        **_crest("min_pcsa_cm2", "max", k15=True),
    ),
)
"""The paper's landmarks, in the order of its Results and Discussion."""


@dataclass(frozen=True)
class Measurement:
    """A landmark with spinectl's value and whether it agrees.

    Attributes
    ----------
    landmark : Landmark
    value : float
        spinectl's value, in the landmark's unit (NaN if not measurable).
    agrees : bool
    off_grid : tuple of ((float, float or None), (float, float or None))
        (position named, grid point read) [m] for each position of the landmark that is
        not a grid point (:func:`~spinectl.paper.readings.grid_point`).
    uncertainty : float
        Standard error of ``value`` in the landmark's unit; NaN where it has none.
    """

    landmark: Landmark
    value: float
    agrees: bool
    off_grid: tuple = ()
    uncertainty: float = np.nan

    @property
    def how(self) -> str:
        """How it was measured: the landmark's :attr:`Landmark.how`, plus the grid points used off its positions."""
        notes = [f"{label(used)} for {label(named)}" for named, used in self.off_grid]
        return self.landmark.how + (f" (nearest grid point: {'; '.join(notes)})" if notes else "")


def measure(landmarks: Landmarks) -> list[Measurement]:
    """Measure every landmark of :data:`LANDMARKS` from the landscapes.

    Parameters
    ----------
    landmarks : Landmarks

    Returns
    -------
    list of Measurement
        One per landmark, in the order of :data:`LANDMARKS`: the value in the
        landmark's unit (NaN where a landscape it needs is missing) and whether it agrees.
    """
    out = []
    for mark in LANDMARKS:
        value = float(mark.measure(landmarks))
        used = ((named, grid_point(landmarks.k0, named)) for named in mark.positions)
        off_grid = tuple((named, near) for named, near in used if not _same(named, near))
        spread = np.nan if mark.uncertainty is None else float(mark.uncertainty(landmarks))
        out.append(Measurement(mark, value, mark.agrees(value), off_grid, spread))
    return out


def _same(position, near) -> bool:
    return all(a is None or np.isclose(a, b, rtol=0.0, atol=1e-9) for a, b in zip(position, near, strict=True))


def local_pcsa_equivalent(counter_torque, specific_tension: float, lever_arm: float = LOCAL_LEVER_ARM):
    """A counter torque [N m] as the PCSA [m^2] of a local muscle with ``lever_arm`` [m].

    PCSA = abs(CT) / (lever_arm * specific_tension) (paper, Discussion: 30 N m at
    7 cm and 25 N/cm^2 is about 17 cm^2).

    Parameters
    ----------
    counter_torque : array_like
        [N m].
    specific_tension : float
        f_iso per PCSA [N/m^2].
    lever_arm : float
        Lever arm of the local muscle [m].

    Returns
    -------
    numpy.ndarray
        PCSA [m^2], the shape of ``counter_torque``.
    """
    return np.abs(counter_torque) / (lever_arm * specific_tension)
