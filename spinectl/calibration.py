"""Calibration of the parameters the paper does not state, against the paper's landmarks.

The paper (Wagner et al. 2012) gives neither the upper-body mass, nor the
muscle attachment coordinates, nor the fibre spread. This module fits them,
within anatomically plausible bounds (:data:`FREE_PARAMETERS`, each bound with
its source), to the landmarks of :mod:`spinectl.landmarks` (design page, "What
the paper reports"), and reports the residual of every landmark.

- A parameter vector maps to a :class:`~spinectl.params.Model` through dotted
  parameter paths (:func:`to_model`, :func:`from_model`); one free parameter
  may set several paths (e.g. the common height of all upper attachments).
- The loss (:func:`loss`, docs/reproduction.md) is a weighted sum over the
  landmarks: squared log-ratio residuals log(value / paper) for the "about"
  landmarks, one-sided (hinge) squared log-ratios for "<" and ">", each hinge
  demanding a margin of :data:`STRICT_MARGIN`, and :data:`MISSING_PENALTY` for a
  landmark that cannot be measured (e.g. a ridge that leaves the grid).
- The landscapes used during fitting are coarse (17 x 17 by default) and use
  the fast path (:mod:`spinectl.batch`); the K = 15 N m/rad landscape needs
  only the minimum PCSA. The fitted model is then measured again on the
  paper's 81 x 81 grid (:func:`measure_model`).
- The optimiser is :func:`scipy.optimize.differential_evolution` with a fixed
  seed and a modest budget, started from a population that contains the
  base model; the passive-stiffness convention (design page, erratum eq. 2) is
  a discrete choice, fitted both ways and reported.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
import scipy.optimize
import scipy.stats
import xarray as xr

from . import batch, landmarks, sweep
from .config import dump_toml, set_parameters
from .errors import ModelError, ParameterError
from .landmarks import Landmarks, Measurement
from .optimise import problem_data
from .params import Model
from .reproduction import RELATION
from .stability import checked_coefficients
from .units import m2_to_cm2

CONVENTIONS = ("physical", "paper")
"""The two readings of the passive stiffness K in eq. 2 (design page, erratum eq. 2)."""

PAPER_RANGE = (0.0, 0.08)
"""E and Lambda [m] of the paper's grid (paper, Methods: 0 to 8 cm)."""

FIT_POINTS = 17
"""Grid points per axis while fitting: 5 mm steps, which contain the paper's positions
A-D and its optimum (E = 3 cm, Lambda = 4 cm)."""

PAPER_POINTS = 81
"""Grid points per axis of the paper's grid (1 mm steps; paper, Methods; design page), on which
the calibrated model is measured."""

POPSIZE = 6
"""Population of differential evolution per free parameter (scipy's ``popsize``): 42 for 7 parameters."""

GENERATIONS = 16
"""Generations of differential evolution per start (scipy's ``maxiter``)."""

REFINE_EVALUATIONS = 120
"""Loss evaluations of the local refinement (Nelder-Mead) per convention. With :data:`POPSIZE`
and :data:`GENERATIONS` about 950 evaluations in all: 2-4 minutes on one core (docs/reproduction.md)."""

REFINE_STEP = 0.05
"""Size of the refinement's initial simplex, as a fraction of each bound's width."""


@dataclass(frozen=True)
class FreeParameter:
    """One unstated parameter of the paper, fitted within anatomical bounds.

    Attributes
    ----------
    name : str
        Identifier, e.g. ``"mass"``.
    unit : str
        Unit of the value and the bounds (SI).
    lower, upper : float
        Bounds, in ``unit``.
    paths : tuple of str
        Dotted parameter paths (:func:`spinectl.config.set_parameters`) that all
        take this value, e.g. the heights of every upper attachment.
    doc : str
        What the parameter is.
    source : str
        Where the bounds come from; "estimate" where they are one.
    """

    name: str
    unit: str
    lower: float
    upper: float
    paths: tuple[str, ...]
    doc: str
    source: str

    def value(self, model: Model) -> float:
        """The value in ``model`` (that of the first path).

        Parameters
        ----------
        model : Model
        """
        node = model
        for key in self.paths[0].split("."):
            node = node[int(key)] if isinstance(node, tuple) else getattr(node, key)
        return float(node)


def _muscle_paths(template: str, pairs: Sequence[int] = (0, 1, 2)) -> tuple[str, ...]:
    return tuple(template.format(i) for i in pairs)


