"""The landscape's variables at a list of points, solved chunk by chunk.

The grid is solved in chunks of points (working memory stays flat however fine the grid),
each chunk by the fast path (:mod:`spinectl.optimise.active_set`) or the per-point reference
(:mod:`spinectl.optimise.reference`); the reflex columns follow from the chosen activation
(:mod:`spinectl.reflex.maps`).

Every output of :mod:`spinectl.landscape.schema` is computed here, each by one function: the sweep,
the study and the atlas (whose draws' coefficients are its own, :mod:`spinectl.landscape.atlas`) call
the same functions, so that one name means one quantity wherever it is written.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from ..errors import ParameterError
from ..model import chain, stability
from ..model.checks import arithmetic_guard, checked_coefficients
from ..model.mechanics import SegmentCoefficients, passive_stiffness
from ..model.params import Model
from ..optimise import active_set, stacked
from ..optimise.problem import OK_STATUSES, problem_data
from ..reflex.delay import STATUS
from ..reflex.inputs import guarded
from ..reflex.maps import landscape
from ..units import M2_PER_CM2, m2_to_cm2

DEFAULT_CHUNK = 1024
"""Grid points per stacked problem: large enough that Python overheads vanish, small enough to keep memory flat."""


def point_columns(
    model: Model,
    eccentricity,
    lordosis,
    *,
    method: str = "fast",
    chunk_size: int = DEFAULT_CHUNK,
    update=None,
    coupled: bool = False,
) -> tuple[dict[str, np.ndarray], int]:
    """Every variable of :data:`VARIABLES` at the points (E_i, Lambda_i), solved chunk by chunk.

    Those of :data:`~spinectl.landscape.schema.ON_REQUEST` only if ``coupled``.

    The fast path solves each chunk of ``chunk_size`` consecutive points as one
    stacked problem, so the answer depends on the chunking only through the
    solver's tolerance; the same points in the same chunks give the same bits.

    Parameters
    ----------
    model : Model
        The parameters; ``passive.stiffness`` is K.
    eccentricity, lordosis : array_like, shape (P,)
        E and Lambda of each point [m].
    method : {'fast', 'per-point'}
    chunk_size : int
        Points per chunk.
    update : callable, optional
        Called with the number of points solved, after each chunk (fast) or point (per-point).
    coupled : bool
        Also the coupled chain's SDP variables (:data:`~spinectl.landscape.schema.ON_REQUEST`).

    Returns
    -------
    columns : dict of str to numpy.ndarray
        Each variable with leading dimension P, in the units of its name.
    per_point : int
        Points that the per-point reference solved (all of them with ``method='per-point'``).
    """
    options = {"method": method, "chunk_size": chunk_size, "update": update, "coupled": coupled}
    return passive_columns([model], eccentricity, lordosis, **options)[0]


def passive_columns(
    models: Sequence[Model],
    eccentricity,
    lordosis,
    *,
    method: str = "fast",
    chunk_size: int = DEFAULT_CHUNK,
    update=None,
    coupled: bool = False,
) -> list[tuple[dict[str, np.ndarray], int]]:
    """:func:`point_columns` of several models that differ in their passive stiffness alone, in one pass.

    K enters the model only as -K_pas on the diagonal of the stiffness
    (:func:`spinectl.model.mechanics.passive_stiffness`, docs/model.md, "Passive stiffness: two
    conventions"), so the segments' and the chain's coefficients per unit PCSA are computed and
    checked once per chunk and each model gets its own K_pas: the same arrays, bit for bit, as one
    :func:`point_columns` per model (the paper's landscapes, K = 0 and 15 N m/rad in both
    conventions, share one geometry).

    Parameters
    ----------
    models : sequence of Model
        Equal but for ``passive`` (K and its convention); at least one.
    eccentricity, lordosis : array_like, shape (P,)
        E and Lambda of each point [m].
    method, chunk_size, coupled
        As for :func:`point_columns`.
    update : callable, optional
        Called with the number of points solved, for each model in turn.

    Returns
    -------
    list of (dict of str to numpy.ndarray, int)
        :func:`point_columns`'s answer for each model, in the order of ``models``.

    Raises
    ------
    ParameterError
        ``models`` empty, or differing in more than ``passive``.
    """
    _check_passive_only(models)
    e_grid, l_grid = np.asarray(eccentricity, float), np.asarray(lordosis, float)
    update = update or (lambda n: None)
    answers = [({}, 0) for _ in models]  # filled chunk by chunk: no copies of the answer beyond the answer
    for start in range(0, e_grid.size, int(chunk_size)):
        part = slice(start, start + int(chunk_size))
        e, lam = e_grid[part], l_grid[part]
        shared = checked_coefficients(models[0], e, lam)  # raises for bad input
        with arithmetic_guard(e, lam):
            shared_chain = chain.chain_coefficients(models[0], e, lam)
        for i, model in enumerate(models):
            coeffs, chain_coeffs = shared, shared_chain
            if i > 0:  # the chain's K_pas is the segments' (the same CoRs and theta_k)
                coeffs = with_passive(model, shared, e, lam)
                chain_coeffs = dataclasses.replace(shared_chain, passive_stiffness=coeffs.passive_stiffness)
            columns, per_point = _chunk(model, e, lam, coeffs, chain_coeffs, method, update, coupled)
            arrays = answers[i][0]
            for name, values in columns.items():
                if name not in arrays:
                    arrays[name] = np.empty((e_grid.size,) + values.shape[1:], values.dtype)
                arrays[name][part] = values
            answers[i] = (arrays, answers[i][1] + per_point)
    return answers


def _check_passive_only(models: Sequence[Model]) -> None:
    """Raise :class:`ParameterError` unless ``models`` is not empty and its models differ in ``passive`` alone."""
    if not models:
        raise ParameterError("models", "must hold at least one model")
    first = models[0]
    if any(dataclasses.replace(model, passive=first.passive) != first for model in models[1:]):
        raise ParameterError("models", "must differ in passive (K and its convention) alone")


def with_passive(model: Model, coeffs: SegmentCoefficients, eccentricity, lordosis) -> SegmentCoefficients:
    """The segment coefficients of ``model`` from those of a model that differs from it in ``passive`` alone.

    K enters only as K_pas (:func:`spinectl.model.mechanics.passive_stiffness`), about the same
    CoRs, so from the same theta_k: the arrays of
    :func:`~spinectl.model.checks.checked_coefficients` for ``model``, bit for bit, checked finite.

    Parameters
    ----------
    model : Model
        The model whose K_pas is wanted.
    coeffs : SegmentCoefficients
        Checked coefficients at the points, of a model equal to ``model`` but for ``passive``.
    eccentricity, lordosis : array_like
        E and Lambda of the points [m], named by an error.

    Returns
    -------
    SegmentCoefficients
        ``coeffs`` with the passive stiffness of ``model`` [N m/rad].

    Raises
    ------
    ModelError
        K_pas overflows (:func:`spinectl.model.checks.arithmetic_guard`).
    """
    with arithmetic_guard(eccentricity, lordosis):
        passive = passive_stiffness(model, coeffs.inertia)
        if not np.all(np.isfinite(passive)):
            raise FloatingPointError("non-finite passive stiffness")
    return dataclasses.replace(coeffs, passive_stiffness=passive)


def _chunk(model: Model, e, lam, coeffs, chain_coeffs, method: str, update, coupled: bool):
    """One model's variables on one chunk of points, from its coefficients; and the points solved per point."""
    data = problem_data(model, coeffs)
    tol = model.optimisation.ct_tolerance
    if method == "fast":
        result = active_set.solve_block(data, tol)
        update(len(data.stability))
    else:
        result = stacked.solve_points(data, tol, progress=update)
    columns = segment_columns(model, e, lam, coeffs, result)
    with arithmetic_guard(e, lam), guarded():
        stiffness = chain_stiffness(chain_coeffs, result.pcsa)
        columns |= coupled_margin_columns(stiffness)
    if coupled:  # SDPs: outside numpy's guard
        columns |= local_stiffness_columns(model, stiffness, method)
        columns |= _joint_optimum(model, e, lam, data, chain_coeffs, method)
    return columns, result.per_point


def segment_columns(model: Model, e, lam, coeffs, result, activation=None, lag=None) -> dict[str, np.ndarray]:
    """The joint-by-joint variables of a block of points: the optimum, its coefficients, its reflex.

    The sweep, the study and the atlas take these from here (docs/optimisation.md, the table of variables).

    Parameters
    ----------
    model : Model
        The tolerances and the reflex.
    e, lam : numpy.ndarray, shape (P,)
        E and Lambda of the points [m], named by an overflow's error.
    coeffs : SegmentCoefficients
        The segments' coefficients at the points (checked).
    result : BlockOptimum
        The joint-by-joint optimum at the points (:func:`spinectl.optimise.active_set.solve_block`).
    activation, lag : array_like, shape (P,), optional
        ``reflex.activation`` [1] and ``reflex.activation_time_constant`` [s] per point (the atlas's draws);
        None: the model's.

    Returns
    -------
    dict of str to numpy.ndarray
        :data:`~spinectl.landscape.schema.VARIABLES` but the coupled chain's, leading dimension P, in the
        units of their names.
    """
    with arithmetic_guard(e, lam), guarded():  # e.g. K = 1e154 overflows S^2 in the reflex
        columns = _reflex_columns(model, coeffs, result.pcsa, activation, lag) | _optimum_columns(result)
        columns |= _coefficient_columns(coeffs)
        columns["slowest_time_constant_s"] = _slowest_time_constant(coeffs, result.pcsa)
    return columns


def _optimum_columns(result: stacked.BlockOptimum) -> dict[str, np.ndarray]:
    """The joint-by-joint optimum's variables [cm^2, N m]."""
    return {
        "min_pcsa_cm2": m2_to_cm2(result.min_pcsa),
        "pcsa_cm2": m2_to_cm2(result.pcsa),
        "counter_torque_Nm": result.counter_torque,
        "counter_torque_norm_Nm": np.linalg.norm(result.counter_torque, axis=-1),
        "status": result.status.astype(object),
    }


def _coefficient_columns(coeffs) -> dict[str, np.ndarray]:
    """The segments' coefficients, per cm^2 of PCSA where they scale with it."""
    return {
        "stiffness_per_cm2": coeffs.stiffness_per_pcsa * M2_PER_CM2,
        "damping_per_cm2": coeffs.damping_per_pcsa * M2_PER_CM2,
        "torque_per_cm2": coeffs.torque_per_pcsa * M2_PER_CM2,
        "gravity_stiffness_Nm_per_rad": coeffs.gravity_stiffness,
        "gravity_torque_Nm": coeffs.gravity_torque,
        "passive_stiffness_Nm_per_rad": coeffs.passive_stiffness,
        "inertia_kgm2": coeffs.inertia,
    }


def counter_torque_max_columns(result) -> dict[str, np.ndarray]:
    """The largest abs(CT_k) over the segments at the chosen activation [N m] (the atlas's ±30 N m verdict).

    Parameters
    ----------
    result : BlockOptimum
        The joint-by-joint optimum at P points.

    Returns
    -------
    dict of str to numpy.ndarray
        ``counter_torque_max_Nm``, shape (P,).
    """
    return {"counter_torque_max_Nm": np.max(np.abs(result.counter_torque), axis=-1)}


def _slowest_time_constant(coeffs, pcsa) -> np.ndarray:
    """The slowest time constant of the segments at the chosen activation [s], NaN where infeasible (eq. 1)."""
    filled = np.nan_to_num(pcsa)
    tau = stability.slowest_time_constant(coeffs.stiffness(filled), coeffs.damping(filled), coeffs.inertia)
    return np.where(np.isnan(pcsa).any(axis=-1), np.nan, tau)


def chain_stiffness(chain_coeffs: chain.ChainCoefficients, pcsa) -> np.ndarray:
    """The coupled chain's K with the global muscles at ``pcsa``, NaN where infeasible (docs/chain.md).

    Parameters
    ----------
    chain_coeffs : ChainCoefficients
        The chain's coefficients at P points.
    pcsa : numpy.ndarray, shape (P, n_muscles)
        The global muscles' PCSA [m^2]; NaN where the optimum is infeasible.

    Returns
    -------
    numpy.ndarray, shape (P, n_cor, n_cor)
        K [N m/rad].
    """
    stiffness = chain_coeffs.stiffness(np.nan_to_num(pcsa))
    return np.where(np.isnan(pcsa).any(axis=-1)[:, None, None], np.nan, stiffness)


def coupled_margin_columns(stiffness) -> dict[str, np.ndarray]:
    """The coupled chain's static margin at the chosen activation, the smallest eigenvalue of -K (docs/chain.md).

    Parameters
    ----------
    stiffness : numpy.ndarray, shape (P, n, n)
        The chain's K at the chosen activation, :func:`chain_stiffness` of the minimum PCSA [N m/rad].

    Returns
    -------
    dict of str to numpy.ndarray
        ``coupled_margin_Nm_per_rad``, shape (P,) [N m/rad]; > 0 stable, NaN where infeasible.
    """
    margin = chain.coupled_margin(np.nan_to_num(stiffness))
    return {"coupled_margin_Nm_per_rad": np.where(np.isnan(stiffness[:, 0, 0]), np.nan, margin)}


def least_local_stiffness(model: Model, stiffness, method: str = "fast") -> np.ndarray:
    """The least local stiffness k_j at every point, problem (a) of docs/chain.md, at the chain's K given.

    The fast path solves the points as one stacked SDP, the per-point method one cvxpy SDP per point.

    Parameters
    ----------
    model : Model
        ``optimisation.stability_margin`` and ``solver_tolerance``.
    stiffness : numpy.ndarray, shape (P, n, n)
        The chain's K with the global muscles at the activation asked for [N m/rad]; NaN rows: infeasible.
    method : {'fast', 'per-point'}

    Returns
    -------
    numpy.ndarray, shape (P, n)
        k_j [N m/rad]; NaN where infeasible or not solved.
    """
    from ..optimise import coupled  # cvxpy (a second of imports) only where the chain's SDPs are asked for

    opt = model.optimisation
    if method == "fast":
        _, k = coupled.least_local_stiffness_stacked(stiffness, opt.stability_margin, opt.solver_tolerance)
        return k
    k = np.full(stiffness.shape[:-1], np.nan)
    for i in np.flatnonzero(np.isfinite(stiffness[:, 0, 0])):
        _, found = coupled.least_local_stiffness_at(stiffness[i], opt.stability_margin, opt.solver_tolerance)
        k[i] = np.nan if found is None else found
    return k


def local_stiffness_columns(model: Model, stiffness, method: str = "fast") -> dict[str, np.ndarray]:
    """The least local stiffness with the global muscles at the whole chosen activation, per joint and total.

    Parameters
    ----------
    model : Model
    stiffness : numpy.ndarray, shape (P, n, n)
        The chain's K at the chosen activation, :func:`chain_stiffness` of the minimum PCSA [N m/rad].
    method : {'fast', 'per-point'}

    Returns
    -------
    dict of str to numpy.ndarray
        ``local_stiffness_Nm_per_rad`` (P, n) and ``local_stiffness_total_Nm_per_rad`` (P,).
    """
    k = least_local_stiffness(model, stiffness, method)
    return {"local_stiffness_Nm_per_rad": k, "local_stiffness_total_Nm_per_rad": np.sum(k, axis=-1)}


def cocontraction_local_stiffness_columns(
    model: Model, e, lam, chain_coeffs, pcsa, activation=None, method: str = "fast"
) -> dict[str, np.ndarray]:
    """The least local stiffness with the global muscles at ``reflex.activation`` x the chosen PCSA: total, largest.

    The co-contraction that the delay margin also assumes (:func:`segment_columns`), so that the local
    muscles supply what that activation leaves; at ``reflex.activation`` = 1 the total is
    ``local_stiffness_total_Nm_per_rad`` (:func:`local_stiffness_columns`), bit for bit.

    Parameters
    ----------
    model : Model
    e, lam : numpy.ndarray, shape (P,)
        E and Lambda of the points [m], named by an overflow's error.
    chain_coeffs : ChainCoefficients
        The chain's coefficients at the points.
    pcsa : numpy.ndarray, shape (P, n_muscles)
        The chosen activation [m^2]; NaN where infeasible.
    activation : array_like, shape (P,), optional
        ``reflex.activation`` per point [1]; None: the model's.
    method : {'fast', 'per-point'}

    Returns
    -------
    dict of str to numpy.ndarray
        ``cocontraction_local_stiffness_total_Nm_per_rad`` and ``cocontraction_local_stiffness_max_Nm_per_rad``,
        shape (P,) [N m/rad].
    """
    with arithmetic_guard(e, lam):
        stiffness = chain_stiffness(chain_coeffs, _scaled(model, activation) * pcsa)
    k = least_local_stiffness(model, stiffness, method)
    return {
        "cocontraction_local_stiffness_total_Nm_per_rad": np.sum(k, axis=-1),
        "cocontraction_local_stiffness_max_Nm_per_rad": np.max(k, axis=-1),
    }


def local_stiffness_limit_columns(model: Model, local_pcsa_limit: float, points: int) -> dict[str, np.ndarray]:
    """The local muscles' stiffness at a PCSA per joint [N m/rad]: kappa times the limit, at every point.

    Parameters
    ----------
    model : Model
        ``local``: kappa, the stiffness per unit PCSA.
    local_pcsa_limit : float
        The limit [cm^2] (the atlas's ``local_pcsa_limit_cm2``).
    points : int
        P.

    Returns
    -------
    dict of str to numpy.ndarray
        ``local_stiffness_limit_Nm_per_rad``, shape (P,).
    """
    limit = chain.local_stiffness_per_pcsa(model) * local_pcsa_limit * M2_PER_CM2
    return {"local_stiffness_limit_Nm_per_rad": np.full(points, limit)}


def delay_columns(delay) -> dict[str, np.ndarray]:
    """The reflex delay at every point [s], beside its delay margin (the atlas's ``stable_at_delay``).

    Parameters
    ----------
    delay : array_like, shape (P,)
        ``reflex.delay`` per point [s].

    Returns
    -------
    dict of str to numpy.ndarray
        ``delay_s``, shape (P,).
    """
    return {"delay_s": np.asarray(delay, float)}


def _scaled(model: Model, activation) -> np.ndarray | float:
    """``reflex.activation``: the model's, or one per point as a column that scales a (P, n) PCSA."""
    return model.reflex.activation if activation is None else np.asarray(activation, float)[:, None]


def _joint_optimum(model: Model, eccentricity, lordosis, data, coefficients, method: str) -> dict[str, np.ndarray]:
    """The joint optimum of global and local muscle, problem (c) of docs/chain.md: its two totals [cm^2].

    The fast path solves the chunk as one stacked SDP and falls back to one cvxpy SDP per point
    where the stack fails as a whole (e.g. one infeasible point); the per-point method always does.
    """
    from ..optimise import coupled  # as in least_local_stiffness

    kappa = chain.local_stiffness_per_pcsa(model) * M2_PER_CM2  # N m/rad per cm^2
    status = "per-point"
    if method == "fast":
        opt = model.optimisation
        status, x, k = coupled.joint_optimum_stacked(
            data, coefficients, opt.stability_margin, kappa, model.local.cost_weight
        )
    if status not in OK_STATUSES:
        x = np.full((eccentricity.size, data.weights.size), np.nan)
        k = np.full((eccentricity.size, len(model.geometry.cor_names)), np.nan)
        for i, (e, lam) in enumerate(zip(eccentricity, lordosis, strict=True)):
            _, x_i, k_i = coupled.joint_optimum_sdp(coupled.coupled_data(model, e, lam))
            if x_i is not None:
                x[i], k[i] = x_i, k_i
    return {
        "joint_global_pcsa_cm2": x @ data.to_muscles.sum(axis=0),
        "joint_local_pcsa_cm2": k.sum(axis=-1) / kappa,
    }


def _reflex_columns(model: Model, coeffs, pcsa, activation=None, lag=None) -> dict[str, np.ndarray]:
    """Delayed PD reflex at every point and segment (docs/reflex.md), vectorised.

    The global muscles are active at ``reflex.activation`` times the chosen
    activation (1: self-stable, no reflex needed; 0: reflex only), or ``activation``
    per point; the gains follow ``reflex``, the lag ``lag`` per point where given.
    The delay margin does not depend on the delay, so
    ``delay_margin_s > tau`` answers "stable at delay tau" for any tau.
    Infeasible points (NaN PCSA) get NaN and status 'undefined'.
    """
    active = _scaled(model, activation) * pcsa
    lag = None if lag is None else np.asarray(lag, float)[:, None]
    maps = landscape(coeffs.stiffness(active), coeffs.damping(active), coeffs.inertia, model.reflex, lag=lag)
    return {
        "reflex_kp_Nm_per_rad": maps.kp,
        "reflex_kd_Nms_per_rad": maps.kd,
        "delay_margin_s": maps.delay_margin,
        "delay_margin_pade_s": maps.delay_margin_pade,
        "delay_margin_status": np.asarray(STATUS, dtype=object)[maps.delay_margin_status],
        "stable_at_delay": maps.stable_at_delay,
        "spine_delay_margin_s": np.min(maps.delay_margin, axis=-1),
    }
