"""Guarded evaluation of the model: positions, PCSA vectors and arithmetic checked before use.

Every analysis evaluates the coefficients of :mod:`spinectl.model.mechanics` through
:func:`checked_coefficients`, which rejects positions outside the model's range or with
attachments the spline cannot reach, and turns floating-point overflow into a
:class:`~spinectl.errors.ModelError` naming the position.
"""

from __future__ import annotations

import contextlib
import dataclasses

import numpy as np

from ..errors import ModelError, ParameterError
from ..units import centimetre_slip
from . import geometry
from .mechanics import SegmentCoefficients, segment_coefficients
from .params import Model


def validate_position(model: Model, eccentricity, lordosis) -> None:
    """Raise unless the model can be evaluated at (E, Lambda); see :func:`checked_coefficients`.

    Parameters
    ----------
    model : Model
        Supplies the modelled ranges, the geometry and every parameter.
    eccentricity, lordosis : array_like
        E and Lambda [m]; broadcast together (a whole grid may be checked at once).

    Raises
    ------
    ParameterError
        E or Lambda is not finite or outside ``geometry.eccentricity_range`` or
        ``geometry.lordosis_range`` [m].
    ModelError
        A fibre attachment lies on a centre of rotation there, or the
        parameters overflow the arithmetic (a value orders of magnitude off).
    """
    checked_coefficients(model, eccentricity, lordosis)