FREE_PARAMETERS: tuple[FreeParameter, ...] = (
    FreeParameter(
        "mass",
        "kg",
        24.0,
        55.0,
        ("body.mass",),
        "Upper-body point mass m.",
        "Head, neck, arms, thorax and half the abdomen are 47 % of the body mass in Dempster's segment "
        "fractions (Winter 2009, Biomechanics and Motor Control of Human Movement, table 4.1: "
        "8.1 + 2 x 5.0 + 21.6 + 13.9/2); the default preset reads 55 %. Adult body masses of about "
        "50-100 kg (estimate) give about 24-55 kg.",
    ),
    FreeParameter(
        "straight_x",
        "m",
        0.03,
        0.17,
        ("muscles.0.upper.0", "muscles.0.lower.0"),
        "Horizontal distance x of the straight pair from the body's symmetry axis (both ends).",
        "Estimate: global muscles lie between the vertebral bodies (about 3 cm from the midline) and the "
        "trunk surface: half the waist depth (sagittal, 20-25 cm) or half the waist breadth (coronal, "
        "30-34 cm) in adult anthropometric tables (e.g. NASA-STD-3000, Anthropometric Source Book vol. II).",
    ),
    FreeParameter(
        "oblique_wide_x",
        "m",
        0.03,
        0.17,
        ("muscles.1.upper.0", "muscles.2.lower.0"),
        "x of the oblique pairs' wide ends: the upper end of oblique_outer, the lower end of oblique_inner.",
        "As for straight_x (estimate).",
    ),
    FreeParameter(
        "oblique_narrow_x",
        "m",
        0.03,
        0.17,
        ("muscles.1.lower.0", "muscles.2.upper.0"),
        "x of the oblique pairs' narrow ends: the lower end of oblique_outer, the upper end of oblique_inner.",
        "As for straight_x (estimate).",
    ),
    FreeParameter(
        "upper_y",
        "m",
        0.176,
        0.326,
        _muscle_paths("muscles.{}.upper.1"),
        "Common height y of the upper (thoracic) attachments.",
        "The thoracic cage lies above P1, the thoracolumbar joint at 176 mm (paper), and a muscle of the "
        "lumbar region attaches below the upper body's centre of mass at 326 mm (paper; the lower ribs "
        "and the costal margin lie between, estimate).",
    ),
    FreeParameter(
        "lower_y",
        "m",
        -0.10,
        0.035,
        _muscle_paths("muscles.{}.lower.1"),
        "Common height y of the lower (pelvic) attachments.",
        "The iliac crest lies at the level of L4L5 (Tuffier's intercristal line; the paper's L4L5 CoR at "
        "35 mm) and the pubic crest and the dorsal sacrum about 10 cm below P2 (estimate).",
    ),
    FreeParameter(
        "spread",
        "m",
        0.0,
        0.05,
        _muscle_paths("muscles.{}.spread"),
        "Common width of the attachment surfaces across which each muscle's fibres are spread.",
        "Estimate: from a single line of action (0) to 5 cm, about the thickness of the erector spinae "
        "or the rectus abdominis in the plane of the model.",
    ),
)
"""The unstated parameters of the paper and their bounds, in the order of the parameter vector.

Tied to the three pairs of the default preset (straight, oblique_outer,
oblique_inner), whose obliques are mirror images of each other in height.
"""


def parameter_set(names: Sequence[str] | None = None) -> tuple[FreeParameter, ...]:
    """The free parameters called ``names`` (all of :data:`FREE_PARAMETERS` if None).

    Parameters
    ----------
    names : sequence of str, optional
        Subset of the names of :data:`FREE_PARAMETERS`, in the order wanted.
    """
    if names is None:
        return FREE_PARAMETERS
    known = {p.name: p for p in FREE_PARAMETERS}
    unknown = [n for n in names if n not in known]
    if unknown or not names:
        raise ParameterError("parameters", f"must be names among {', '.join(known)} (got {list(names)})")
    return tuple(known[n] for n in names)


def to_model(base: Model, vector, parameters: Sequence[FreeParameter] = FREE_PARAMETERS) -> Model:
    """``base`` with the free parameters set to ``vector``.

    Parameters
    ----------
    base : Model
        Supplies every parameter that is not free.
    vector : array_like, shape (n,)
        Values of ``parameters``, each in its unit.
    parameters : sequence of FreeParameter
    """
    values = {path: float(v) for p, v in zip(parameters, vector, strict=True) for path in p.paths}
    return set_parameters(base, values)


def from_model(model: Model, parameters: Sequence[FreeParameter] = FREE_PARAMETERS) -> np.ndarray:
    """The parameter vector of ``model`` (the first path of each free parameter).

    Parameters
    ----------
    model : Model
    parameters : sequence of FreeParameter
    """
    return np.array([p.value(model) for p in parameters])


def bounds(parameters: Sequence[FreeParameter] = FREE_PARAMETERS) -> list[tuple[float, float]]:
    """The (lower, upper) bounds of ``parameters``, in their units.

    Parameters
    ----------
    parameters : sequence of FreeParameter
    """
    return [(p.lower, p.upper) for p in parameters]


