"""Joint by joint (each CoR alone, the others fixed; the paper's criterion): the least co-contraction for a delay.

The least activation a (a fraction of the minimum stabilising PCSA, as ``margins --activation`` takes it) for
which every segment's exact delay margin with the lag (:func:`spinectl.reflex.delay.delay_margin`) under the
reflex rule at that activation is at least the delay. The margins are first scanned over a in [0, 1]
(:data:`SCAN`; they do not depend on the delay); each delay's answer is then bisected in the bracket of the
first scanned activation that meets it, all delays at once (one vectorised margin call per halving). Where
every segment's margin is non-decreasing on the scan the answer is the least ('bisection: monotone on the
scan'); otherwise the same bracket is refined and the method says so ('scan and refine: not monotone').
One delay (:func:`joint_design`) is the curve's search (:func:`least_activations`) at that delay alone.
"""

from __future__ import annotations

import numpy as np

from ...model.checks import arithmetic_guard, checked_coefficients
from ...model.params import Model
from ...optimise.reference import solve_point
from .. import gains
from ..delay import delay_margin
from .decay import shifted_loop
from .result import SegmentDesign

SCAN = 41
"""Activations scanned in [0, 1] before the bisection."""

BISECTIONS = 20
"""Halvings of the bracket: the answer to 1e-6 of the scanned step above the least design (the chain's search
reaches the same precision, 2^-20 of its range)."""


def segment_margins_at(
    model: Model, coefficients, optimum_pcsa, activations, kp=None, kd=None, decay: float = 0.0
) -> np.ndarray:
    """Every segment's exact delay margin with the lag at each activation, shape (n_activations, n_cor) [s].

    Parameters
    ----------
    model : Model
        ``model.reflex``: gains (rule or explicit) and the lag T_a.
    coefficients : spinectl.model.mechanics.SegmentCoefficients
        At the position.
    optimum_pcsa : numpy.ndarray, shape (n_muscles,)
        The minimum stabilising PCSA [m^2].
    activations : array_like, shape (m,)
        Fractions of it [1].
    kp, kd : float, optional
        Explicit gains [N m/rad], [N m s/rad].
    decay : float
        A least decay rate sigma [1/s]: the margins of each loop shifted by sigma at ``reflex.delay``
        (:mod:`~spinectl.reflex.design.decay`), at least the delay exactly where every root of the segment's
        loop at the delay has Re s < -sigma; 0, the loops themselves.

    Returns
    -------
    numpy.ndarray, shape (m, n_cor)
        [s]; inf where any delay is stable, 0 where unstable without delay.
    """
    a = np.asarray(activations, float)[:, None]
    pcsa = a * optimum_pcsa[None, :]
    s = np.stack([coefficients.stiffness(p) for p in pcsa])
    d = np.stack([coefficients.damping(p) for p in pcsa])
    theta = np.broadcast_to(coefficients.inertia, s.shape)
    kps, kds = gains.resolve_gains(s, d, theta, model.reflex, kp, kd)
    lag = model.reflex.activation_time_constant
    if decay > 0:  # the segment's loop is the chain's of one joint: theta, S, D for M, K, D
        s, d, kps, kds, lag = shifted_loop(theta, s, d, kps, kds, lag, model.reflex.delay, decay)
    return np.asarray(delay_margin(s, d, theta, kps, kds, lag).margin)


def _nondecreasing(values: np.ndarray) -> np.ndarray:
    """True per column where the scanned values never fall (inf equal to inf), shape (n,)."""
    with np.errstate(invalid="ignore"):
        steps = np.diff(values, axis=0)
    return np.all((steps >= 0) | (values[1:] == values[:-1]), axis=0)


def scan_margins(model: Model, coefficients, optimum_pcsa, kp=None, kd=None, decay: float = 0.0):
    """The scanned activations and every segment's exact margin there (they do not depend on the delay).

    Parameters
    ----------
    model, coefficients, optimum_pcsa, kp, kd, decay
        As in :func:`segment_margins_at`.

    Returns
    -------
    scan : numpy.ndarray, shape (SCAN,)
        The activations [1].
    margins : numpy.ndarray, shape (SCAN, n_cor)
        [s].
    """
    scan = np.linspace(0.0, 1.0, SCAN)
    return scan, segment_margins_at(model, coefficients, optimum_pcsa, scan, kp, kd, decay)