def validate_grid(model: Model, eccentricity, lordosis, chunk_points: int, *, attachments: bool = True) -> None:
    """Raise unless the model can be evaluated at every point of the grid E x Lambda, before any work.

    The modelled range is a box, so its check and the arithmetic's (:func:`validate_position`)
    are made at the grid's corners; an attachment on a centre of rotation can happen at any
    point, so that check covers the whole grid, ``chunk_points`` points at a time (its
    arrays grow with points x centres x fibres).

    Parameters
    ----------
    model : Model
        The parameters.
    eccentricity, lordosis : array_like, 1-d
        The grid's axes E and Lambda [m].
    chunk_points : int
        Most grid points checked at once (e.g. a study's chunk size), >= 1.
    attachments : bool
        Check the attachments at every point; False when a model with the same geometry
        and muscles has passed already (they alone decide it).

    Raises
    ------
    ParameterError
        E or Lambda not finite or outside the modelled range [m].
    ModelError
        A fibre attachment on a centre of rotation at some grid point (named), or
        floating-point trouble at a corner.
    """
    e_axis, l_axis = np.ravel(np.asarray(eccentricity, float)), np.ravel(np.asarray(lordosis, float))
    _check_range(model, e_axis, l_axis)
    validate_position(model, *np.meshgrid([e_axis.min(), e_axis.max()], [l_axis.min(), l_axis.max()]))
    if not attachments:
        return
    rows = max(1, chunk_points // l_axis.size)  # whole rows of Lambda, as the study's tiles
    for start in range(0, e_axis.size, rows):
        e_grid, l_grid = np.meshgrid(e_axis[start : start + rows], l_axis, indexing="ij")
        with arithmetic_guard(e_grid, l_grid):
            _check_attachments(model, e_grid, l_grid)


def checked_coefficients(model: Model, eccentricity, lordosis) -> SegmentCoefficients:
    """:func:`~spinectl.model.mechanics.segment_coefficients` after every check of :func:`validate_position`.

    Floating-point overflow, division by zero and invalid operations become a
    :class:`ModelError`, never a numpy warning or a NaN passed on to a solver.

    Parameters
    ----------
    model : Model
        The parameters.
    eccentricity, lordosis : array_like
        E and Lambda [m]; broadcast together.

    Returns
    -------
    SegmentCoefficients
        As :func:`~spinectl.model.mechanics.segment_coefficients`, every entry finite
        and every inertia > 0.

    Raises
    ------
    ParameterError
        E or Lambda not finite or outside the modelled range [m].
    ModelError
        A fibre attachment on a centre of rotation, or floating-point trouble.
    """
    _check_range(model, eccentricity, lordosis)
    with arithmetic_guard(eccentricity, lordosis):
        _check_attachments(model, eccentricity, lordosis)
        coeffs = segment_coefficients(model, eccentricity, lordosis)
        values = [getattr(coeffs, f.name) for f in dataclasses.fields(coeffs)]
        if not all(np.all(np.isfinite(x)) for x in values) or np.any(coeffs.inertia <= 0):
            raise FloatingPointError("non-finite segment coefficients or zero inertia")
    return coeffs


def _where(eccentricity, lordosis) -> str:
    e, lam = np.broadcast_arrays(np.asarray(eccentricity, float), np.asarray(lordosis, float))
    if e.size == 1:
        return f"at E = {e.flat[0]:g} m, Lambda = {lam.flat[0]:g} m"
    return f"on the grid E in [{e.min():g}, {e.max():g}] m, Lambda in [{lam.min():g}, {lam.max():g}] m"


@contextlib.contextmanager
def arithmetic_guard(eccentricity, lordosis):
    """Raise :class:`ModelError` for floating-point trouble inside the ``with`` block.

    Validated parameters are finite, so overflow, division by zero or an
    invalid operation mean that some values are orders of magnitude off (a
    unit typo); the user gets that, not a numpy warning and NaN results.

    Parameters
    ----------
    eccentricity, lordosis : array_like
        E and Lambda [m] being evaluated, named in the message.

    Yields
    ------
    None
        Control returns to the ``with`` block under ``numpy.errstate(over, divide,
        invalid = "raise")``.

    Raises
    ------
    ModelError
        On overflow, division by zero or an invalid operation inside the block.
    """
    try:
        with np.errstate(over="raise", divide="raise", invalid="raise"):
            yield
    except (FloatingPointError, OverflowError, ZeroDivisionError) as exc:
        reason = str(exc) if isinstance(exc, FloatingPointError) else type(exc).__name__  # numpy's say where
        raise ModelError(
            f"the model's arithmetic fails {_where(eccentricity, lordosis)} ({reason}); "
            "is a parameter or an input orders of magnitude off? (units are SI: m, kg, N, s)"
        ) from None


ATTACHMENT_TOLERANCE = 4 * np.finfo(float).eps
"""Relative distance [1] below which an attachment is on a centre of rotation: the sum of the absolute
coordinates of their offset is at most this times the sum of the absolute coordinates of both points
(equal up to round-off of the coordinates)."""


def _check_attachments(model: Model, eccentricity, lordosis) -> None:
    """Raise :class:`ModelError` if a fibre attachment lies on a centre of rotation.

    A fibre's line of action may pass through a CoR (a zero lever arm is a
    valid answer), but an attachment on the CoR leaves no arm between the
    joint and the muscle: the fibre has zero length on one side of the joint.
    "On" means equal up to round-off of the coordinates (:data:`ATTACHMENT_TOLERANCE`).
    Only the (CoR, fibre) pairs that :func:`_attachment_candidates` cannot rule out are
    checked point by point, with the same arithmetic, so the verdict and the point named
    are those of checking every pair.
    """
    cor = geometry.cor_positions(eccentricity, lordosis, model.geometry)  # (..., K, 2)
    upper, lower, share = geometry.all_fibres(model)  # (F, 2), (F, 2), (F, M)
    for end, points in (("upper", upper), ("lower", lower)):
        cors, fibres = _attachment_candidates(cor, points)  # in the order (k, f) of all pairs
        if cors.size == 0:
            continue
        offset = cor[..., cors, :] - points[fibres]  # (..., C, 2)
        scale = np.abs(cor[..., cors, :]).sum(-1) + np.abs(points[fibres]).sum(-1)
        on_cor = np.abs(offset).sum(-1) <= ATTACHMENT_TOLERANCE * scale
        if on_cor.any():
            *at, c = np.argwhere(on_cor)[0]  # the first point, then the first pair: as over all pairs
            k, f = cors[c], fibres[c]
            muscle = int(np.argmax(share[f]))
            pair = muscle // 2
            e, lam = (
                np.broadcast_to(np.asarray(x, float), on_cor.shape[:-1])[tuple(at)] for x in (eccentricity, lordosis)
            )
            raise ModelError(
                f"muscles.{pair}.{end}: the {end} attachment of a fibre of {model.muscle_names[muscle]} lies on the "
                f"centre of rotation {model.geometry.cor_names[k]} {_where(e, lam)}; a fibre needs a non-zero "
                "arm between the joint and each attachment"
            )


def _attachment_candidates(cor, points):
    """The (CoR, point) pairs that can be "on" somewhere on the grid, as two index arrays in row-major order.

    Rounding is monotonic, so over the box that the CoR's coordinates span on the grid
    [lo, hi], |fl(c - P)| >= fl(max(lo - P, P - hi, 0)) per coordinate, and the scale
    |c|_1 + |P|_1 is at most its value at the largest abs(c_x) and abs(c_y): a pair whose lower
    bound of the offset exceeds the tolerance times that upper bound of the scale is "on"
    nowhere (the bound rules out every pair of the presets). Coordinates near the overflow
    threshold keep every pair, so that the arithmetic (and its overflow) is that of the
    full check.
    """
    flat = cor.reshape(-1, *cor.shape[-2:])  # (P, K, 2)
    n_cor, n_points = cor.shape[-2], points.shape[0]
    if flat.shape[0] == 0:
        return np.empty(0, int), np.empty(0, int)
    lo, hi = flat.min(axis=0)[:, None, :], flat.max(axis=0)[:, None, :]  # (K, 1, 2)
    largest = max(np.abs(lo).max(initial=0.0), np.abs(hi).max(initial=0.0), np.abs(points).max(initial=0.0))
    if not largest <= np.finfo(float).max / 8:  # sums of four coordinates could overflow: check every pair
        return np.divmod(np.arange(n_cor * n_points), n_points)
    gap = np.maximum(np.maximum(lo - points, points - hi), 0.0).sum(-1)  # (K, F)
    scale = np.maximum(np.abs(lo), np.abs(hi)).sum(-1) + np.abs(points).sum(-1)
    return np.nonzero(gap <= ATTACHMENT_TOLERANCE * scale)


def check_axis_range(name: str, axis, bounds, typed: str, corrected: str) -> None:
    """Refuse a grid axis beyond the modelled range, naming it as the user wrote it and a cm slip.

    The message shows ``typed`` (not the first bad point, which the user never wrote)
    and, where every value read as cm lies in the range, ``corrected``
    (:func:`spinectl.units.centimetre_slip`). ``spinectl sweep --E 0:8:81`` and a study
    file's ``E = { start = 0, stop = 8, num = 81 }`` share it.

    Parameters
    ----------
    name : str
        The field as the user names it, e.g. ``"--E"`` or ``"axes.E"``.
    axis : array_like, 1-d
        The axis [m], finite.
    bounds : (float, float)
        The allowed range [m] (``geometry.eccentricity_range`` or ``lordosis_range``).
    typed, corrected : str
        The axis as written (``"0:8:81"``) and the same in metres if it was cm (``"0:0.08:81"``).

    Raises
    ------
    ParameterError
        Naming ``name``, the range, ``typed`` with the axis's extent [m] and the cm hint if it fits,
        e.g. ``--E: must be in [-0.1, 0.1] m, the modelled range (got '0:8:81': 0 to 8 m); lengths
        are in metres: if you meant 0:8:81 cm, give 0:0.08:81``.
    """
    axis = np.asarray(axis, float)
    low, high = bounds
    if np.all((axis >= low) & (axis <= high)):
        return
    hint = centimetre_slip(axis, low, high, typed, corrected)
    got = f"got {typed!r}: {axis.min():g} to {axis.max():g} m"
    raise ParameterError(name, f"must be in [{low:g}, {high:g}] m, the modelled range ({got}){hint}")


def _check_range(model: Model, eccentricity, lordosis) -> None:
    for name, value, (lo, hi) in (
        ("E", eccentricity, model.geometry.eccentricity_range),
        ("Lambda", lordosis, model.geometry.lordosis_range),
    ):
        arr = np.asarray(value, float)
        if not np.all(np.isfinite(arr)):
            raise ParameterError(name, "must be finite")
        if np.any(arr < lo) or np.any(arr > hi):
            bad = arr[(arr < lo) | (arr > hi)].flat[0]
            raise ParameterError(name, f"must be in [{lo:g}, {hi:g}] m, the modelled range (got {bad:g})")


MAX_PLAUSIBLE_PCSA = 0.1
"""Largest PCSA of one muscle [m^2] that :func:`expand_pcsa` accepts: 1000 cm^2, four times the
largest human muscle's (the soleus, about 230 cm^2; Ward SR et al. 2009, Clin Orthop Relat Res
467:1074-1082, doi:10.1007/s11999-008-0594-8). A larger value is almost surely cm^2 typed where the
API means m^2 (``pcsa=[10, 10, 10]``)."""


MAX_PCSA = 1e100
"""Largest PCSA of one muscle [m^2] that any analysis takes, given or computed: its force (at most 1e7 N/m^2,
:data:`spinectl.model.params.bounds.SPECIFIC_TENSION_RANGE`) on a lever of at most 1 m
(:data:`spinectl.model.params.bounds.MAX_BODY_LENGTH`) is a torque of at most 1e107 N m, whose sums and squares
(‖CT‖) stay far from overflow. Far beyond any optimum a valid model has; a larger value is no PCSA."""


def expand_pcsa(model: Model, pcsa, *, given: bool = True) -> np.ndarray:
    """Per-muscle PCSA [m^2] from per-muscle (2 n values) or per-pair (n values, each side) input.

    With n values, both muscles of pair j get ``pcsa[j]`` (paired activation).

    Parameters
    ----------
    model : Model
        Supplies the muscle pairs.
    pcsa : array_like, shape (..., n) or (..., 2 n)
        PCSA [m^2], finite and >= 0.
    given : bool
        True (the default): the caller gave the PCSA, and one above :data:`MAX_PLAUSIBLE_PCSA` is
        refused as a unit slip. False: spinectl computed it (a minimum stabilising PCSA), which is an
        answer whatever its size: a heavy body with weak fibres needs more than any muscle has.

    Returns
    -------
    numpy.ndarray, shape (..., 2 n)
        PCSA of each muscle [m^2], in the order of
        :attr:`~spinectl.model.params.model.Model.muscle_names`.

    Raises
    ------
    ParameterError
        Neither n nor 2 n values, a value negative, not finite or above :data:`MAX_PCSA`, or (``given``) one above
        :data:`MAX_PLAUSIBLE_PCSA` (most likely cm^2 given where m^2 are meant).
    """
    pcsa = np.asarray(pcsa, float)
    n_pairs = len(model.muscles)
    if pcsa.shape[-1:] == (n_pairs,):
        pcsa = pcsa @ geometry.pairing_matrix(n_pairs).T
    elif pcsa.shape[-1:] != (2 * n_pairs,):
        raise ParameterError(
            "pcsa",
            f"must have {n_pairs} values (one per pair) or {2 * n_pairs} (one per muscle); got {_count(pcsa)}",
        )
    if not np.all(np.isfinite(pcsa)) or np.any(pcsa < 0):
        raise ParameterError("pcsa", "must be finite and >= 0")
    if np.any(pcsa > MAX_PCSA):
        raise ParameterError(
            "pcsa",
            f"must be at most {MAX_PCSA:g} m^2 per muscle, beyond which the torques overflow (got {pcsa.max():g})",
        )
    if given and np.any(pcsa > MAX_PLAUSIBLE_PCSA):
        largest = float(pcsa.max())
        raise ParameterError(
            "pcsa",
            f"must be at most {MAX_PLAUSIBLE_PCSA:g} m^2 per muscle (got {largest:g} m^2): the Python API takes "
            f"m^2; if you meant {largest:g} cm^2, pass {largest * 1e-4:g} (spinectl.units.cm2_to_m2)",
        )
    return pcsa


def _count(values: np.ndarray) -> str:
    """How many values an array holds, in words: ``"2 values"``, ``"one number"``, ``"2 per row (shape (4, 2))"``."""
    if values.ndim == 0:
        return "one number, not one per pair"
    count = f"{values.shape[-1]} value{'s' if values.shape[-1] != 1 else ''}"
    return count if values.ndim == 1 else f"{values.shape[-1]} per row (shape {values.shape})"