# --- the landmarks as fitting targets ---------------------------------------------------------

STRICT_MARGIN = 0.05
"""Margin of the hinge for '<' and '>' landmarks, as a log-ratio (5 %): a value at the
paper's bound does not satisfy a strict inequality, and one just inside is fragile."""

MISSING_PENALTY = 4.0
"""Penalty of a landmark that cannot be measured (NaN, or a ratio <= 0): as much as a
value off by a factor e^2 = 7.4."""

C_READINGS = 3
"""Readings of the paper's position C (:mod:`spinectl.landmarks`): the corner, the text's optimum, the ridge line."""

WEIGHTS = {
    "ct_A": 0.0,
    **{f"ct_{r}_over_C{s}": 1.0 / C_READINGS for r in "DB" for s in ("", "_text", "_ridge")},
    "halving_K15_other": 0.0,
}
"""Weights of the landmarks in the loss; 1 for any landmark not listed.

``ct_A`` is zero by symmetry under paired activation, whatever the parameters;
the three readings of position C share one weight; ``halving_K15_other`` belongs
to the convention not being fitted (it is reported, not fitted).
"""


@dataclass(frozen=True)
class Target:
    """One landmark as a fitting target.

    Attributes
    ----------
    name : str
        Landmark name (:data:`spinectl.landmarks.LANDMARKS`).
    value : float
        Target value, in the landmark's unit (> 0).
    relation : str
        '~', '<' or '>'.
    weight : float
        Weight in the loss.
    """

    name: str
    value: float
    relation: str
    weight: float = 1.0


def paper_targets(weights: dict[str, float] | None = None) -> tuple[Target, ...]:
    """The paper's landmarks as targets, weighted by ``weights`` (default :data:`WEIGHTS`).

    A landmark whose value is zero (‖CT‖ at A) has no log-ratio and is left out.

    Parameters
    ----------
    weights : dict, optional
        Landmark name to weight; unlisted landmarks weigh 1.
    """
    weights = WEIGHTS if weights is None else weights
    return tuple(
        Target(m.name, m.paper, m.relation, weights.get(m.name, 1.0))
        for m in landmarks.LANDMARKS
        if m.paper > 0 and weights.get(m.name, 1.0) > 0
    )


def synthetic_targets(measurements: Sequence[Measurement], names: Sequence[str] | None = None) -> tuple[Target, ...]:
    """Targets '~' equal to measured values, for the identifiability check.

    Parameters
    ----------
    measurements : sequence of Measurement
        From :func:`spinectl.landmarks.measure` on a model with known parameters.
    names : sequence of str, optional
        Landmarks to use; default every one with a finite positive value. Exact zeros
        (relation '=', e.g. ‖CT‖ at A, whose measured value is rounding) are left out.
    """
    chosen = [m for m in measurements if (names is None or m.landmark.name in names) and m.landmark.relation != "="]
    return tuple(Target(m.landmark.name, m.value, "~") for m in chosen if np.isfinite(m.value) and m.value > 0)


def penalty(target: Target, value: float) -> float:
    """The loss term of one landmark [1]: weight times a squared log-ratio (docs/reproduction.md).

    '~': log(value/target)^2; '<': max(0, log(value/target) + margin)^2; '>':
    max(0, margin - log(value/target))^2, with the margin :data:`STRICT_MARGIN`;
    :data:`MISSING_PENALTY` if the value is not finite and positive.

    Parameters
    ----------
    target : Target
    value : float
        spinectl's measurement, in the landmark's unit.
    """
    if not (np.isfinite(value) and value > 0):
        return target.weight * MISSING_PENALTY
    residual = math.log(value / target.value)
    if target.relation == "<":
        residual = max(0.0, residual + STRICT_MARGIN)
    elif target.relation == ">":
        residual = min(0.0, residual - STRICT_MARGIN)
    return target.weight * residual**2


def loss(measurements: Sequence[Measurement], targets: Sequence[Target]) -> float:
    """The calibration loss: the sum of :func:`penalty` over ``targets``.

    Parameters
    ----------
    measurements : sequence of Measurement
        From :func:`spinectl.landmarks.measure`.
    targets : sequence of Target
    """
    values = {m.landmark.name: m.value for m in measurements}
    return float(sum(penalty(t, values[t.name]) for t in targets))


# --- landscapes -------------------------------------------------------------------------------


def paper_axis(points: int) -> np.ndarray:
    """The paper's E and Lambda axis, 0 to 8 cm, with ``points`` points [m].

    Parameters
    ----------
    points : int
        Number of grid points (81: 1 mm steps).
    """
    return np.linspace(*PAPER_RANGE, int(points))