def least_activations(
    model: Model, coefficients, optimum_pcsa, delays, scan, margins, kp=None, kd=None, decay: float = 0.0
):
    """Every delay's common least activation and each segment's, bisected together in the scan's brackets.

    Parameters
    ----------
    model, coefficients, optimum_pcsa, kp, kd, decay
        As in :func:`segment_margins_at` (a decay rate: ``delays`` is ``reflex.delay`` alone).
    delays : numpy.ndarray, shape (n_delays,)
        tau [s].
    scan, margins : numpy.ndarray
        Of :func:`scan_margins`.

    Returns
    -------
    common : numpy.ndarray, shape (n_delays,)
        The least activation for every segment at once [1]; NaN where none on the scan meets the delay.
    each : numpy.ndarray, shape (n_delays, n_cor)
        Each segment's own [1].
    """
    n = margins.shape[1]
    pick = [lambda m, k=k: m[:, k] for k in range(n)] + [lambda m: np.min(m, axis=1)]
    answers = []
    for value in pick:
        ok = value(margins)[None, :] >= delays[:, None]  # (n_delays, SCAN)
        first = np.argmax(ok, axis=1)
        found = ok.any(axis=1)
        hi = scan[first]
        lo = np.where(first > 0, scan[np.maximum(first - 1, 0)], hi)
        active = found & (first > 0)
        for _ in range(BISECTIONS if active.any() else 0):
            mid = 0.5 * (lo + hi)
            meets = value(segment_margins_at(model, coefficients, optimum_pcsa, mid, kp, kd, decay)) >= delays
            hi = np.where(active & meets, mid, hi)
            lo = np.where(active & ~meets, mid, lo)
        answers.append(np.where(found, hi, np.nan))
    return answers[-1], np.stack(answers[:-1], axis=1)


def joint_design(model: Model, eccentricity: float, lordosis: float, kp=None, kd=None, decay: float = 0.0):
    """Joint by joint: each segment's and the common least activation whose margins meet ``reflex.delay``.

    The curve's search (:func:`least_activations`) at the one delay, so that the answer is the curve's there.

    Parameters
    ----------
    model : Model
    eccentricity, lordosis : float
        E and Lambda [m].
    kp, kd : float, optional
        Explicit gains [N m/rad], [N m s/rad].
    decay : float
        A least decay rate sigma [1/s]: every segment's loop with every root at the delay at Re s < -sigma
        (:func:`segment_margins_at`); the segments' margins reported are their own, unshifted, and
        ``largest_delay`` NaN (the shifted loops' gains hold one delay).

    Returns
    -------
    activation : float
        The least for every segment at once [1]; NaN if none in [0, 1].
    segments : tuple of SegmentDesign
    optimum_pcsa : numpy.ndarray
        The minimum stabilising PCSA [m^2] (NaN without an optimum).
    status : str
        'ok', 'infeasible' or the optimum's status.
    largest_delay : float
        The largest common delay met on the scan [s].
    method : str
    """
    e, lam = float(eccentricity), float(lordosis)
    coefficients = checked_coefficients(model, e, lam)
    optimum = solve_point(model, e, lam)
    names = model.geometry.cor_names
    if not np.all(np.isfinite(optimum.pcsa)):
        nan = tuple(SegmentDesign(n, np.nan, np.nan, np.nan, False) for n in names)
        return np.nan, nan, optimum.pcsa, optimum.status, np.nan, "none: no optimum"
    p = np.asarray(optimum.pcsa, float)
    with arithmetic_guard(e, lam):
        scan, margins = scan_margins(model, coefficients, p, kp, kd, decay)
        delays = np.array([model.reflex.delay])
        common, each = least_activations(model, coefficients, p, delays, scan, margins, kp, kd, decay)
        own = [
            np.nan if np.isnan(a) else segment_margins_at(model, coefficients, p, [a], kp, kd)[0, k]
            for k, a in enumerate(each[0])
        ]
    monotone = _nondecreasing(margins)
    segments = tuple(
        SegmentDesign(name, float(a), a * p.sum() if np.isfinite(a) else np.nan, float(m), bool(monotone[k]))
        for k, (name, a, m) in enumerate(zip(names, each[0], own, strict=True))
    )
    activation = float(common[0])
    method = "bisection: monotone on the scan" if monotone.all() else "scan and refine: not monotone"
    largest = float(np.max(np.min(margins, axis=1))) if not decay > 0 else np.nan
    return activation, segments, p, ("ok" if np.isfinite(activation) else "infeasible"), largest, method
