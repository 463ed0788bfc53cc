"""The fit: differential evolution, then Nelder-Mead, then verification on the paper's grid.

:func:`calibrate` is the routine behind ``spinectl calibrate``
(docs/reproduction.md, "The optimiser"). The passive-stiffness convention
(docs/model.md, "Passive stiffness: two conventions") is a discrete choice, fitted
both ways and reported.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ... import _validate as v
from ...errors import ModelError, ParameterError
from ...landscape.budget import duration
from ...model.params import Model
from .. import grid, landmarks
from ..landmarks import Landmarks
from .landscapes import FIT_POINTS, coarse_landscape
from .parameters import FREE_PARAMETERS, FreeParameter, bounds, from_model, to_model
from .targets import MISSING_PENALTY, Residual, Target, loss, paper_targets, residuals

POPSIZE = 6
"""Population of differential evolution per free parameter (scipy's ``popsize``): 42 for 7 parameters."""

GENERATIONS = 16
"""Generations of differential evolution per start (scipy's ``maxiter``)."""

REFINE_EVALUATIONS = 120
"""Loss evaluations of the local refinement (Nelder-Mead) per convention. With :data:`POPSIZE`
and :data:`GENERATIONS` about 950 evaluations in all: 2-4 minutes on one core (docs/reproduction.md)."""

BUDGET_RANGES = {"seed": (0, 2**31 - 1), "starts": (1, 100), "popsize": (1, 1000), "generations": (1, 100_000)}
"""Allowed [low, high] of the run's integer settings.

Seeds: scipy seeds numpy's legacy generator, which takes 0 <= seed + start < 2^32.
The other highs are far beyond any useful run (a population of 1000 per parameter
already costs about 10^4 losses a generation) and reject a typo before it asks for
terabytes (popsize 10^12)."""

REFINE_RANGE = (0, 1_000_000)
"""Allowed [low, high] of ``refine``, the local refinement's loss evaluations per convention."""

REFINE_STEP = 0.05
"""Size of the refinement's initial simplex, as a fraction of each bound's width."""


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
    origin : str
        The convention whose search found ``vector`` (the convention is picked at the final
        vector, so it may differ from ``convention``).
    """

    convention: str
    vector: np.ndarray
    fit_loss: float
    loss: float
    residuals: tuple[Residual, ...]
    origin: str = ""


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
        self.axis, self.conventions = grid.paper_axis(points), tuple(conventions)
        self.vectors: list[np.ndarray] = []
        self.losses: list[np.ndarray] = []

    def evaluate(self, vector, conventions: Sequence[str]) -> np.ndarray:
        """The loss with each of ``conventions`` [1], recorded; a geometry the model rejects gets the most."""
        try:
            model = to_model(self.base, vector, self.parameters)
            k0 = coarse_landscape(grid.with_stiffness(model, 0.0), self.axis)
            values = []
            for convention in conventions:
                stiff = grid.with_stiffness(model, grid.PAPER_STIFFNESS, convention)
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
    import scipy.stats  # here: scipy.stats and scipy.optimize take most of a second, and only a fit needs them

    lows, highs = np.array(bounds(parameters)).T
    sample = scipy.stats.qmc.LatinHypercube(len(lows), seed=seed).random(max(5, popsize * len(lows)))
    init = lows + sample * (highs - lows)
    init[0] = np.clip(from_model(base, parameters), lows, highs)
    return init


def _reporter(
    objective: _Objective, say, label: str, every: int, started: float, convention=None, *, total=None, planned=0
):
    """A per-iteration callback of the optimisers: every ``every`` iterations, say how far the run is.

    The best loss quoted is that of ``convention``, or the least over all conventions if None; ``total``
    iterations of this stage (None: no fixed number), ``planned`` evaluations of the whole fit (:func:`_planned`).
    """
    count = [0]

    def iteration(intermediate_result) -> None:  # scipy passes the OptimizeResult by this name
        count[0] += 1
        if count[0] % every == 0:
            best = objective.best(convention)[1] if convention else np.nanmin(np.array(objective.losses))
            say(
                progress_line(
                    label, count[0], total, best, len(objective.losses), planned, time.perf_counter() - started
                )
            )

    return iteration


def progress_line(label: str, count: int, total, best: float, evaluations: int, planned: int, seconds: float) -> str:
    """A calibration's progress: ``start 1/1, generation 9 of 16: best loss 1.335, 420 evaluations, 101 s, about 1.2
    min left``.

    Parameters
    ----------
    label : str
        The stage and its iteration's name.
    count : int
        Iterations of the stage done.
    total : int or None
        Iterations of the stage (None: no fixed number, as Nelder-Mead's).
    best : float
        The best loss so far.
    evaluations : int
        Loss evaluations so far.
    planned : int
        Evaluations the fit will make at most (:func:`_planned`); 0: no estimate of the time left.
    seconds : float
        Time since the fit started [s].

    Returns
    -------
    str
        The line; the time left is the time per evaluation so far times the evaluations left (at most
        ``planned``: a refinement may stop earlier), the verification's larger grids not counted.
    """
    of = "" if total is None else f" of {total}"
    line = f"{label} {count}{of}: best loss {best:.4g}, {evaluations} evaluations, {seconds:.0f} s"
    if planned <= 0 or evaluations <= 0:
        return line
    left = seconds / evaluations * max(planned - evaluations, 0)
    return f"{line}, about {duration(left)} left"


def _planned(starts: int, popsize: int, generations: int, refine: int, n_parameters: int, n_conventions: int) -> int:
    """The evaluations a fit makes at most: each start's initial population and its generations (each a
    population: ``polish`` is off), then each convention's refinement (at most ``refine``)."""
    population = max(5, popsize * n_parameters)  # as _initial_population draws it
    return starts * (generations + 1) * population + refine * n_conventions


def _evolve(objective: _Objective, parameters, *, seed, starts, popsize, generations, say, started, planned) -> list:
    """The global stage: differential evolution, ``starts`` times, over all conventions at once."""
    import scipy.optimize

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
                callback=_reporter(objective, say, label, 1, started, total=generations, planned=planned),
            )
        )
    return reports