def other_convention(model: Model) -> str:
    """The passive-stiffness convention that ``model`` does not use.

    Parameters
    ----------
    model : Model
    """
    return next(c for c in CONVENTIONS if c != model.passive.convention)


def with_stiffness(model: Model, stiffness: float, convention: str | None = None) -> Model:
    """``model`` with passive stiffness K [N m/rad] and, if given, its convention.

    Parameters
    ----------
    model : Model
    stiffness : float
        K [N m/rad].
    convention : str, optional
        'physical' or 'paper'.
    """
    values = {"passive.stiffness": float(stiffness)}
    if convention is not None:
        values["passive.convention"] = convention
    return set_parameters(model, values)


def coarse_landscape(model: Model, axis, *, counter_torque: bool = True) -> xr.Dataset:
    """Minimum PCSA (and ‖CT‖) on the grid axis x axis by the fast path, for fitting.

    The variables that :func:`spinectl.landmarks.measure` reads, without the rest
    of a :func:`spinectl.sweep.sweep` Dataset. Without ``counter_torque`` only
    stage 1 is solved (:func:`spinectl.batch.solve_stacked`), and
    ``counter_torque_norm_Nm`` is absent.

    Parameters
    ----------
    model : Model
    axis : array_like, 1-D
        E and Lambda axis [m].
    counter_torque : bool
        Also solve for the least counter torques.
    """
    axis = np.asarray(axis, float)
    e, lam = (a.ravel() for a in np.meshgrid(axis, axis, indexing="ij"))
    data = problem_data(model, checked_coefficients(model, e, lam))
    result = batch.solve_stacked(data, model.optimisation.ct_tolerance, min_pcsa_only=not counter_torque)
    shape, dims = (axis.size, axis.size), ("E", "Lambda")
    variables = {"min_pcsa_cm2": (dims, m2_to_cm2(result.min_pcsa).reshape(shape))}
    if counter_torque:
        variables["counter_torque_norm_Nm"] = (dims, np.linalg.norm(result.counter_torque, axis=-1).reshape(shape))
    return xr.Dataset(variables, coords={"E": axis, "Lambda": axis})


def coarse_landmarks(model: Model, points: int = FIT_POINTS, *, other: bool = False) -> Landmarks:
    """The landscapes the landmarks need, on a coarse grid (:func:`coarse_landscape`).

    K = 0 with counter torques; K = 15 N m/rad with the model's convention; with
    ``other``, K = 15 with the other convention too.

    Parameters
    ----------
    model : Model
    points : int
        Grid points per axis.
    other : bool
        Also the K = 15 landscape of the other convention.
    """
    axis = paper_axis(points)
    k15 = landmarks.PAPER_STIFFNESS
    k0 = coarse_landscape(with_stiffness(model, 0.0), axis)
    own = coarse_landscape(with_stiffness(model, k15), axis, counter_torque=False)
    alt = None
    if other:
        alt = coarse_landscape(with_stiffness(model, k15, other_convention(model)), axis, counter_torque=False)
    return Landmarks(k0, own, alt)


def paper_landscapes(model: Model, points: int = PAPER_POINTS, progress=None) -> tuple[xr.Dataset, xr.Dataset]:
    """Full sweeps for the landmarks: K = 0 and 15 N m/rad (model's convention), and K = 15 (other).

    Parameters
    ----------
    model : Model
    points : int
        Grid points per axis (81: the paper's 1 mm).
    progress : bool or None
        Progress bars (None: on a terminal only).

    Returns
    -------
    both : xarray.Dataset
        :func:`spinectl.sweep.stiffness_sweep` over K = 0 and 15.
    other : xarray.Dataset
        :func:`spinectl.sweep.sweep` at K = 15 with the other convention.
    """
    axis = paper_axis(points)
    k15 = landmarks.PAPER_STIFFNESS
    both = sweep.stiffness_sweep(model, [0.0, k15], axis, axis, progress=progress)
    other = sweep.sweep(with_stiffness(model, k15, other_convention(model)), axis, axis, progress=progress)
    return both, other


def measure_model(model: Model, points: int = PAPER_POINTS, progress=None) -> list[Measurement]:
    """Every landmark of ``model`` measured afresh on the paper's grid (:func:`paper_landscapes`).

    Parameters
    ----------
    model : Model
    points : int
        Grid points per axis.
    progress : bool or None
        Progress bars.
    """
    both, other = paper_landscapes(model, points, progress)
    k15 = landmarks.PAPER_STIFFNESS
    return landmarks.measure(Landmarks(both.sel(K=0.0), both.sel(K=k15), other))


# --- the fit ---------------------------------------------------------------------------------


