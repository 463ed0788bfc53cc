"""The design question, answered at one delay (:func:`design`) or against the delay (:func:`delay_curve`).

Two answers at one (E, Lambda), one per criterion (docs/reflex.md, "The design question"): joint by joint,
the least co-contraction (:mod:`~spinectl.reflex.design.joint`); for the chain, the least local stiffness
(:mod:`~spinectl.reflex.design.chain`). One delay is the curve's search at that delay alone, so that
``design --delay 0.12`` and ``design --delays 0.12:0.12:1`` give the same design. No design meets the
delay: status 'infeasible' and the largest delay met.
"""

from __future__ import annotations

import numpy as np

from ..._threads import with_one_blas_thread
from ...model.checks import arithmetic_guard, checked_coefficients
from ...model.params import Model
from ...optimise.reference import solve_point
from .chain import chain_curve, chain_design
from .joint import joint_design, least_activations, scan_margins
from .result import GIVEN_REFLEX, Design, DesignCurve


@with_one_blas_thread
def design(model: Model, eccentricity: float, lordosis: float, kp=None, kd=None, decay: float = 0.0) -> Design:
    """Both answers to the design question at ``model.reflex.delay`` (see the module).

    Parameters
    ----------
    model : Model
        ``model.reflex``: delay, lag, gains (rule or explicit).
    eccentricity, lordosis : float
        E and Lambda [m].
    kp, kd : float, optional
        Explicit gains for every segment and joint [N m/rad], [N m s/rad].
    decay : float
        A least decay rate sigma [1/s] for both criteria (:func:`~spinectl.reflex.design.joint.joint_design`,
        :func:`~spinectl.reflex.design.chain.chain_design`): every characteristic root at the delay at
        Re s < -sigma; 0, stable at the delay.

    Returns
    -------
    Design

    Raises
    ------
    ParameterError
        E or Lambda out of range.

    Examples
    --------
    >>> from spinectl import load_preset
    >>> from spinectl.reflex.design import design
    >>> answer = design(load_preset("wagner2012"), 0.03, 0.04)  # at the preset's 100 ms delay
    >>> answer.status, round(answer.activation, 3)  # joint by joint: the least co-contraction
    ('ok', 0.271)
    >>> round(float(answer.chain.local_stiffness.sum()), 1)  # the chain: local stiffness [N m/rad]
    135.8
    """
    from ...model.source import header, provenance

    activation, segments, optimum, status, largest, method = joint_design(model, eccentricity, lordosis, kp, kd, decay)
    pcsa = activation * optimum if np.isfinite(activation) else np.full_like(np.asarray(optimum, float), np.nan)
    at = model.reflex.activation  # the chain at the operating point of spinectl margins
    chain_answer = chain_design(
        model, float(eccentricity), float(lordosis), at * np.asarray(optimum, float), at, kp, kd, decay
    )
    if status == "ok" and np.isnan(chain_answer.fraction):
        status = "chain_infeasible"
    return Design(
        eccentricity=float(eccentricity),
        lordosis=float(lordosis),
        delay=model.reflex.delay,
        activation_time_constant=model.reflex.activation_time_constant,
        activation=activation,
        pcsa=float(np.sum(pcsa)),
        segments=segments,
        chain=chain_answer,
        status=status,
        largest_delay=largest,
        method=method,
        model=provenance(model) | {"header": header(model)},
        decay_rate=float(decay),
    )