def _refine(objective: _Objective, parameters, convention: str, evaluations: int, say, started, planned: int):
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

    import scipy.optimize

    return scipy.optimize.minimize(
        scaled,
        u0,
        method="Nelder-Mead",
        bounds=[(0.0, 1.0)] * len(u0),
        callback=_reporter(
            objective, say, f"refining ({convention}), iteration", 20, started, convention, planned=planned
        ),
        options={"maxfev": evaluations, "initial_simplex": simplex, "adaptive": True},
    )


def convention_losses(model: Model, targets: Sequence[Target], points: int = grid.PAPER_POINTS) -> dict:
    """The loss of ``model``'s parameter vector with each passive-stiffness convention, from one set of sweeps.

    :func:`spinectl.paper.grid.paper_landscapes` solves K = 0 and K = 15 N m/rad with both conventions
    at once, so scoring the vector with each convention costs no more than scoring it once.

    Parameters
    ----------
    model : Model
        The vector to score (its passive stiffness is replaced by 0 and 15 N m/rad).
    targets : sequence of Target
    points : int
        Grid points per axis.

    Returns
    -------
    dict
        Convention (each of :data:`spinectl.paper.grid.CONVENTIONS`) to (loss [1], tuple of Residual).
    """
    both, other = grid.paper_landscapes(model, points, progress=False)
    k15 = {model.passive.convention: both.sel(K=grid.PAPER_STIFFNESS), grid.other_convention(model): other}
    out = {}
    for convention in grid.CONVENTIONS:
        alternative = next(k15[c] for c in grid.CONVENTIONS if c != convention)
        found = residuals(landmarks.measure(Landmarks(both.sel(K=0.0), k15[convention], alternative)), targets)
        out[convention] = (float(sum(r.penalty for r in found)), found)
    return out