@dataclass(frozen=True)
class Residual:
    """One landmark of a calibrated model.

    Attributes
    ----------
    name : str
        Landmark name.
    relation : str
        '~', '=', '<' or '>'.
    paper : float
        The paper's value.
    value : float
        spinectl's value.
    unit : str
    log_ratio : float
        log(value / paper); NaN where undefined.
    penalty : float
        Its term in the loss (0 for a landmark that is not fitted).
    agrees : bool
        Within the tolerance of :mod:`spinectl.landmarks`.
    """

    name: str
    relation: str
    paper: float
    value: float
    unit: str
    log_ratio: float
    penalty: float
    agrees: bool


def residuals(measurements: Sequence[Measurement], targets: Sequence[Target]) -> tuple[Residual, ...]:
    """Every landmark with its log-ratio residual and its term in the loss.

    Parameters
    ----------
    measurements : sequence of Measurement
        From :func:`spinectl.landmarks.measure`.
    targets : sequence of Target
        The fitted landmarks; the others get penalty 0.
    """
    by_name = {t.name: t for t in targets}
    out = []
    for m in measurements:
        mark, value = m.landmark, m.value
        ratio = math.log(value / mark.paper) if mark.paper > 0 and np.isfinite(value) and value > 0 else math.nan
        term = penalty(by_name[mark.name], value) if mark.name in by_name else 0.0
        out.append(Residual(mark.name, mark.relation, mark.paper, value, mark.unit, ratio, term, m.agrees))
    return tuple(out)


@dataclass(frozen=True)
class Fit:
    """The best parameters found with one passive-stiffness convention.

    Attributes
    ----------
    convention : str
        'physical' or 'paper'.
    vector : numpy.ndarray
        Its best parameter vector.
    fit_loss : float
        Its loss on the fitting grid.
    loss : float
        Its loss on the verification grid.
    residuals : tuple of Residual
        Every landmark on the verification grid.
    """

    convention: str
    vector: np.ndarray
    fit_loss: float
    loss: float
    residuals: tuple[Residual, ...]


@dataclass(frozen=True)
class CalibrationResult:
    """What :func:`calibrate` returns.

    Attributes
    ----------
    model : Model
        The calibrated model: the best fit's parameters and convention, passive stiffness 0 (Figure 3).
    parameters : tuple of FreeParameter
        The free parameters, in the order of the vectors.
    best : Fit
        The fit of ``model`` (least loss on the verification grid).
    fits : dict
        Convention to :class:`Fit`: every convention tried.
    optimiser : list of scipy.optimize.OptimizeResult
        The optimiser's reports: one per differential-evolution start, then one
        per convention for the local refinement.
    vectors : numpy.ndarray, shape (n_evaluations, n_parameters)
        Every parameter vector evaluated, in order.
    history : numpy.ndarray, shape (n_evaluations, n_conventions)
        The loss of every evaluation with each convention (NaN where a convention was not evaluated).
    seconds : float
        Wall time [s].
    settings : dict
        Seed, starts, grids and budget: what reproduces the run.
    """

    model: Model
    parameters: tuple[FreeParameter, ...]
    best: Fit
    fits: dict[str, Fit]
    optimiser: list
    vectors: np.ndarray
    history: np.ndarray
    seconds: float
    settings: dict = field(default_factory=dict)

    @property
    def evaluations(self) -> int:
        """Number of loss evaluations in all."""
        return len(self.history)

    @property
    def best_history(self) -> np.ndarray:
        """The least loss so far (over the conventions) after each evaluation."""
        return np.fmin.accumulate(np.nanmin(self.history, axis=1))


class _Objective:
    """The loss of a parameter vector on the coarse grid with each convention; keeps every evaluation.

    The K = 0 landscape is shared by the conventions, so fitting them together
    costs one K = 0 and one stage-1 K = 15 landscape per convention. Called
    directly, it returns the least loss over the conventions: the convention is
    a discrete parameter, optimised exactly at every vector.
    """

    def __init__(self, base: Model, parameters, targets, points: int, conventions: Sequence[str]):
        self.base, self.parameters, self.targets = base, tuple(parameters), tuple(targets)
        self.axis, self.conventions = paper_axis(points), tuple(conventions)
        self.vectors: list[np.ndarray] = []
        self.losses: list[np.ndarray] = []

    def evaluate(self, vector, conventions: Sequence[str]) -> np.ndarray:
        """The loss with each of ``conventions`` [1], recorded; a geometry the model rejects gets the most."""
        try:
            model = to_model(self.base, vector, self.parameters)
            k0 = coarse_landscape(with_stiffness(model, 0.0), self.axis)
            values = []
            for convention in conventions:
                stiff = with_stiffness(model, landmarks.PAPER_STIFFNESS, convention)
                k15 = coarse_landscape(stiff, self.axis, counter_torque=False)
                values.append(loss(landmarks.measure(Landmarks(k0, k15)), self.targets))
        except (ParameterError, ModelError):  # e.g. an attachment on a CoR somewhere on the grid
            values = [MISSING_PENALTY * sum(t.weight for t in self.targets)] * len(conventions)
        row = np.full(len(self.conventions), np.nan)
        row[[self.conventions.index(c) for c in conventions]] = values
        self.vectors.append(np.array(vector, float))
        self.losses.append(row)
        return np.asarray(values)

    def __call__(self, vector) -> float:
        return float(self.evaluate(vector, self.conventions).min())

    def best(self, convention: str) -> tuple[np.ndarray, float]:
        """The best vector evaluated so far with ``convention``, and its loss."""
        column = np.array(self.losses)[:, self.conventions.index(convention)]
        i = int(np.nanargmin(column))
        return self.vectors[i], float(column[i])