@with_one_blas_thread
def delay_curve(model: Model, eccentricity: float, lordosis: float, delays, lags=None, kp=None, kd=None) -> DesignCurve:
    """Both criteria's required design against the delay, for each lag: the design curve.

    Joint by joint, each delay's least activations are bisected together (one vectorised margin call per
    halving for all delays) in the brackets of the activation scan, whose margins do not depend on the
    delay. The chain's least local stiffness is nondecreasing in the delay (a design that meets a delay
    meets every shorter one), so each delay starts from the previous delay's answer: if that meets the
    delay it is the answer; otherwise the bracket from it to the top of the search is narrowed by a
    safeguarded inverse interpolation of the exact margins
    (:func:`spinectl.reflex.design.chain._bracket_root`), on the bisection's grid
    precision and with its certificate. The exact delay margin at each fraction is computed once (it does
    not depend on the delay), and the rightmost root once per fraction that the margin admits.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    delays : array_like, shape (n_delays,)
        tau in [0, 10] s; sorted ascending in the result.
    lags : array_like, optional
        T_a values [s], >= 0; default: ``reflex.activation_time_constant``.
    kp, kd : float, optional
        Explicit gains [N m/rad], [N m s/rad].

    Returns
    -------
    DesignCurve

    Raises
    ------
    ParameterError
        A delay or lag out of range; E or Lambda out of range.
    """
    from ...model import config
    from ...model.params.bounds import design_axes
    from ...model.source import header, provenance

    ds, lag_values = design_axes(  # the bounds of reflex.delay and reflex.activation_time_constant
        np.asarray(delays, float).ravel().tolist(),
        np.asarray([model.reflex.activation_time_constant] if lags is None else lags, float).ravel().tolist(),
    )
    ds, lag_values = np.sort(ds), np.array(lag_values)
    e, lam = float(eccentricity), float(lordosis)
    coefficients = checked_coefficients(model, e, lam)
    optimum = np.asarray(solve_point(model, e, lam).pcsa, float)
    names = model.geometry.cor_names
    rows = []
    for lag in lag_values:
        at = config.set_parameters(model, {"reflex.activation_time_constant": float(lag)})
        rows.append(_curve_at_lag(at, e, lam, coefficients, optimum, ds, kp, kd))
    stack = [np.array([r[i] for r in rows]) for i in range(6)]
    activation, segment_activation, local_fraction, least, chain_margin, roots = stack
    return DesignCurve(
        eccentricity=e,
        lordosis=lam,
        delays=ds,
        lags=lag_values,
        activation=activation,
        segment_activation=segment_activation,
        pcsa=activation * np.sum(optimum),
        chain_activation=model.reflex.activation,
        local_fraction=local_fraction,
        local_stiffness=local_fraction[..., None] * least,
        chain_margin=chain_margin,
        max_root_real=roots,
        names=tuple(names),
        model=provenance(model) | {"header": header(model)},
        reflex=curve_reflex(model, kp, kd),
        global_pcsa=model.reflex.activation * float(np.sum(optimum)),
    )


def curve_reflex(model: Model, kp=None, kd=None) -> str:
    """The reflex the curve's values assume, in words (both criteria).

    Parameters
    ----------
    model : Model
    kp, kd : float, optional
        Explicit gains [N m/rad], [N m s/rad].

    Returns
    -------
    str
    """
    if model.reflex.gains == "rule" and kp is None and kd is None:
        return (
            "the reflex rule (joint by joint, at each activation; the chain, (1 - f)+ x the rule's gains); other "
            "diagonal PD gains may need less (design --delay D --gains search)"
        )
    return GIVEN_REFLEX


def _curve_at_lag(model, e, lam, coefficients, optimum, delays, kp, kd):
    """(activation, segment activations, chain fraction, k* per delay, chain margin, root) at the model's lag."""
    n = len(model.geometry.cor_names)
    if not np.all(np.isfinite(optimum)):
        nan = np.full(delays.size, np.nan)
        return nan, np.full((delays.size, n), np.nan), nan, np.full((delays.size, n), np.nan), nan, nan
    with arithmetic_guard(e, lam):
        scan, margins = scan_margins(model, coefficients, optimum, kp, kd)
        common, each = least_activations(model, coefficients, optimum, delays, scan, margins, kp, kd)
    fraction, least, margin, roots = chain_curve(model, e, lam, model.reflex.activation * optimum, delays, kp, kd)
    return common, each, fraction, np.broadcast_to(least, (delays.size, n)), margin, roots
