"""The stability of every segment at one point, with the minimum stabilising PCSA by the fast path.

:func:`stability_at` and :func:`minimum_stabilising_pcsa` solve their point with
:func:`spinectl.optimise.active_set.solve_point` (the same answer as the per-point reference
:func:`spinectl.optimise.reference.solve_point` to rounding, docs/optimisation.md), which imports
cvxpy only for a point that fails verification: ``spinectl stability`` starts at once. Here,
above both solvers, so that the reference imports nothing of the fast path that falls back on it.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..errors import ModelError
from ..model.params import Model
from ..model.stability import StabilityResult, segment_stability
from .active_set import solve_point as fast_solve_point
from .problem import PointOptimum


class NoStabilisingActivation(ModelError):
    """No activation within the bounds stabilises every segment (or the solver failed): the caller may
    give a PCSA instead (the library's ``pcsa`` argument; the CLI names its own option)."""


def minimum_stabilising_pcsa(model: Model, eccentricity: float, lordosis: float) -> np.ndarray:
    """The minimum stabilising PCSA [m^2]: the chosen activation of the reference's ``solve_point``, by the fast path.

    Parameters
    ----------
    model : Model
        ``optimisation`` sets activation mode, margin, bounds and tolerances.
    eccentricity, lordosis : float
        E and Lambda [m].

    Returns
    -------
    numpy.ndarray, shape (n_muscles,)
        PCSA of each muscle [m^2] that makes every segment self-stable.

    Raises
    ------
    NoStabilisingActivation
        A :class:`~spinectl.errors.ModelError`: no activation within the bounds stabilises every
        segment, or the solver failed (the message names the optimiser's status and suggests
        giving the PCSA, the ``pcsa`` argument of :func:`stability_at`).
    """
    return _stabilising_optimum(model, eccentricity, lordosis).pcsa


def _stabilising_optimum(model: Model, eccentricity: float, lordosis: float) -> PointOptimum:
    """The optimum of the reference's ``solve_point``, or :func:`minimum_stabilising_pcsa`'s error unless optimal.

    Solved by the fast path (:func:`spinectl.optimise.active_set.solve_point`, the same answer to rounding).
    """
    optimum = fast_solve_point(model, eccentricity, lordosis)
    if not optimum.ok:
        raise NoStabilisingActivation(
            f"pcsa: no activation stabilises every segment at E = {eccentricity:g} m, Lambda = {lordosis:g} m "
            f"(optimiser status {optimum.status}); give the PCSA (argument pcsa, [m^2])"
        )
    return optimum


def stability_at(
    model: Model, eccentricity: float, lordosis: float, pcsa=None, *, slip_check: bool = True
) -> StabilityResult:
    """Stability of every segment for a PCSA, by default the minimum stabilising one.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    pcsa : array_like, optional
        PCSA [m^2], per pair or per muscle (:func:`spinectl.model.checks.expand_pcsa`);
        default :func:`minimum_stabilising_pcsa`.
    slip_check : bool
        True (the default): a ``pcsa`` above :data:`spinectl.model.checks.MAX_PLAUSIBLE_PCSA` is refused
        as cm^2 typed where m^2 are meant. False: the caller has checked its unit (``--pcsa``, in cm^2), and
        it is analysed whatever its size, as a computed optimum is (docs/robustness.md, "Model evaluation").

    Returns
    -------
    StabilityResult
        :func:`spinectl.model.stability.segment_stability` at that PCSA; with the optimiser's
        PCSA, its ``min_pcsa`` is the LP minimum [m^2].

    Raises
    ------
    ModelError
        ``pcsa`` not given and no activation stabilises every segment.
    ParameterError
        E, Lambda or ``pcsa`` out of range.

    Examples
    --------
    >>> from spinectl import load_preset
    >>> from spinectl.optimise.stabilising import stability_at
    >>> result = stability_at(load_preset("wagner2012"), 0.03, 0.04)
    >>> round(float(result.min_pcsa) * 1e4, 1), bool(result.self_stable.all())  # [cm^2]
    (35.8, True)
    """
    if pcsa is not None:
        return segment_stability(model, eccentricity, lordosis, pcsa, given=slip_check)
    optimum = _stabilising_optimum(model, eccentricity, lordosis)
    # the optimum is an answer however large (as in a sweep), not a PCSA typed in the wrong unit
    result = segment_stability(model, eccentricity, lordosis, optimum.pcsa, given=False)
    return dataclasses.replace(result, min_pcsa=optimum.min_pcsa)