def _initial_population(base: Model, parameters, popsize: int, seed: int) -> np.ndarray:
    """A Latin hypercube sample of the bounds whose first member is the base model (clipped to the bounds)."""
    lows, highs = np.array(bounds(parameters)).T
    sample = scipy.stats.qmc.LatinHypercube(len(lows), seed=seed).random(max(5, popsize * len(lows)))
    init = lows + sample * (highs - lows)
    init[0] = np.clip(from_model(base, parameters), lows, highs)
    return init


def _reporter(objective: _Objective, say, label: str, every: int, started: float, convention: str | None = None):
    """A per-iteration callback of the optimisers: every ``every`` iterations, say how far the run is.

    The best loss quoted is that of ``convention``, or the least over all conventions if None.
    """
    count = [0]

    def iteration(intermediate_result) -> None:  # scipy passes the OptimizeResult by this name
        count[0] += 1
        if count[0] % every == 0:
            best = objective.best(convention)[1] if convention else np.nanmin(np.array(objective.losses))
            say(
                f"{label} {count[0]}: best loss {best:.4g}, {len(objective.losses)} evaluations, "
                f"{time.perf_counter() - started:.0f} s"
            )

    return iteration


def _evolve(objective: _Objective, parameters, *, seed, starts, popsize, generations, say, started) -> list:
    """The global stage: differential evolution, ``starts`` times, over all conventions at once."""
    reports = []
    for start in range(int(starts)):
        label = f"start {start + 1}/{starts}, generation"
        reports.append(
            scipy.optimize.differential_evolution(
                objective,
                bounds(parameters),
                seed=seed + start,
                maxiter=generations,
                init=_initial_population(objective.base, parameters, popsize, seed + start),
                tol=0.0,
                polish=False,
                callback=_reporter(objective, say, label, 1, started),
            )
        )
    return reports


def _refine(objective: _Objective, parameters, convention: str, evaluations: int, say, started):
    """The local stage: Nelder-Mead from the best vector of ``convention``, in coordinates scaled to the bounds.

    Nelder-Mead needs no gradient, so the steps of the loss (grid arg-maxima
    moving from one grid point to the next) do not stop it; its simplex starts
    at 5 % of each bound's width.
    """
    lows, highs = np.array(bounds(parameters)).T
    start, _ = objective.best(convention)
    u0 = (start - lows) / (highs - lows)
    simplex = np.clip(u0 + np.vstack([np.zeros(len(u0)), REFINE_STEP * np.eye(len(u0))]), 0.0, 1.0)

    def scaled(u) -> float:
        return float(objective.evaluate(lows + np.clip(u, 0.0, 1.0) * (highs - lows), (convention,))[0])

    return scipy.optimize.minimize(
        scaled,
        u0,
        method="Nelder-Mead",
        bounds=[(0.0, 1.0)] * len(u0),
        callback=_reporter(objective, say, f"refining ({convention}), iteration", 20, started, convention),
        options={"maxfev": evaluations, "initial_simplex": simplex, "adaptive": True},
    )