def _verify(objective: _Objective, conventions: Sequence[str], verify_points: int, say) -> dict[str, Fit]:
    """Each convention's best vector measured on the verification grid, and its loss there with every convention.

    The convention is picked at the final vector (:func:`convention_losses`): each convention keeps
    the vector that scores best with it, whichever convention's search found it (:attr:`Fit.origin`).
    """
    fits: dict[str, Fit] = {}
    for origin in conventions:
        vector, _ = objective.best(origin)
        model = grid.with_stiffness(to_model(objective.base, vector, objective.parameters), 0.0, origin)
        scored = convention_losses(model, objective.targets, verify_points)
        for convention in conventions:
            verified, found = scored[convention]
            if convention not in fits or verified < fits[convention].loss:
                fit_loss = float(objective.evaluate(vector, (convention,))[0])
                fits[convention] = Fit(convention, vector, fit_loss, verified, found, origin)
        say(
            f"best {origin} vector on the {verify_points}-point grid: "
            + ", ".join(f"{c} {scored[c][0]:.4g}" for c in conventions)
        )
    return fits


def _check_settings(conventions: Sequence[str], **settings: int) -> None:
    """Raise :class:`ParameterError` for unknown or repeated conventions or a setting out of range."""
    unknown = [c for c in conventions if c not in grid.CONVENTIONS]
    if unknown or not conventions or len(set(conventions)) != len(conventions):
        raise ParameterError(
            "conventions", f"must be distinct names among {', '.join(grid.CONVENTIONS)} (got {list(conventions)})"
        )
    ranges = BUDGET_RANGES | {"refine": REFINE_RANGE}
    for name, value in settings.items():
        v.integer(name, value, *ranges[name])


def calibrate(
    base: Model,
    parameters: Sequence[FreeParameter] = FREE_PARAMETERS,
    targets: Sequence[Target] | None = None,
    *,
    conventions: Sequence[str] = grid.CONVENTIONS,
    points: int = FIT_POINTS,
    verify_points: int = grid.PAPER_POINTS,
    seed: int = 0,
    starts: int = 1,
    popsize: int = POPSIZE,
    generations: int = GENERATIONS,
    refine: int = REFINE_EVALUATIONS,
    progress: Callable[[str], None] | None = None,
) -> CalibrationResult:
    """Fit the free parameters of ``base`` to the landmarks, with each passive-stiffness convention.

    Two stages on the coarse grid. Global: differential evolution [1]_
    (:func:`scipy.optimize.differential_evolution`, seeded) ``starts`` times with
    seeds ``seed``, ``seed + 1``, ..., minimising the least loss over the
    conventions; each initial population contains the base model's own vector,
    so the fit is never worse than the start. Local: Nelder-Mead [2]_ from the best
    vector of each convention (``refine`` evaluations each). Then the best
    vector of each convention is measured on the verification grid with every
    convention, and the least loss there, over vectors and conventions, wins:
    the convention is picked at the final vector.

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

    Returns
    -------
    CalibrationResult
        The calibrated model (passive stiffness 0, the winning convention), the fit of
        each convention with its losses and residuals, every evaluated vector and its
        losses, the optimiser's reports, the wall time [s] and the settings.

    References
    ----------
    .. [1] Storn R, Price K (1997). Differential evolution - a simple and efficient
       heuristic for global optimization over continuous spaces. J Global Optim
       11:341-359.
    .. [2] Nelder JA, Mead R (1965). A simplex method for function minimization.
       Comput J 7:308-313.
    """
    started = time.perf_counter()
    parameters = tuple(parameters)
    targets = paper_targets() if targets is None else tuple(targets)
    _check_settings(conventions, seed=seed, starts=starts, popsize=popsize, generations=generations, refine=refine)
    objective = _Objective(base, parameters, targets, points, conventions)
    say = progress or (lambda line: None)
    budget = {"seed": seed, "starts": starts, "popsize": popsize, "generations": generations}
    planned = _planned(starts, popsize, generations, refine, len(parameters), len(conventions))
    reports = _evolve(objective, parameters, **budget, say=say, started=started, planned=planned)
    if refine > 0:
        reports += [_refine(objective, parameters, c, refine, say, started, planned) for c in conventions]
    fits = _verify(objective, conventions, verify_points, say)
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
        model=grid.with_stiffness(to_model(base, best.vector, parameters), 0.0, best.convention),
        parameters=parameters,
        best=best,
        fits=fits,
        optimiser=reports,
        vectors=np.array(objective.vectors),
        history=np.array(objective.losses),
        seconds=time.perf_counter() - started,
        settings=settings,
    )