def calibrate(
    base: Model,
    parameters: Sequence[FreeParameter] = FREE_PARAMETERS,
    targets: Sequence[Target] | None = None,
    *,
    conventions: Sequence[str] = CONVENTIONS,
    points: int = FIT_POINTS,
    verify_points: int = PAPER_POINTS,
    seed: int = 0,
    starts: int = 1,
    popsize: int = POPSIZE,
    generations: int = GENERATIONS,
    refine: int = REFINE_EVALUATIONS,
    progress: Callable[[str], None] | None = None,
) -> CalibrationResult:
    """Fit the free parameters of ``base`` to the landmarks, with each passive-stiffness convention.

    Two stages on the coarse grid. Global: differential evolution
    (:func:`scipy.optimize.differential_evolution`, seeded) ``starts`` times with
    seeds ``seed``, ``seed + 1``, ..., minimising the least loss over the
    conventions; each initial population contains the base model's own vector,
    so the fit is never worse than the start. Local: Nelder-Mead from the best
    vector of each convention (``refine`` evaluations each). Then the best
    vector of each convention is measured on the verification grid, and the
    least loss there wins.

    Parameters
    ----------
    base : Model
        Supplies the fixed parameters and a starting vector.
    parameters : sequence of FreeParameter
        What to fit (default :data:`FREE_PARAMETERS`).
    targets : sequence of Target, optional
        Default :func:`paper_targets`.
    conventions : sequence of str
        Passive-stiffness conventions to fit.
    points, verify_points : int
        Grid points per axis while fitting and for the final measurement.
    seed : int
        Seed of the first start.
    starts : int
        Independent runs of differential evolution.
    popsize : int
        Population per free parameter (scipy's ``popsize``).
    generations : int
        Generations per start (scipy's ``maxiter``).
    refine : int
        Loss evaluations of the local refinement per convention (0: none).
    progress : callable, optional
        Called with a line of text as the run proceeds.
    """
    started = time.perf_counter()
    parameters = tuple(parameters)
    targets = paper_targets() if targets is None else tuple(targets)
    unknown = [c for c in conventions if c not in CONVENTIONS]
    if unknown or not conventions or len(set(conventions)) != len(conventions):
        raise ParameterError("conventions", f"must be among {', '.join(CONVENTIONS)} (got {list(conventions)})")
    objective = _Objective(base, parameters, targets, points, conventions)
    say = progress or (lambda line: None)
    budget = {"seed": seed, "starts": starts, "popsize": popsize, "generations": generations}
    reports = _evolve(objective, parameters, **budget, say=say, started=started)
    if refine > 0:
        reports += [_refine(objective, parameters, c, refine, say, started) for c in conventions]
    fits = {}
    for convention in conventions:
        vector, fit_loss = objective.best(convention)
        model = with_stiffness(to_model(base, vector, parameters), 0.0, convention)
        found = residuals(measure_model(model, verify_points, progress=False), targets)
        fits[convention] = Fit(convention, vector, fit_loss, float(sum(r.penalty for r in found)), found)
        say(
            f"{convention}: loss {fit_loss:.4g} on the {points}-point grid, "
            f"{fits[convention].loss:.4g} on the {verify_points}-point grid"
        )
    best = min(fits.values(), key=lambda f: f.loss)
    settings = {
        **budget,
        "refine": refine,
        "points": points,
        "verify_points": verify_points,
        "conventions": list(conventions),
        "parameters": [p.name for p in parameters],
    }
    return CalibrationResult(
        model=with_stiffness(to_model(base, best.vector, parameters), 0.0, best.convention),
        parameters=parameters,
        best=best,
        fits=fits,
        optimiser=reports,
        vectors=np.array(objective.vectors),
        history=np.array(objective.losses),
        seconds=time.perf_counter() - started,
        settings=settings,
    )


STEP_LANDMARKS = ("ridge_slope", "ct_valley_slope", "optimum_lordosis", "ridge_slope_K15")
"""Landmarks read off grid arg-maxima: they move in steps of the grid, not continuously, so a
finite difference cannot see them (:func:`sensitivity`, the identifiability check)."""


def _log(value: float) -> float:
    return math.log(value) if value > 0 else math.nan  # NaN > 0 is False too


@dataclass(frozen=True)
class Sensitivity:
    """How the landmarks respond to the free parameters at one model: what the fit can identify.

    Attributes
    ----------
    landmarks : tuple of str
        The landmarks differentiated: continuous ones with a positive value, not exact zeros.
    jacobian : numpy.ndarray, shape (n_landmarks, n_parameters)
        d log(landmark) / d(parameter / width of its bounds) [1].
    singular_values : numpy.ndarray, shape (n_parameters,)
        Of the Jacobian, largest first [1]: a value near 0 is a direction the landmarks do not see.
    directions : numpy.ndarray, shape (n_parameters, n_parameters)
        Right singular vectors, one per row, in the order of ``singular_values``.
    """

    landmarks: tuple[str, ...]
    jacobian: np.ndarray
    singular_values: np.ndarray
    directions: np.ndarray


def sensitivity(
    model: Model, parameters: Sequence[FreeParameter] = FREE_PARAMETERS, points: int = FIT_POINTS, step: float = 0.01
) -> Sensitivity:
    """Central differences of the log-landmarks in the free parameters, scaled to their bounds.

    Parameters
    ----------
    model : Model
        Where to differentiate (e.g. the calibrated preset); its convention is used at K = 15.
    parameters : sequence of FreeParameter
    points : int
        Grid points per axis of the landscapes.
    step : float
        Half step, as a fraction of each bound's width (clipped to the bounds).
    """
    parameters = tuple(parameters)
    centre = from_model(model, parameters)
    lows, highs = np.array(bounds(parameters)).T

    def logs(vector) -> dict[str, float]:
        found = landmarks.measure(coarse_landmarks(to_model(model, vector, parameters), points))
        return {m.landmark.name: m.value for m in found}

    base = logs(centre)
    exact = {m.name for m in landmarks.LANDMARKS if m.relation == "="}  # zero up to rounding: no log-ratio
    names = tuple(n for n, v in base.items() if n not in STEP_LANDMARKS and n not in exact and v > 0)
    columns = []
    for i in range(len(parameters)):
        up, down = centre.copy(), centre.copy()
        up[i] = min(centre[i] + step * (highs[i] - lows[i]), highs[i])
        down[i] = max(centre[i] - step * (highs[i] - lows[i]), lows[i])
        hi, lo = logs(up), logs(down)
        width = (up[i] - down[i]) / (highs[i] - lows[i])
        columns.append([(_log(hi[n]) - _log(lo[n])) / width for n in names])
    jacobian = np.array(columns).T
    _, singular, directions = np.linalg.svd(jacobian, full_matrices=False)
    return Sensitivity(names, jacobian, singular, directions)


# --- reporting --------------------------------------------------------------------------------


def _number(value: float) -> str:
    return f"{value:.4g}" if np.isfinite(value) else "n/a"


def summary(result: CalibrationResult) -> str:
    """The calibration as text: the parameters with their bounds, each convention's loss, every landmark.

    Parameters
    ----------
    result : CalibrationResult
    """
    best = result.best
    lines = [f"calibrated in {result.seconds:.0f} s, {result.evaluations} evaluations; convention {best.convention}"]
    lines += ["", f"{'parameter':18} {'value':>9} {'lower':>8} {'upper':>8}  unit"]
    for p, v in zip(result.parameters, best.vector, strict=True):
        lines.append(f"{p.name:18} {v:9.4g} {p.lower:8.4g} {p.upper:8.4g}  {p.unit}")
    lines += ["", "convention   loss (fit grid)   loss (verification grid)"]
    for fit in result.fits.values():
        lines.append(f"{fit.convention:12} {fit.fit_loss:15.4g}   {fit.loss:.4g}")
    lines += ["", f"{'landmark':22} {'paper':>9} {'spinectl':>10} {'log-ratio':>10} {'penalty':>8}  agrees"]
    for r in best.residuals:
        paper = f"{RELATION[r.relation]} {r.paper:.3g}"
        lines.append(
            f"{r.name:22} {paper:>9} {_number(r.value):>10} {_number(r.log_ratio):>10} {r.penalty:8.3g}  "
            f"{'yes' if r.agrees else 'no'}"
        )
    return "\n".join(lines)


def preset_toml(result: CalibrationResult, command: str, date: str | None = None) -> str:
    """The calibrated model as a preset TOML, with a header saying how it was produced.

    Parameters
    ----------
    result : CalibrationResult
    command : str
        The command line that produced it.
    date : str, optional
        ISO date; default today.
    """
    date = date or time.strftime("%Y-%m-%d")
    best = result.best
    header = [
        "# spinectl preset calibrated against the landmarks of Wagner et al. (2012); docs/reproduction.md.",
        f"# Produced by: {command}",
        f"# Date: {date}; wall time {result.seconds:.0f} s, {result.evaluations} loss evaluations.",
        f"# Loss: {best.loss:.4g} on the {result.settings['verify_points']}-point grid "
        f"({best.fit_loss:.4g} on the {result.settings['points']}-point fitting grid); "
        f"{sum(r.agrees for r in best.residuals)} of {len(best.residuals)} landmarks agree.",
        f"# Passive-stiffness convention: {best.convention} (losses: "
        + ", ".join(f"{f.convention} {f.loss:.4g}" for f in result.fits.values())
        + ").",
        "# Free parameters (value; bounds):",
    ]
    for p, v in zip(result.parameters, best.vector, strict=True):
        header.append(f"#   {p.name} = {v:.6g} {p.unit}; [{p.lower:g}, {p.upper:g}]")
    return "\n".join(header) + "\n" + dump_toml(result.model)


def history_csv(result: CalibrationResult) -> str:
    """Every loss evaluation as CSV: the parameter vector, then the loss with each convention.

    Parameters
    ----------
    result : CalibrationResult
    """
    names = [f"{p.name}_{p.unit}" for p in result.parameters]
    header = ",".join(["evaluation", *names, *(f"loss_{c}" for c in result.settings["conventions"])])
    rows = [
        ",".join([str(i), *(f"{v:.10g}" for v in vector), *(f"{v:.10g}" for v in losses)])
        for i, (vector, losses) in enumerate(zip(result.vectors, result.history, strict=True))
    ]
    return "\n".join([header, *rows]) + "\n"
